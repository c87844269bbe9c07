//! The `analytic` method: exact for planar polygons, with a Gauss ladder where provably
//! accurate enough, and exact shadow clipping for obstructed pairs.
//!
//! Exact kernels:
//! - [`lambert`]: point-to-polygon (Lambert 1760), point-to-ring and exact point-to-disk factors;
//! - [`disk`]: the exact element-to-disk factor (full circle and clipped circular segment);
//! - [`contour`]: polygon-to-polygon exchange area by the double contour integral;
//! - [`edge`]: the edge-pair terms of that integral (parallel, crossing and skew lines);
//! - [`gauss`]: Gauss–Legendre rules graded towards known complex singularities;
//! - [`ring`]: stack-allocated vertex rings and half-space clipping;
//! - [`angle`]: a fast, accurate atan2 for the kernels' angles.
//!
//! Shadows (obstructed pairs):
//! - [`polygon_ops`]: 2-D convex clipping and subtraction for shadows;
//! - [`penumbra`]: exact clear / blocked / partial classification of a pair against a blocker;
//! - [`shadow`]: shadow clipping from one viewpoint (the shaded integrand g);
//! - [`adaptive`]: adaptive emitter integration of g with per-cell re-classification;
//! - [`blockers`]: the scene's convex blockers (surface outlines) and their box hierarchies;
//! - [`obstruction`]: per row, the obstructed receivers and their blockers;
//! - [`pair`]: one obstructed pair: emitter choice, shadow integration, A·F;
//! - [`obstructed`]: the obstructed branch of the kernel (`analytic` and `auto` policies).
//!
//! The method on a scene:
//! - [`ladder`]: Gauss area rules per patch and their a-priori error model (far pairs);
//! - [`occlusion`]: detection of pairs whose view is partly blocked;
//! - [`planes`]: grouping polygons by plane (coplanar pairs, blocker planes);
//! - [`lattice`]: one evaluation per offset for translated pairs of gridded surfaces;
//! - [`kernel`]: the [`RowKernel`](crate::viewfactor::engine::RowKernel) tying them together.
pub mod adaptive;
pub mod angle;
pub mod blockers;
pub mod contour;
pub mod disk;
pub mod edge;
pub mod gauss;
pub mod kernel;
pub mod ladder;
pub mod lambert;
pub mod lattice;
pub mod obstructed;
pub mod obstruction;
pub mod occlusion;
pub mod pair;
pub mod penumbra;
pub mod planes;
pub mod polygon_ops;
pub mod ring;
pub mod shadow;
