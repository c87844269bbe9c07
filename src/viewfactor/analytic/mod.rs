//! Exact kernels of the `analytic` method for planar polygons, and exact shadow clipping for
//! obstructed pairs.
//!
//! - [`lambert`]: point-to-polygon (Lambert 1760), point-to-ring and exact point-to-disk factors;
//! - [`disk`]: the exact element-to-disk factor (full circle and clipped circular segment);
//! - [`contour`]: polygon-to-polygon exchange area by the double contour integral;
//! - [`edge`]: the edge-pair terms of that integral (parallel, crossing and skew lines);
//! - [`gauss`]: Gauss–Legendre rules graded towards known complex singularities;
//! - [`ring`]: stack-allocated vertex rings and half-space clipping;
//! - [`polygon_ops`]: 2-D convex clipping and subtraction for shadows;
//! - [`penumbra`]: exact clear / blocked / partial classification of a pair against a blocker;
//! - [`shadow`]: shadow clipping from one viewpoint (the shaded integrand g);
//! - [`adaptive`]: adaptive emitter integration of g with per-cell re-classification;
//! - [`blockers`]: the scene's convex blockers (surface outlines) and their box hierarchies;
//! - [`obstruction`]: per row, the obstructed receivers and their blockers;
//! - [`obstructed`]: the obstructed branch of the kernels (`analytic` and `auto` policies);
//! - [`pair`]: one obstructed pair: emitter choice, shadow integration, A·F.
pub mod adaptive;
pub mod blockers;
pub mod contour;
pub mod disk;
pub mod edge;
pub mod gauss;
pub mod lambert;
pub mod obstructed;
pub mod obstruction;
pub mod pair;
pub mod penumbra;
pub mod polygon_ops;
pub mod ring;
pub mod shadow;
