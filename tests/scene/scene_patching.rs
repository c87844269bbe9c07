//! Patching properties on random shapes (seeded proptest): area conservation to 1e-12,
//! orientation, counts, grid-cell containment and the `max_patch_size` bound.
use lambert::geometry::frame::Frame;
use lambert::geometry::subdivide::diameter;
use lambert::geometry::{DVec3, Polygon};
use lambert::scene::patching::{self, Split, SIZE_SLACK};
use lambert::scene::Disk;
use proptest::prelude::*;
use std::f64::consts::TAU;

/// SPEC-level area conservation (relative).
const AREA_TOL: f64 = 1e-12;
/// Patch normals equal the surface normal to round-off.
const NORMAL_TOL: f64 = 1e-12;
/// Containment in a grid cell, relative to the polygon size (round-off of the frame mapping).
const CELL_TOL: f64 = 1e-9;

/// A star-shaped (generally non-convex) polygon in a random plane.
fn star() -> impl Strategy<Value = Polygon> {
    (
        prop::collection::vec((0.0..1.0f64, 0.2..1.0f64), 3..14),
        -1.0..1.0f64,
        0.0..TAU,
        prop::array::uniform3(-5.0..5.0f64),
    )
        .prop_filter_map("valid polygon", |(pts, z, phi, shift)| {
            let n = pts.len();
            let ring: Vec<(f64, f64)> = pts
                .iter()
                .enumerate()
                .map(|(k, (jitter, r))| {
                    let a = TAU * (k as f64 + 0.8 * jitter) / n as f64;
                    (r * a.cos(), r * a.sin())
                })
                .collect();
            let normal = DVec3::new(phi.cos() * (1.0 - z * z).sqrt(), phi.sin() * (1.0 - z * z).sqrt(), z);
            let (e1, e2) = lambert::geometry::subdivide::plane_axes(normal);
            let o = DVec3::from_array(shift);
            Polygon::new(ring.iter().map(|(x, y)| o + x * e1 + y * e2).collect()).ok()
        })
}

/// A histogram (staircase) polygon on the integer lattice: non-convex, with collinear vertices
/// and grid lines through vertices and along edges.
fn histogram() -> impl Strategy<Value = Polygon> {
    prop::collection::vec(1u8..5, 1..8).prop_map(|h| {
        let m = h.len() as f64;
        let mut v = vec![DVec3::ZERO, DVec3::new(m, 0.0, 0.0)];
        for (k, &y) in h.iter().enumerate().rev() {
            v.push(DVec3::new(k as f64 + 1.0, y as f64, 0.0));
            v.push(DVec3::new(k as f64, y as f64, 0.0));
        }
        Polygon::new(v).unwrap()
    })
}

fn assert_tiles(p: &Polygon, patches: &[Polygon]) -> Result<(), TestCaseError> {
    let sum: f64 = patches.iter().map(Polygon::area).sum();
    prop_assert!((sum - p.area()).abs() <= AREA_TOL * p.area(), "area {} vs {}", sum, p.area());
    for q in patches {
        prop_assert!(q.normal().dot(p.normal()) > 1.0 - NORMAL_TOL, "orientation {:?}", q.normal());
        prop_assert!(q.vertices().iter().all(|v| p.plane_distance(*v).abs() < 1e-9));
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 128, rng_seed: proptest::test_runner::RngSeed::Fixed(7), ..ProptestConfig::default() })]

    #[test]
    fn polygon_grid_tiles_within_cells(p in star(), nu in 1usize..9, nv in 1usize..9) {
        let patches = patching::polygon(&p, Split::Grid(nu, nv)).unwrap();
        assert_tiles(&p, &patches)?;
        prop_assert!(!patches.is_empty());
        prop_assert_eq!(&patches, &patching::polygon(&p, Split::Grid(nu, nv)).unwrap(), "deterministic");
        // Every patch lies inside one cell of the grid over the bounding box.
        let f = Frame::of_polygon(&p);
        let (lo, hi) = f.bounds(&p);
        let (w, h) = ((hi[0] - lo[0]) / nu as f64, (hi[1] - lo[1]) / nv as f64);
        let tol = CELL_TOL * (hi[0] - lo[0]).max(hi[1] - lo[1]);
        for q in &patches {
            let c = f.in_plane(q.centroid());
            let (i, j) = (((c[0] - lo[0]) / w).floor(), ((c[1] - lo[1]) / h).floor());
            for v in q.vertices() {
                let s = f.in_plane(*v);
                prop_assert!(s[0] >= lo[0] + i * w - tol && s[0] <= lo[0] + (i + 1.0) * w + tol);
                prop_assert!(s[1] >= lo[1] + j * h - tol && s[1] <= lo[1] + (j + 1.0) * h + tol);
            }
        }
        if p.is_convex() {
            prop_assert!(patches.len() <= nu * nv, "convex: at most one patch per cell");
        }
    }

    #[test]
    fn lattice_polygons_split_exactly(p in histogram(), nu in 1usize..17, nv in 1usize..9) {
        let patches = patching::polygon(&p, Split::Grid(nu, nv)).unwrap();
        assert_tiles(&p, &patches)?;
    }

    #[test]
    fn polygon_max_size_is_honoured(p in star(), l in 0.08..1.5f64) {
        let patches = patching::polygon(&p, Split::MaxSize(l)).unwrap();
        assert_tiles(&p, &patches)?;
        for q in &patches {
            prop_assert!(diameter(q.vertices()) <= l * (1.0 + SIZE_SLACK), "{} > {}", diameter(q.vertices()), l);
        }
    }

    #[test]
    fn rectangle_grid_counts_and_size(
        u in prop::array::uniform3(-2.0..2.0f64),
        v in prop::array::uniform3(-2.0..2.0f64),
        nu in 1usize..12, nv in 1usize..12, l in 0.1..2.0f64,
    ) {
        let (u, v) = (DVec3::from_array(u), DVec3::from_array(v));
        prop_assume!(u.cross(v).length() > 1e-3);
        let p = Polygon::new(vec![DVec3::ZERO, u, u + v, v]).unwrap();
        let grid = patching::rectangle(DVec3::ZERO, u, v, Split::Grid(nu, nv)).unwrap();
        prop_assert_eq!(grid.len(), nu * nv);
        assert_tiles(&p, &grid)?;
        let sized = patching::rectangle(DVec3::ZERO, u, v, Split::MaxSize(l)).unwrap();
        assert_tiles(&p, &sized)?;
        prop_assert!(sized.iter().all(|q| diameter(q.vertices()) <= l * (1.0 + SIZE_SLACK)));
    }

    #[test]
    fn disk_rings_and_sectors(rings in 1usize..6, sectors in 2usize..20, segments in 3usize..80, r in 0.01..3.0f64) {
        let d = Disk { center: DVec3::new(1.0, -2.0, 0.5), normal: DVec3::new(0.0, 0.6, 0.8), radius: r, segments };
        let patches = patching::disk(&d, Split::Grid(rings, sectors)).unwrap();
        prop_assert_eq!(patches.len(), rings * sectors);
        let exact = std::f64::consts::PI * r * r;
        let sum: f64 = patches.iter().map(Polygon::area).sum();
        prop_assert!((sum - exact).abs() <= AREA_TOL * exact, "{} vs {}", sum, exact);
        prop_assert!(patches.iter().all(|q| q.normal().dot(d.normal) > 1.0 - NORMAL_TOL));
    }

    #[test]
    fn mesh_refinement_bounds_edges(l in 0.05..2.0f64, seed in prop::array::uniform9(-1.0..1.0f64)) {
        let v = |k: usize| DVec3::new(seed[3 * k], seed[3 * k + 1], seed[3 * k + 2]);
        let Some(t) = Polygon::triangle(v(0), v(1), v(2)) else { return Ok(()) };
        prop_assume!(t.area() > 1e-3);
        let patches = patching::mesh(std::slice::from_ref(&t), Some(l)).unwrap();
        let longest = t.edges().map(|(a, b)| a.distance(b)).fold(0.0, f64::max);
        let n = (longest / l).ceil() as usize;
        prop_assert_eq!(patches.len(), n * n);
        assert_tiles(&t, &patches)?;
        prop_assert!(patches.iter().all(|q| q.edges().all(|(a, b)| a.distance(b) <= l * (1.0 + SIZE_SLACK))));
    }
}

#[test]
fn whole_split_keeps_the_polygon() {
    let p = Polygon::new(vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0)]).unwrap();
    assert_eq!(patching::polygon(&p, Split::Whole).unwrap(), vec![p.clone()]);
    assert_eq!(patching::polygon(&p, Split::Grid(1, 1)).unwrap(), vec![p.clone()]);
    assert_eq!(patching::mesh(std::slice::from_ref(&p), None).unwrap(), vec![p]);
}
