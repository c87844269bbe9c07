//! Grid cells of a planar polygon: a nu×nv grid over its bounding box in a local frame
//! aligned with its first edge, each cell clipped to the polygon.
//!
//! - convex polygons: each cell is the polygon clipped by the cell's four lines (one convex
//!   piece per cell);
//! - non-convex polygons: the polygon is triangulated first, every triangle is clipped per cell,
//!   and the pieces of one cell are glued back along their shared edges. Intersection points
//!   are computed from canonically ordered endpoints, and points within a few ulps of a grid
//!   line are put on it, so the two sides of a shared edge agree bit for bit and gluing is
//!   exact. A cell may hold several disjoint pieces; each becomes a
//!   patch. If a glued ring fails validation, its convex pieces are kept instead.
use super::frame::Frame;
use super::glue::{area2, glue_all, P};
use super::tolerance::GRID_SNAP_REL;
use super::{Polygon, PolygonError};

/// Grid line k of n over [lo, hi]; the last one is `hi` exactly.
fn line(lo: f64, hi: f64, k: usize, n: usize) -> f64 {
    if k == n {
        hi
    } else {
        lo + (hi - lo) * (k as f64 / n as f64)
    }
}

/// Keeps the part of `ring` with sign·(p[axis] − c) ≥ 0 (Sutherland–Hodgman, canonical
/// intersections; points within `snap` of the line are put on it, p[axis] = c exactly).
// Not `super::clip::clip_ring`: snaps onto the line and interpolates in a canonical direction.
fn clip(ring: &[P], axis: usize, c: f64, sign: f64, snap: f64) -> Vec<P> {
    let ring: Vec<P> = ring
        .iter()
        .map(|&p| {
            let mut q = p;
            if (q[axis] - c).abs() <= snap {
                q[axis] = c;
            }
            q
        })
        .collect();
    let n = ring.len();
    let d: Vec<f64> = ring.iter().map(|p| sign * (p[axis] - c)).collect();
    let mut out = Vec::with_capacity(n + 2);
    for k in 0..n {
        let (a, b, da, db) = (ring[k], ring[(k + 1) % n], d[k], d[(k + 1) % n]);
        if da >= 0.0 {
            out.push(a);
        }
        if (da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0) {
            let (p, q) = if (a[0], a[1]) < (b[0], b[1]) { (a, b) } else { (b, a) };
            let f = (c - p[axis]) / (q[axis] - p[axis]);
            let other = 1 - axis;
            let mut r = [0.0; 2];
            r[axis] = c;
            r[other] = p[other] + f * (q[other] - p[other]);
            out.push(r);
        }
    }
    out.dedup();
    while out.len() > 1 && out.first() == out.last() {
        out.pop();
    }
    if out.len() < 3 {
        out.clear();
    }
    out
}

/// Splits the polygon into grid cells (see the module docs); cells run row by row along e1.
pub fn polygon_grid(poly: &Polygon, nu: usize, nv: usize) -> Result<Vec<Polygon>, PolygonError> {
    let frame = Frame::of_polygon(poly);
    let (lo, hi) = frame.bounds(poly);
    let snap = GRID_SNAP_REL * (hi[0] - lo[0]).max(hi[1] - lo[1]);
    let xs: Vec<f64> = (0..=nu).map(|i| line(lo[0], hi[0], i, nu)).collect();
    let ys: Vec<f64> = (0..=nv).map(|j| line(lo[1], hi[1], j, nv)).collect();
    let sources: Vec<Vec<P>> = if poly.is_convex() {
        vec![poly.vertices().iter().map(|v| frame.in_plane(*v).to_array()).collect()]
    } else {
        poly.triangulate().iter().map(|t| t.iter().map(|v| frame.in_plane(*v).to_array()).collect()).collect()
    };
    let mut cells: Vec<Vec<Vec<P>>> = vec![Vec::new(); nu * nv];
    for src in &sources {
        let (smin, smax) =
            src.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, p| (a.0.min(p[0]), a.1.max(p[0])));
        for i in span(&xs, smin, smax) {
            let col = clip(&clip(src, 0, xs[i], 1.0, snap), 0, xs[i + 1], -1.0, snap);
            if col.is_empty() {
                continue;
            }
            let (tmin, tmax) =
                col.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, p| (a.0.min(p[1]), a.1.max(p[1])));
            for j in span(&ys, tmin, tmax) {
                let piece = clip(&clip(&col, 1, ys[j], 1.0, snap), 1, ys[j + 1], -1.0, snap);
                if !piece.is_empty() && area2(&piece) > 0.0 {
                    cells[j * nu + i].push(piece);
                }
            }
        }
    }
    let mut out = Vec::new();
    for pieces in cells {
        for (rings, parts) in glue_all(pieces) {
            let glued =
                rings.map(|rs| rs.iter().map(|r| to_polygon(&frame, r)).collect::<Result<Vec<_>, _>>());
            match glued {
                Some(Ok(polys)) => out.extend(polys.into_iter().flatten()),
                // Tracing failed or a glued ring is not simple: keep the convex parts instead.
                _ => {
                    for part in &parts {
                        out.extend(to_polygon(&frame, part)?);
                    }
                }
            }
        }
    }
    Ok(out)
}

/// Indices k with [lines[k], lines[k+1]] overlapping [lo, hi].
fn span(lines: &[f64], lo: f64, hi: f64) -> std::ops::Range<usize> {
    let n = lines.len() - 1;
    let first = lines[1..n].partition_point(|&x| x <= lo);
    let last = lines[1..n].partition_point(|&x| x < hi);
    first..(last + 1).min(n)
}

/// The ring as a 3-D polygon; `None` for a sliver too thin to be a polygon.
fn to_polygon(frame: &Frame, ring: &[P]) -> Result<Option<Polygon>, PolygonError> {
    match Polygon::new(ring.iter().map(|p| frame.from_plane((*p).into())).collect()) {
        Ok(p) => Ok(Some(p)),
        Err(PolygonError::Degenerate | PolygonError::TooFewVertices(_)) => Ok(None),
        Err(e) => Err(e),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// Area conservation required by the scene format (relative).
    const AREA_TOL: f64 = 1e-12;

    fn poly(pts: &[(f64, f64)]) -> Polygon {
        Polygon::new(pts.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect()).unwrap()
    }

    fn check(p: &Polygon, nu: usize, nv: usize) -> Vec<Polygon> {
        let cells = polygon_grid(p, nu, nv).unwrap();
        let sum: f64 = cells.iter().map(Polygon::area).sum();
        assert!((sum - p.area()).abs() <= AREA_TOL * p.area(), "{nu}x{nv}: {sum} vs {}", p.area());
        assert!(cells.iter().all(|c| c.normal().dot(p.normal()) > 1.0 - 1e-12));
        cells
    }

    #[test]
    fn convex_square_gives_one_patch_per_cell() {
        let cells = check(&poly(&[(0., 0.), (2., 0.), (2., 1.), (0., 1.)]), 4, 2);
        assert_eq!(cells.len(), 8);
        assert!(cells.iter().all(|c| (c.area() - 0.25).abs() < 1e-15));
    }

    #[test]
    fn l_shape_cells_are_glued() {
        let l = poly(&[(0., 0.), (2., 0.), (2., 1.), (1., 1.), (1., 2.), (0., 2.)]);
        // Cells of 1×1 cover the three squares of the L exactly: three patches, not triangles.
        let cells = check(&l, 2, 2);
        assert_eq!(cells.len(), 3, "{cells:?}");
        let cells = check(&l, 5, 3);
        assert!(cells.len() <= 15);
    }

    #[test]
    fn comb_cell_keeps_disjoint_pieces_apart() {
        // A U shape: one cell over the whole box holds the polygon as one glued piece; a
        // horizontal band through the prongs holds two disjoint pieces.
        let u = poly(&[(0., 0.), (3., 0.), (3., 3.), (2., 3.), (2., 1.), (1., 1.), (1., 3.), (0., 3.)]);
        assert_eq!(check(&u, 1, 1).len(), 1);
        let cells = check(&u, 1, 3);
        assert_eq!(cells.len(), 5, "bottom band, then the two prongs in each upper band: {cells:?}");
    }

    #[test]
    fn pinched_cell_gives_two_simple_patches() {
        // A notch from the top edge down to (1, 1): the upper cell's part of the polygon is two
        // regions that touch only at the notch tip.
        let notch = poly(&[(0., 0.), (2., 0.), (2., 2.), (1.2, 2.), (1., 1.), (0.8, 2.), (0., 2.)]);
        let cells = check(&notch, 1, 2);
        assert_eq!(cells.len(), 3, "{cells:?}");
        assert!((cells[0].area() - 2.0).abs() < 1e-15);
    }

    #[test]
    fn rotated_star_conserves_area() {
        let pts: Vec<(f64, f64)> = (0..14)
            .map(|k| {
                let a = k as f64 * std::f64::consts::TAU / 14.0 + 0.3;
                let r = if k % 2 == 0 { 1.0 } else { 0.37 };
                (r * a.cos(), r * a.sin())
            })
            .collect();
        let star = poly(&pts);
        assert_eq!(check(&star, 1, 1).len(), 1, "one cell over the whole star glues back to the star");
        for (nu, nv) in [(1, 1), (2, 2), (3, 7), (10, 10)] {
            check(&star, nu, nv);
        }
    }
}
