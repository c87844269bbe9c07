//! The `analytic` method: exact kernels, and shadow clipping for obstructed pairs.
//!
//! - [`polygon_ops`]: 2-D convex clipping and subtraction for shadows;
pub mod polygon_ops;
