//! Splitting planar shapes into patches (pure geometry, no scene knowledge):
//!
//! - [`parallelogram_grid`]: nu×nv parallelograms of o + s·u + t·v;
//! - [`regular_polygon`] / [`disk_patches`]: the equal-area regular polygon of a disk and its
//!   rings × sectors;
//! - [`refine_triangle`]: uniform n² refinement of a triangle;
//! - [`diameter`]: largest vertex-to-vertex distance, the "width" that `max_patch_size` bounds.
//!
//! Grid cells of general polygons are in `super::grid_clip`.
use super::{Polygon, PolygonError};
use glam::DVec3;
use std::f64::consts::TAU;

/// Largest distance between two vertices of a polygon (its width).
pub fn diameter(vertices: &[DVec3]) -> f64 {
    let mut d2: f64 = 0.0;
    for (k, a) in vertices.iter().enumerate() {
        for b in &vertices[k + 1..] {
            d2 = d2.max(a.distance_squared(*b));
        }
    }
    d2.sqrt()
}

/// Point o + (i/nu)·u + (j/nv)·v; neighbouring cells compute shared corners identically.
fn grid_point(o: DVec3, u: DVec3, v: DVec3, i: usize, nu: usize, j: usize, nv: usize) -> DVec3 {
    o + u * (i as f64 / nu as f64) + v * (j as f64 / nv as f64)
}

/// The nu×nv parallelograms of o + s·u + t·v, s, t ∈ [0, 1], row by row along u; each keeps
/// the orientation u × v.
pub fn parallelogram_grid(
    o: DVec3,
    u: DVec3,
    v: DVec3,
    nu: usize,
    nv: usize,
) -> Result<Vec<Polygon>, PolygonError> {
    let mut out = Vec::with_capacity(nu * nv);
    for j in 0..nv {
        for i in 0..nu {
            out.push(Polygon::new(vec![
                grid_point(o, u, v, i, nu, j, nv),
                grid_point(o, u, v, i + 1, nu, j, nv),
                grid_point(o, u, v, i + 1, nu, j + 1, nv),
                grid_point(o, u, v, i, nu, j + 1, nv),
            ])?);
        }
    }
    Ok(out)
}

/// Circumradius of the regular n-gon whose area is πr²: r·√(2π / (n·sin(2π/n))).
pub fn equal_area_radius(radius: f64, segments: usize) -> f64 {
    let n = segments as f64;
    radius * (TAU / (n * (TAU / n).sin())).sqrt()
}

/// In-plane unit axes (e1, e2) with e1 × e2 = normal, so angles run counter-clockwise.
pub fn plane_axes(normal: DVec3) -> (DVec3, DVec3) {
    let n = normal.normalize();
    let e1 = n.any_orthogonal_vector().normalize();
    (e1, n.cross(e1))
}

/// Vertices of the regular `segments`-gon with the area of the disk (centre, normal, radius),
/// counter-clockwise about the normal, the first on the axis of [`plane_axes`].
pub fn regular_polygon(center: DVec3, normal: DVec3, radius: f64, segments: usize) -> Vec<DVec3> {
    let (e1, e2) = plane_axes(normal);
    let r = equal_area_radius(radius, segments);
    (0..segments)
        .map(|k| {
            let phi = TAU * k as f64 / segments as f64;
            center + r * (phi.cos() * e1 + phi.sin() * e2)
        })
        .collect()
}

fn gcd(a: usize, b: usize) -> usize {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// Splits the equal-area `segments`-gon of a disk into `rings` × `sectors` patches.
///
/// Ring k spans the scaled copies of the polygon at fractions √(k/rings) … √((k+1)/rings) of
/// its circumradius, so every ring has the same area. Sectors are equal runs of boundary
/// edges; when `sectors` does not divide `segments`, each edge is split into equal pieces first
/// (lcm(segments, sectors) boundary points, extra ones lying on the polygon's edges). The
/// innermost ring is a fan of wedges around the centre. Patches run ring by ring, outward.
pub fn disk_patches(
    center: DVec3,
    normal: DVec3,
    radius: f64,
    segments: usize,
    rings: usize,
    sectors: usize,
) -> Result<Vec<Polygon>, PolygonError> {
    if sectors == 1 && rings > 1 {
        // Rings beyond the first would be annuli, which are not simple polygons.
        return Err(PolygonError::SelfIntersecting(0, 0));
    }
    if sectors == 1 {
        return Ok(vec![Polygon::new(regular_polygon(center, normal, radius, segments))?]);
    }
    let corners = regular_polygon(center, normal, radius, segments);
    let split = sectors / gcd(segments, sectors);
    let m = segments * split;
    // Boundary points relative to the centre: the corners and `split − 1` points per edge.
    let boundary: Vec<DVec3> = (0..m)
        .map(|q| {
            let (k, f) = (q / split, (q % split) as f64 / split as f64);
            let (a, b) = (corners[k] - center, corners[(k + 1) % segments] - center);
            a + (b - a) * f
        })
        .collect();
    let per_sector = m / sectors;
    let scale = |k: usize| (k as f64 / rings as f64).sqrt();
    let mut out = Vec::with_capacity(rings * sectors);
    for ring in 0..rings {
        let (inner, outer) = (scale(ring), scale(ring + 1));
        for s in 0..sectors {
            let run = (s * per_sector..=(s + 1) * per_sector).map(|q| boundary[q % m]);
            let mut v: Vec<DVec3> = run.clone().map(|p| center + p * outer).collect();
            if ring == 0 {
                v.push(center);
            } else {
                let inner_pts: Vec<DVec3> = run.map(|p| center + p * inner).collect();
                v.extend(inner_pts.into_iter().rev());
            }
            out.push(Polygon::new(v)?);
        }
    }
    Ok(out)
}

/// Uniform refinement of triangle (a, b, c) into n² similar triangles with the same
/// orientation; `None` if the triangle is degenerate.
pub fn refine_triangle(a: DVec3, b: DVec3, c: DVec3, n: usize) -> Option<Vec<Polygon>> {
    let (ab, ac) = (b - a, c - a);
    let p = |i: usize, j: usize| a + ab * (i as f64 / n as f64) + ac * (j as f64 / n as f64);
    let mut out = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n - j {
            out.push(Polygon::triangle(p(i, j), p(i + 1, j), p(i, j + 1))?);
            if i + j + 2 <= n {
                out.push(Polygon::triangle(p(i + 1, j), p(i + 1, j + 1), p(i, j + 1))?);
            }
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Area sums are exact up to a few ulps of the parent area.
    const AREA_TOL: f64 = 1e-13;

    fn area_sum(p: &[Polygon]) -> f64 {
        p.iter().map(Polygon::area).sum()
    }

    #[test]
    fn parallelogram_grid_tiles_with_orientation() {
        let (o, u, v) = (DVec3::new(1.0, 2.0, 3.0), DVec3::new(2.0, 0.0, 0.0), DVec3::new(0.5, 0.0, 1.0));
        let cells = parallelogram_grid(o, u, v, 3, 5).unwrap();
        assert_eq!(cells.len(), 15);
        let n = u.cross(v).normalize();
        assert!(cells.iter().all(|c| c.normal().dot(n) > 1.0 - 1e-14));
        assert!((area_sum(&cells) - u.cross(v).length()).abs() < AREA_TOL * 2.0);
        assert!((cells[0].area() - u.cross(v).length() / 15.0).abs() < AREA_TOL);
    }

    #[test]
    fn regular_polygon_has_disk_area_and_normal() {
        let n = DVec3::new(1.0, -2.0, 0.5).normalize();
        for segments in [3, 4, 7, 64] {
            let p = Polygon::new(regular_polygon(DVec3::ONE, n, 0.3, segments)).unwrap();
            let exact = std::f64::consts::PI * 0.09;
            assert!((p.area() - exact).abs() < AREA_TOL * exact, "segments {segments}: {}", p.area());
            assert!(p.normal().dot(n) > 1.0 - 1e-14);
            assert!((p.centroid() - DVec3::ONE).length() < 1e-14);
        }
    }

    #[test]
    fn disk_rings_have_equal_area() {
        let exact = std::f64::consts::PI * 4.0;
        for (seg, rings, sectors) in [(64, 3, 8), (64, 1, 5), (12, 4, 2), (7, 2, 3)] {
            let p = disk_patches(DVec3::ZERO, DVec3::Z, 2.0, seg, rings, sectors).unwrap();
            assert_eq!(p.len(), rings * sectors);
            assert!((area_sum(&p) - exact).abs() < AREA_TOL * exact * 10.0, "{seg} {rings} {sectors}");
            // Equal-area rings: each ring's total is exact / rings.
            for r in 0..rings {
                let ring: f64 = p[r * sectors..(r + 1) * sectors].iter().map(Polygon::area).sum();
                assert!((ring - exact / rings as f64).abs() < 1e-12 * exact, "ring {r}: {ring}");
            }
            assert!(p.iter().all(|q| q.normal().dot(DVec3::Z) > 1.0 - 1e-14));
        }
    }

    #[test]
    fn triangle_refinement_tiles() {
        let (a, b, c) = (DVec3::ZERO, DVec3::new(3.0, 0.0, 0.0), DVec3::new(1.0, 2.0, 1.0));
        let parent = Polygon::triangle(a, b, c).unwrap();
        for n in [1, 2, 5] {
            let t = refine_triangle(a, b, c, n).unwrap();
            assert_eq!(t.len(), n * n);
            assert!((area_sum(&t) - parent.area()).abs() < AREA_TOL * parent.area());
            assert!(t.iter().all(|q| q.normal().dot(parent.normal()) > 1.0 - 1e-14));
            let longest = t.iter().map(|q| diameter(q.vertices())).fold(0.0, f64::max);
            assert!((longest - diameter(parent.vertices()) / n as f64).abs() < 1e-14);
        }
    }
}
