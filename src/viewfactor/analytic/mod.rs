//! The `analytic` method: exact kernels, and shadow clipping for obstructed pairs.
//!
//! - [`polygon_ops`]: 2-D convex clipping and subtraction for shadows;
//! - [`penumbra`]: exact clear / blocked / partial classification of a pair against a blocker;
//! - [`shadow`]: shadow clipping from one viewpoint (the shaded integrand g);
//! - [`adaptive`]: adaptive emitter integration of g with per-cell re-classification;
pub mod adaptive;
pub mod penumbra;
pub mod polygon_ops;
pub mod shadow;
