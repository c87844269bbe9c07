//! Howell-catalogue closed forms in f64, written from docs/literature.md §1.1 independently of
//! `viewfactor::closed_form`. Valid where they do not cancel catastrophically: use [`super::far`]
//! beyond a separation of a few sizes.
use std::f64::consts::PI;

/// C-11 (V1): identical, parallel, directly opposed rectangles a×b at gap c.
pub fn parallel_rectangles(a: f64, b: f64, c: f64) -> f64 {
    let (x, y) = (a / c, b / c);
    let (x2, y2) = (x * x, y * y);
    // ln[(1+X²)(1+Y²)/(1+X²+Y²)] = ln(1 + X²Y²/(1+X²+Y²)): ln_1p keeps the far-field digits.
    let t = 0.5 * (x2 * y2 / (1.0 + x2 + y2)).ln_1p()
        + x * (1.0 + y2).sqrt() * (x / (1.0 + y2).sqrt()).atan()
        + y * (1.0 + x2).sqrt() * (y / (1.0 + x2).sqrt()).atan()
        - x * x.atan()
        - y * y.atan();
    2.0 * t / (PI * x * y)
}

/// C-14 (V2): perpendicular rectangles with a common edge of length l; F from A_1 (width w) to
/// A_2 (height h). The W², H² powers are taken in log form; a zero width term vanishes.
pub fn perpendicular_common_edge(w: f64, h: f64, l: f64) -> f64 {
    let (w, h) = (w / l, h / l);
    let (w2, h2) = (w * w, h * h);
    let s = w2 + h2;
    let xlnx = |c: f64, arg: f64| if c == 0.0 { 0.0 } else { c * arg.ln() };
    let log_term = ((1.0 + w2) * (1.0 + h2) / (1.0 + s)).ln()
        + xlnx(w2, w2 * (1.0 + s) / ((1.0 + w2) * s))
        + xlnx(h2, h2 * (1.0 + s) / ((1.0 + h2) * s));
    let atan_inv = |x: f64| if x == 0.0 { 0.0 } else { x * (1.0 / x).atan() };
    (atan_inv(w) + atan_inv(h) - s.sqrt() * (1.0 / s.sqrt()).atan() + 0.25 * log_term) / (PI * w)
}

/// V4 algebra: exchange area A_1 F_12 of a floor strip x ∈ [a, b] and a wall strip z ∈ [c, d]
/// (distances from the common line, length l), by bilinearity of G(w, h) = w·l·F_C14(w, h, l).
pub fn perpendicular_strips_exchange(a: f64, b: f64, c: f64, d: f64, l: f64) -> f64 {
    let g = |w: f64, h: f64| {
        if w == 0.0 || h == 0.0 {
            0.0
        } else {
            w * l * perpendicular_common_edge(w, h, l)
        }
    };
    g(b, d) - g(a, d) - g(b, c) + g(a, c)
}

/// Section B (V10): element parallel to an a×b rectangle at height c, normal through a corner.
#[cfg(test)]
pub fn element_to_rectangle_corner(a: f64, b: f64, c: f64) -> f64 {
    let (x, y) = (a / c, b / c);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * PI)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Literature.md digits are 8 significant figures; the contour checks carry 12.
    const PRINTED: f64 = 5e-9;

    #[test]
    fn closed_forms_match_literature() {
        assert!((parallel_rectangles(1.0, 1.0, 1.0) - 0.199824895698).abs() < 1e-12);
        assert!((parallel_rectangles(1.0, 1.0, 0.5) - 0.41525328).abs() < PRINTED);
        assert!((perpendicular_common_edge(1.0, 1.0, 1.0) - 0.200043776075).abs() < 1e-12);
        assert!((perpendicular_common_edge(1.0, 2.0, 1.0) - 0.232852602795).abs() < 1e-12);
        assert!((perpendicular_common_edge(2.0, 1.0, 1.0) - 0.11642630).abs() < PRINTED);
        assert!((perpendicular_strips_exchange(0.0, 1.0, 1.0, 2.0, 1.0) - 0.0328088267).abs() < 1e-10);
        assert!((perpendicular_strips_exchange(1.0, 2.0, 1.0, 2.0, 1.0) - 0.0329381623).abs() < 1e-10);
        assert!((element_to_rectangle_corner(1.0, 1.0, 1.0) - 0.13853161).abs() < PRINTED);
        assert!((element_to_rectangle_corner(2.0, 1.0, 1.0) - 0.16737501).abs() < PRINTED);
        // V15: the cube interior sums to one.
        let sum = parallel_rectangles(1.0, 1.0, 1.0) + 4.0 * perpendicular_common_edge(1.0, 1.0, 1.0);
        assert!((sum - 1.0).abs() < 1e-14, "{sum}");
    }

    #[test]
    fn touching_limit_of_the_strip_algebra_is_c14() {
        let touching = perpendicular_strips_exchange(0.0, 1.0, 0.0, 1.0, 1.0);
        assert!((touching - perpendicular_common_edge(1.0, 1.0, 1.0)).abs() < 1e-15);
        let near = perpendicular_strips_exchange(0.0, 1.0, 1e-9, 1.0 + 1e-9, 1.0);
        assert!((near - touching).abs() < 1e-7, "{near} vs {touching}");
    }
}
