//! Geometry level 0: planar polygons in f64.
//!
//! - [`polygon`]: validated planar polygon (normal, area, centroid), triangulation, clipping.
//! - [`quadrature`]: Gauss–Legendre rules on segments, triangles and quads.
//! - [`sampling`]: warps to patches and hemispheres, each with its pdf and inverse.
//! - [`subdivide`]: parallelogram grids, disk rings × sectors, triangle refinement.
//! - [`grid_clip`]: grid cells of any simple polygon, clipped, then glued (`glue`, private).
//!
//! Everything here is pure math; nothing depends on scenes or methods.
mod glue;
pub mod grid_clip;
pub mod polygon;
pub mod quadrature;
pub mod sampling;
pub mod subdivide;

pub use glam::DVec3;
pub use polygon::{Polygon, PolygonError};

/// Relative planarity tolerance: a vertex may sit this fraction of the polygon's diameter off
/// its best-fit plane (CAD exports carry f32 round-off, about 1e-7).
pub const PLANARITY_TOL: f64 = 1e-6;

/// Relative collinearity tolerance: a polygon whose area is below this fraction of its
/// diameter squared is degenerate (zero area or collinear vertices).
pub const DEGENERACY_TOL: f64 = 1e-12;

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
