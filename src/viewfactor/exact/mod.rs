//! The exact kernels of view-factor integration, one layer below every method that uses them
//! (`analytic`, `shadow`, the points and the clustered links); nothing here imports a method.
//!
//! - [`lambert`]: point-to-polygon (Lambert 1760), point-to-ring and exact point-to-disk factors;
//! - `disk`: the exact element-to-disk factor (full circle and clipped circular segment);
//! - [`pair`]: polygon-to-polygon exchange area, the contour integral or the split;
//! - [`contour`]: the double contour integral;
//! - `edge`: the edge-pair terms of that integral (parallel, crossing and skew lines);
//! - `gauss`: Gauss–Legendre rules graded towards known complex singularities;
//! - `ring`: stack-allocated vertex rings and half-space clipping;
//! - `cubature`: area cubature of Lambert's point factor (fixed and adaptive);
//! - `split`: pairs of very different size (near part by contour, far part by Gauss on
//!   Lambert's point factor);
//! - `angle`: a fast, accurate atan2 for the kernels' angles.
pub(crate) mod angle;
pub mod contour;
pub(crate) mod cubature;
pub(crate) mod disk;
pub(crate) mod edge;
pub(crate) mod gauss;
pub mod lambert;
pub mod pair;
pub(crate) mod ring;
pub(crate) mod split;
