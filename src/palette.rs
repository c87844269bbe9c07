//! Okabe–Ito colours (Okabe & Ito 2008), distinguishable with every common colour-vision
//! deficiency; yellow is left out (unreadable on white). Used by the charts and by the method
//! registry's fixed colour per method.
/// Black.
pub const BLACK: (u8, u8, u8) = (0, 0, 0);
/// Orange.
pub const ORANGE: (u8, u8, u8) = (230, 159, 0);
/// Sky blue.
pub const SKY_BLUE: (u8, u8, u8) = (86, 180, 233);
/// Bluish green.
pub const BLUISH_GREEN: (u8, u8, u8) = (0, 158, 115);
/// Blue.
pub const BLUE: (u8, u8, u8) = (0, 114, 178);
/// Vermillion.
pub const VERMILLION: (u8, u8, u8) = (213, 94, 0);
/// Reddish purple.
pub const REDDISH_PURPLE: (u8, u8, u8) = (204, 121, 167);
/// Grey (not Okabe–Ito; for reference lines and `auto`, which are dashed).
pub const GREY: (u8, u8, u8) = (110, 110, 110);
/// The seven colours in order, for charts whose series are not methods.
pub const ALL: [(u8, u8, u8); 7] = [BLUE, VERMILLION, BLUISH_GREEN, ORANGE, REDDISH_PURPLE, SKY_BLUE, BLACK];
