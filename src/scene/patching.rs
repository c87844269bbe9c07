//! Splitting surfaces into patches (docs/SPEC.md "Patches").
//!
//! - `subdivide = [nu, nv]`: a rectangle into nu×nv parallelograms; a polygon into the cells of
//!   an nu×nv grid over its bounding box in a frame aligned with its first edge, clipped to it
//!   (geometry::grid_clip); a disk into `nu` equal-area rings × `nv` sectors (a single ring
//!   may have one sector: the whole disk).
//! - `max_patch_size = L`: every patch's diameter (largest vertex-to-vertex distance) is at
//!   most L. Rectangles and polygons get the coarsest grid whose cell diameter is ≤ L; disks
//!   use the polygon grid over their regular polygon; mesh triangles are refined uniformly
//!   into n² triangles, n = ⌈longest edge / L⌉ per triangle (neighbours may then meet at
//!   T-junctions, which view factors do not mind); a mesh's larger polygons (View3D
//!   quadrilaterals) get the polygon grid.
//!
//! Patches keep the surface's orientation, and their areas sum to the surface's area.
use super::validate::MAX_PATCHES_PER_SURFACE;
use super::Disk;
use crate::geometry::frame::Frame;
use crate::geometry::grid_clip::polygon_grid;
use crate::geometry::subdivide::{disk_patches, parallelogram_grid, refine_triangle, regular_polygon};
use crate::geometry::{DVec3, Polygon};

/// Relative slack on "diameter ≤ L": grid cells sized exactly to L may exceed it by round-off.
pub const SIZE_SLACK: f64 = 1e-12;

/// Relative area a polygon's grid cells may lose to dropped slivers; SPEC asks for 1e-12.
pub const AREA_CONSERVATION_TOL: f64 = 1e-12;

/// Most validation work (Σ vertices² over the patches) a disk split may take, about 0.5 s:
/// ring patches of a many-segment disk cut into few sectors have thousands of vertices.
pub const MAX_DISK_WORK: f64 = 1e8;

/// How to split one surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Split {
    /// One patch (meshes: one per triangle).
    Whole,
    /// `subdivide = [nu, nv]`.
    Grid(usize, usize),
    /// `max_patch_size = L`.
    MaxSize(f64),
}

fn too_many(n: f64) -> String {
    format!(
        "this would make {n:.0} patches, more than the limit of {MAX_PATCHES_PER_SURFACE} per surface; \
         use a coarser subdivide or a larger max_patch_size"
    )
}

fn check_count(nu: usize, nv: usize) -> Result<(), String> {
    let n = nu as f64 * nv as f64;
    if n > MAX_PATCHES_PER_SURFACE as f64 {
        Err(too_many(n))
    } else {
        Ok(())
    }
}

/// Coarsest nu×nv grid on the parallelogram (u, v) whose cell diameter is ≤ `l`.
fn grid_for_size(u: DVec3, v: DVec3, l: f64) -> Result<(usize, usize), String> {
    let (lu, lv) = (u.length(), v.length());
    let (fu, fv) = ((lu / l).ceil().max(1.0), (lv / l).ceil().max(1.0));
    if fu * fv > MAX_PATCHES_PER_SURFACE as f64 {
        return Err(too_many(fu * fv));
    }
    let (mut nu, mut nv) = (fu as usize, fv as usize);
    loop {
        let (a, b) = (u / nu as f64, v / nv as f64);
        if (a + b).length().max((a - b).length()) <= l * (1.0 + SIZE_SLACK) {
            return Ok((nu, nv));
        }
        if lu / nu as f64 >= lv / nv as f64 {
            nu += 1;
        } else {
            nv += 1;
        }
        check_count(nu, nv)?;
    }
}

/// Patches of the parallelogram o, o+u, o+u+v, o+v.
pub fn rectangle(o: DVec3, u: DVec3, v: DVec3, split: Split) -> Result<Vec<Polygon>, String> {
    let (nu, nv) = match split {
        Split::Whole => (1, 1),
        Split::Grid(nu, nv) => (nu, nv),
        Split::MaxSize(l) => grid_for_size(u, v, l)?,
    };
    check_count(nu, nv)?;
    parallelogram_grid(o, u, v, nu, nv).map_err(|e| super::validate::polygon_problem(&e))
}

/// Patches of a planar polygon.
pub fn polygon(p: &Polygon, split: Split) -> Result<Vec<Polygon>, String> {
    let (nu, nv) = match split {
        Split::Whole => return Ok(vec![p.clone()]),
        Split::Grid(nu, nv) => (nu, nv),
        Split::MaxSize(l) => {
            let f = Frame::of_polygon(p);
            let (lo, hi) = f.bounds(p);
            grid_for_size(f.t * (hi[0] - lo[0]), f.b * (hi[1] - lo[1]), l)?
        }
    };
    check_count(nu, nv)?;
    if (nu, nv) == (1, 1) {
        return Ok(vec![p.clone()]);
    }
    let cells = polygon_grid(p, nu, nv).map_err(|e| {
        format!("could not split the polygon into a {nu}×{nv} grid: {}", super::validate::polygon_problem(&e))
    })?;
    let sum: f64 = cells.iter().map(Polygon::area).sum();
    if (sum - p.area()).abs() > AREA_CONSERVATION_TOL * p.area() {
        return Err(format!(
            "splitting the polygon into a {nu}×{nv} grid lost area ({sum:e} of {:e} m²); \
             try another subdivide",
            p.area()
        ));
    }
    Ok(cells)
}

/// Patches of a disk (tessellated into its equal-area regular polygon).
pub fn disk(d: &Disk, split: Split) -> Result<Vec<Polygon>, String> {
    match split {
        Split::Whole => disk(d, Split::Grid(1, 1)),
        Split::Grid(rings, sectors) => {
            if rings > 1 && sectors < 2 {
                return Err(format!(
                    "a disk with {rings} rings needs at least 2 sectors (subdivide = [rings, sectors]): \
                     a whole ring is not a simple polygon"
                ));
            }
            check_count(rings, sectors)?;
            // Boundary points lcm(segments, sectors); each patch has about 2·(points/sectors + 1).
            let lcm = d.segments as f64 * (sectors / gcd(d.segments, sectors)) as f64;
            let each = 2.0 * (lcm / sectors as f64 + 1.0);
            if rings as f64 * sectors as f64 * each * each > MAX_DISK_WORK {
                return Err(format!(
                    "splitting this {}-segment disk into {rings}×{sectors} would make patches of {each:.0} vertices \
                     each; use fewer segments, or a sector count that divides them",
                    d.segments
                ));
            }
            disk_patches(d.center, d.normal, d.radius, d.segments, rings, sectors)
                .map_err(|e| super::validate::polygon_problem(&e))
        }
        Split::MaxSize(_) => {
            let whole = Polygon::new(regular_polygon(d.center, d.normal, d.radius, d.segments))
                .map_err(|e| super::validate::polygon_problem(&e))?;
            polygon(&whole, split)
        }
    }
}

fn gcd(a: usize, b: usize) -> usize {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// Patches of a mesh: its triangles, refined so no edge exceeds `max_size`; a larger polygon
/// (a View3D quadrilateral) is split as [`polygon`] does.
pub fn mesh(triangles: &[Polygon], max_size: Option<f64>) -> Result<Vec<Polygon>, String> {
    let Some(l) = max_size else { return Ok(triangles.to_vec()) };
    let longest = |t: &Polygon| t.edges().map(|(a, b)| a.distance(b)).fold(0.0, f64::max);
    let counts: Vec<f64> = triangles.iter().map(|t| (longest(t) / l).ceil().max(1.0)).collect();
    let total: f64 = counts.iter().map(|n| n * n).sum();
    if total > MAX_PATCHES_PER_SURFACE as f64 && total > triangles.len() as f64 {
        return Err(too_many(total));
    }
    let mut out = Vec::with_capacity(total as usize);
    for (t, n) in triangles.iter().zip(counts) {
        let v = t.vertices();
        if v.len() > 3 {
            // A View3D quadrilateral: split as any polygon.
            out.extend(polygon(t, Split::MaxSize(l))?);
            continue;
        }
        let pieces = refine_triangle(v[0], v[1], v[2], n as usize)
            .ok_or_else(|| "a refined mesh triangle became degenerate".to_string())?;
        out.extend(pieces);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::subdivide::diameter;

    fn widest(p: &[Polygon]) -> f64 {
        p.iter().map(|q| diameter(q.vertices())).fold(0.0, f64::max)
    }

    #[test]
    fn max_size_grid_is_honoured_and_coarsest() {
        let (u, v) = (DVec3::new(1.0, 0.0, 0.0), DVec3::new(0.0, 0.5, 0.0));
        let p = rectangle(DVec3::ZERO, u, v, Split::MaxSize(0.25)).unwrap();
        assert!(widest(&p) <= 0.25 * (1.0 + SIZE_SLACK));
        // Cell diagonals ≤ 0.25 need cells of at most 0.177 on a side: 6 × 3 here.
        assert_eq!(p.len(), 18);
        let (nu, nv) = grid_for_size(u, v, 0.25).unwrap();
        let coarser = [(nu - 1, nv), (nu, nv - 1)];
        for (a, b) in coarser {
            let (x, y) = (u / a as f64, v / b as f64);
            assert!((x + y).length() > 0.25, "{a}×{b} would also fit");
        }
    }

    #[test]
    fn limits_are_errors() {
        let e = rectangle(DVec3::ZERO, DVec3::X, DVec3::Y, Split::MaxSize(1e-6)).unwrap_err();
        assert!(e.contains("limit"), "{e}");
        let d = Disk { center: DVec3::ZERO, normal: DVec3::Z, radius: 1.0, segments: 64 };
        assert!(disk(&d, Split::Grid(3, 1)).unwrap_err().contains("at least 2 sectors"));
    }

    #[test]
    fn disk_max_size() {
        let d = Disk { center: DVec3::ZERO, normal: DVec3::Z, radius: 1.0, segments: 64 };
        let p = disk(&d, Split::MaxSize(0.3)).unwrap();
        assert!(widest(&p) <= 0.3 * (1.0 + SIZE_SLACK));
        let sum: f64 = p.iter().map(Polygon::area).sum();
        assert!((sum - std::f64::consts::PI).abs() < 1e-12 * std::f64::consts::PI);
    }
}
