//! Geometry level 0: planar polygons in f64.
//!
//! - `polygon`: validated planar polygon (normal, area, centroid), triangulation, clipping.
//! - [`quadrature`]: Gauss–Legendre rules on segments, triangles and quads.
//! - [`frame`]: the one orthonormal frame (origin, t, b, n) and its constructors.
//! - [`sampling`]: warps to patches and hemispheres, each with its pdf and inverse.
//! - [`subdivide`]: parallelogram grids, disk rings × sectors, triangle refinement.
//! - `grid_clip`: grid cells of any simple polygon, clipped, then glued (`glue`, private).
//! - `planes`: the one plane type; grouping polygons by unoriented plane (coplanar pairs,
//!   blocker planes).
//! - `clip`: the Sutherland–Hodgman clippers: the one loop of convex rings (plain and
//!   homogeneous) and the named variants whose arithmetic differs.
//! - [`convex`]: 2-D convex helpers: half-planes, subtraction, hull, disjointness and overlap,
//!   convexity, ear clipping.
//! - `groups`: disjoint groups of indices (union–find), rooted at their smallest member.
//! - `loops`: closed rings from the loose edges of a cycle (a silhouette's outline).
//! - `union`: the union of many plane polygons by one boolean (Clipper2's sweep).
//! - [`shaft`]: the shaft between two boxes (Haines–Wallace): everything a sight line
//!   between them can meet.
//! - `tolerance`: every geometric epsilon, one name per concept, with its reason.
//!
//! Everything here is pure math; nothing depends on scenes or methods.
pub(crate) mod clip;
pub mod convex;
pub mod frame;
mod glue;
pub(crate) mod grid_clip;
pub(crate) mod groups;
pub(crate) mod loops;
pub(crate) mod planes;
pub(crate) mod polygon;
pub mod quadrature;
pub mod sampling;
pub mod shaft;
pub mod subdivide;
pub(crate) mod tolerance;
pub mod union;

pub use glam::DVec3;
pub use polygon::{Polygon, PolygonError};

pub use tolerance::{DEGENERACY_TOL, PLANARITY_TOL};

/// Shapes shared by the unit tests.
#[cfg(test)]
pub(crate) mod fixtures {
    use glam::DVec3;

    /// The square [x0, x0 + s] × [y0, y0 + s] at height z, counter-clockwise seen from +z
    /// (normal +z) when `up`, reversed (normal −z) otherwise.
    pub(crate) fn square(z: f64, x0: f64, y0: f64, s: f64, up: bool) -> Vec<DVec3> {
        let mut v = vec![
            DVec3::new(x0, y0, z),
            DVec3::new(x0 + s, y0, z),
            DVec3::new(x0 + s, y0 + s, z),
            DVec3::new(x0, y0 + s, z),
        ];
        if !up {
            v.reverse();
        }
        v
    }
}
