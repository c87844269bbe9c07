//! Exact kernels of the `analytic` method for planar polygons.
//!
//! - [`lambert`]: point-to-polygon (Lambert 1760), point-to-ring and exact point-to-disk factors;
//! - [`disk`]: the exact element-to-disk factor (full circle and clipped circular segment);
//! - [`contour`]: polygon-to-polygon exchange area by the double contour integral;
//! - [`edge`]: the edge-pair terms of that integral (parallel, crossing and skew lines);
//! - [`gauss`]: Gauss–Legendre rules graded towards known complex singularities;
//! - [`ring`]: stack-allocated vertex rings and half-space clipping;
//! - [`angle`]: a fast, accurate atan2 for the kernels' angles.
pub mod angle;
pub mod contour;
pub mod disk;
pub mod edge;
pub mod gauss;
pub mod lambert;
pub mod ring;
