//! The shared helpers of the integration tests (one `mod common;` per test binary; benches
//! and examples include this file with `#[path]`).
//!
//! This file: scenes with closed-form view factors (parallel, perpendicular and blocked squares,
//! cubes, concentric boxes, an icosphere) and cosine rays. Submodules:
//! - [`rect_exact`]: exact exchange areas between axis-aligned rectangles (C-11, C-14 and
//!   their extensions);
//! - [`exact_vf`]: hand-made view-factor matrices: exact box factors and multinomial counts;
//! - [`analytic_scenes`]: subdivided boxes, an L-shaped room and plates with blockers;
//! - [`concave_meshes`]: extruded concave closed meshes and a brute Monte Carlo reference;
//! - [`hemicube`]: closed forms, scenes and error models of the projection methods.
#![allow(dead_code, unused_imports)]
pub mod analytic_scenes;
pub mod concave_meshes;
pub mod exact_vf;
pub mod hemicube;
pub mod mesh_files;
pub mod rect_exact;

pub use exact_vf::{box_scene, multinomial, patch_vf, vf_from_s};
use glam::DVec2;
use lambert::geometry::{
    frame::Frame,
    sampling::{sample_cosine_hemisphere, PolygonSampler},
};
use lambert::geometry::{DVec3, Polygon};
use lambert::scene::Scene;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// C-11, unit squares 1 apart (docs/literature.md V1).
pub const F_PARALLEL: f64 = 0.1998248957;
/// C-14, unit squares at 90° with a common edge (V2).
pub const F_PERPENDICULAR: f64 = 0.2000437761;
/// Unit squares 1 apart with a centred 0.5×0.5 one-sided blocker midway (view3d.md §5 (d)).
pub const F_BLOCKED: f64 = 0.0995062946;

/// Parallelogram o, o+u, o+u+v, o+v; normal u × v.
pub fn rect(o: DVec3, u: DVec3, v: DVec3) -> Polygon {
    Polygon::new(vec![o, o + u, o + u + v, o + v]).expect("valid rectangle")
}

/// Parallelogram split into n × n patches.
pub fn rect_grid(o: DVec3, u: DVec3, v: DVec3, n: usize) -> Vec<Polygon> {
    let (du, dv) = (u / n as f64, v / n as f64);
    (0..n).flat_map(|a| (0..n).map(move |b| rect(o + du * a as f64 + dv * b as f64, du, dv))).collect()
}

/// The six faces of an axis-aligned cube, each split n × n; normals point inward or outward.
pub fn cube_faces(center: DVec3, side: f64, inward: bool, n: usize) -> Vec<Vec<Polygon>> {
    let h = 0.5 * side;
    let axes = [DVec3::X, DVec3::Y, DVec3::Z];
    let mut faces = Vec::new();
    for a in 0..3 {
        let (eb, ec) = (axes[(a + 1) % 3] * side, axes[(a + 2) % 3] * side);
        for s in [1.0, -1.0] {
            // e_b × e_c = e_a: (eb, ec) gives the normal +e_a, (ec, eb) gives −e_a.
            let outward_pos = s > 0.0;
            let (u, v) = if outward_pos != inward { (eb, ec) } else { (ec, eb) };
            let c = center + axes[a] * (s * h);
            faces.push(rect_grid(c - 0.5 * (u + v), u, v, n));
        }
    }
    faces
}

/// Two unit squares facing each other at gap 1.
pub fn parallel_squares() -> Scene {
    Scene::builder()
        .surface("bottom", vec![rect(DVec3::ZERO, DVec3::X, DVec3::Y)], 1.0, None)
        .surface("top", vec![rect(DVec3::Z, DVec3::Y, DVec3::X)], 1.0, None)
        .ambient(0.0)
        .build()
}

/// Floor and wall sharing the edge x = 0.
pub fn perpendicular_squares() -> Scene {
    Scene::builder()
        .surface("floor", vec![rect(DVec3::ZERO, DVec3::X, DVec3::Y)], 1.0, None)
        .surface("wall", vec![rect(DVec3::ZERO, DVec3::Y, DVec3::Z)], 1.0, None)
        .ambient(0.0)
        .build()
}

/// Interior of the unit cube, one surface per face (faces 2k, 2k+1 are opposite).
pub fn cube_interior(n: usize) -> Scene {
    let names = ["x+", "x-", "y+", "y-", "z+", "z-"];
    let mut b = Scene::builder();
    for (name, face) in names.iter().zip(cube_faces(DVec3::splat(0.5), 1.0, true, n)) {
        b = b.surface(name, face, 1.0, None);
    }
    b.build()
}

/// `parallel_squares` with the centred 0.5×0.5 blocker at z = 0.5 (an obstruction).
pub fn blocked_squares() -> Scene {
    let shade = rect(DVec3::new(0.25, 0.25, 0.5), DVec3::X * 0.5, DVec3::Y * 0.5);
    Scene::builder()
        .surface("bottom", vec![rect(DVec3::ZERO, DVec3::X, DVec3::Y)], 1.0, None)
        .surface("top", vec![rect(DVec3::Z, DVec3::Y, DVec3::X)], 1.0, None)
        .obstruction("shade", vec![shade])
        .ambient(0.0)
        .build()
}

/// Outward cube of side 0.5 centred in an inward cube of side 2: F(in→out) = 1,
/// F(out→in) = 0.0625, F(out→out) = 0.9375. Each box is one surface of 6 faces (n × n each).
pub fn concentric_boxes(n: usize) -> Scene {
    let c = DVec3::splat(1.0);
    Scene::builder()
        .surface("inner", cube_faces(c, 0.5, false, n).concat(), 1.0, None)
        .surface("outer", cube_faces(c, 2.0, true, n).concat(), 1.0, None)
        .build()
}

/// Icosphere of `level` subdivisions (20·4^level triangles) with normals pointing inward.
pub fn inward_sphere(center: DVec3, radius: f64, level: u32) -> Vec<Polygon> {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v: Vec<DVec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| DVec3::new(x, y, z).normalize())
    .collect();
    let mut f: Vec<[usize; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..level {
        let mut mid = std::collections::HashMap::new();
        let mut midpoint = |a: usize, b: usize, v: &mut Vec<DVec3>| {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                v.push(((v[a] + v[b]) * 0.5).normalize());
                v.len() - 1
            })
        };
        let mut next = Vec::with_capacity(f.len() * 4);
        for [a, b, c] in f {
            let (ab, bc, ca) = (midpoint(a, b, &mut v), midpoint(b, c, &mut v), midpoint(c, a, &mut v));
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        f = next;
    }
    // The icosahedron's faces are counter-clockwise from outside; reverse them to face inward.
    f.iter()
        .filter_map(|&[a, b, c]| {
            Polygon::triangle(center + v[c] * radius, center + v[b] * radius, center + v[a] * radius)
        })
        .collect()
}

/// Faces of an axis-aligned box [lo, lo + size], n × n quads each, normals in or out.
pub fn box_faces(lo: DVec3, size: DVec3, inward: bool, n: usize) -> Vec<Vec<Polygon>> {
    let axes = [DVec3::X, DVec3::Y, DVec3::Z];
    let mut out = Vec::new();
    for a in 0..3 {
        let (eb, ec) = (axes[(a + 1) % 3] * size, axes[(a + 2) % 3] * size);
        for hi in [false, true] {
            let o = if hi { lo + axes[a] * size } else { lo };
            let (u, v) = if hi != inward { (eb, ec) } else { (ec, eb) };
            out.push(rect_grid(o, u, v, n));
        }
    }
    out
}

/// The crates.md §1.5 scene: one surface per big-box face and per small box.
pub fn bench_scene() -> Scene {
    let mut b = Scene::builder();
    for (k, f) in box_faces(DVec3::ZERO, DVec3::splat(10.0), true, 65).into_iter().enumerate() {
        b = b.surface(&format!("wall{k}"), f, 0.9, None);
    }
    let mut rng = Pcg64Mcg::seed_from_u64(17);
    for k in 0..250 {
        let size =
            DVec3::new(rng.random_range(0.2..0.8), rng.random_range(0.2..0.8), rng.random_range(0.2..0.8));
        let lo = DVec3::new(rng.random(), rng.random(), rng.random()) * (DVec3::splat(9.0) - size) + 0.5;
        b = b.surface(&format!("box{k}"), box_faces(lo, size, false, 4).concat(), 0.9, None);
    }
    b.build()
}

/// Cosine rays, `n` per patch in patch order: (patch, origin, direction).
pub fn cosine_rays(scene: &Scene, n: usize) -> Vec<(u32, DVec3, DVec3)> {
    let mut rng = Pcg64Mcg::seed_from_u64(5);
    let mut rays = Vec::with_capacity(scene.patches.len() * n);
    for (p, patch) in scene.patches.iter().enumerate() {
        let (s, f) = (PolygonSampler::new(&patch.polygon), Frame::from_normal(patch.polygon.normal()));
        for _ in 0..n {
            let x = s.sample(DVec2::new(rng.random(), rng.random()));
            let d = f.to_world(sample_cosine_hemisphere(DVec2::new(rng.random(), rng.random())));
            rays.push((p as u32, x, d.normalize()));
        }
    }
    rays
}
