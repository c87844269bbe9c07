//! The `analytic` method: exact for planar polygons, with a Gauss ladder where provably
//! accurate enough.
//!
//! - [`ladder`]: Gauss area rules per patch and their a-priori error model (far pairs);
//! - [`occlusion`]: detection of pairs whose view is partly blocked (refused until shadowing);
//! - [`planes`]: grouping polygons by plane (coplanar pairs, blocker planes).
pub mod ladder;
pub mod occlusion;
pub mod planes;
