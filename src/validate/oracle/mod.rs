//! Independent reference values for the validation studies, written apart from the methods'
//! code paths so that an error in a method cannot hide in its own oracle.
//!
//! - [`lambert`]: Lambert's point-to-polygon factor (docs/literature.md V12) on raw vertex rings, and
//!   its Gauss integral over an emitter (the "1LI" reference for separated pairs);
//! - [`closed`]: Howell-catalogue closed forms in f64 (C-11, C-14 and its strip algebra,
//!   element-to-rectangle corner);
//! - [`far`]: a tensor Gauss "2AI" reference for far pairs, where the closed forms cancel.
pub(crate) mod closed;
pub(crate) mod far;
pub(crate) mod lambert;
