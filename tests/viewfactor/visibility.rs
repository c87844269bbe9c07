//! Visibility: watertightness (closed cube, tessellated sphere), sidedness rules, occlusion,
//! blocker candidates against brute force, tree quality and scale invariance.
use crate::common;

use common::*;
use glam::DVec2;
use lambert::geometry::{
    frame::Frame,
    sampling::{sample_uniform_hemisphere, PolygonSampler},
};
use lambert::geometry::{DVec3, Polygon};
use lambert::scene::Scene;
use lambert::visibility::{Occluder, Visibility};
use rand::Rng;
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;

/// Uniform direction on the sphere.
fn sphere_dir(rng: &mut Pcg64Mcg) -> DVec3 {
    let z = 2.0 * rng.random::<f64>() - 1.0;
    let phi = 2.0 * std::f64::consts::PI * rng.random::<f64>();
    let r = (1.0 - z * z).sqrt();
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

fn scene_of(polys: Vec<Polygon>) -> Scene {
    Scene::builder().surface("s", polys, 1.0, None).build()
}

/// Casts `n` rays per chunk from interior points of the unit-ish box [lo, hi] and counts
/// (misses, back-side hits).
fn cast_from_inside(
    vis: &Visibility,
    lo: DVec3,
    hi: DVec3,
    chunks: u64,
    n: usize,
    aim: &[DVec3],
) -> (usize, usize) {
    (0..chunks)
        .into_par_iter()
        .map(|c| {
            let mut rng = Pcg64Mcg::new(0xC0FFEE + c as u128);
            let (mut miss, mut back) = (0, 0);
            for k in 0..n {
                // Half the origins hug a face or an edge (within 1e-6), the rest are anywhere.
                let mut o = lo + (hi - lo) * DVec3::new(rng.random(), rng.random(), rng.random());
                if k % 2 == 0 {
                    let axis = k / 2 % 3;
                    o[axis] = if rng.random::<bool>() { lo[axis] + 1e-6 } else { hi[axis] - 1e-6 };
                    if k % 4 == 0 {
                        let axis2 = (axis + 1) % 3;
                        o[axis2] = lo[axis2] + 1e-7;
                    }
                }
                // Every 8th ray aims exactly at a mesh vertex (shared edges and vertices).
                let d = if k % 8 == 1 && !aim.is_empty() {
                    (aim[rng.random_range(0..aim.len())] - o).normalize()
                } else {
                    sphere_dir(&mut rng)
                };
                match vis.first_hit(o, d, f64::INFINITY, None) {
                    None => miss += 1,
                    Some(h) if !h.front_facing => back += 1,
                    Some(_) => {}
                }
            }
            (miss, back)
        })
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1))
}

#[test]
fn closed_subdivided_cube_does_not_leak() {
    let faces = cube_faces(DVec3::splat(0.5), 1.0, true, 16);
    let verts: Vec<DVec3> = faces.iter().flatten().flat_map(|p| p.vertices().to_vec()).collect();
    let vis = Visibility::new(&scene_of(faces.concat()));
    let (miss, back) = cast_from_inside(&vis, DVec3::ZERO, DVec3::ONE, 64, 16_384, &verts);
    assert_eq!((miss, back), (0, 0), "1,048,576 rays from inside the cube: misses, back hits");
}

#[test]
fn tessellated_sphere_does_not_leak() {
    let c = DVec3::new(0.3, -2.0, 5.0);
    let tris = inward_sphere(c, 1.5, 4);
    assert_eq!(tris.len(), 5120);
    for t in &tris {
        assert!(t.normal().dot(c - t.centroid()) > 0.0, "sphere triangles face inward");
    }
    let verts: Vec<DVec3> = tris.iter().flat_map(|p| p.vertices().to_vec()).collect();
    let vis = Visibility::new(&scene_of(tris));
    // Inscribed cube of the polyhedron: half-side below r·cos(facet angle)/√3.
    let h = 1.5 * 0.99 / 3f64.sqrt();
    let (miss, back) = cast_from_inside(&vis, c - h, c + h, 32, 16_384, &verts);
    assert_eq!((miss, back), (0, 0), "524,288 rays from inside the sphere: misses, back hits");
}

#[test]
fn rays_from_every_patch_of_a_closed_box_hit_front_sides_and_never_their_own_patch() {
    let faces = cube_faces(DVec3::new(-3.0, 7.0, 1.0), 2.0, true, 8).concat();
    let scene = scene_of(faces);
    let vis = Visibility::new(&scene);
    let mut rng = Pcg64Mcg::new(5);
    for (p, patch) in scene.patches.iter().enumerate() {
        let s = PolygonSampler::new(&patch.polygon);
        let f = Frame::from_normal(patch.polygon.normal());
        for _ in 0..2000 {
            let x = s.sample(DVec2::new(rng.random(), rng.random()));
            let d = f.to_world(sample_uniform_hemisphere(DVec2::new(rng.random(), rng.random())));
            let h = vis.first_hit(x, d, f64::INFINITY, Some(p)).expect("closed box");
            assert!(h.front_facing && h.occluder != Occluder::Patch(p), "patch {p}: {h:?}");
        }
    }
}

#[test]
fn thin_two_sided_plate_in_a_box_sends_both_faces_to_the_box() {
    // Plate at z = 0.5 as two coincident surfaces, facing up and down, inside a closed box.
    let up = rect(DVec3::new(0.2, 0.2, 0.5), DVec3::X * 0.6, DVec3::Y * 0.6);
    let down = up.flipped();
    let scene = Scene::builder()
        .surface("up", vec![up], 1.0, None)
        .surface("down", vec![down], 1.0, None)
        .surface("box", cube_faces(DVec3::splat(0.5), 1.0, true, 2).concat(), 1.0, None)
        .build();
    let vis = Visibility::new(&scene);
    let mut rng = Pcg64Mcg::new(11);
    for p in 0..2 {
        let poly = &scene.patches[p].polygon;
        let (s, f) = (PolygonSampler::new(poly), Frame::from_normal(poly.normal()));
        for _ in 0..20_000 {
            let x = s.sample(DVec2::new(rng.random(), rng.random()));
            let d = f.to_world(sample_uniform_hemisphere(DVec2::new(rng.random(), rng.random())));
            let h = vis.first_hit(x, d, f64::INFINITY, Some(p)).expect("closed box");
            assert!(h.front_facing && h.occluder >= Occluder::Patch(2), "from {p}: {h:?}");
        }
    }
}

#[test]
fn rays_reaching_a_two_sided_plate_hit_the_face_turned_towards_them() {
    // The plate of case o2: two coincident surfaces, subdivided 2×2 with opposite windings,
    // between two squares. Each side's rays must land on the face that looks at them, never
    // on the coincident back face (a closest-hit tie within rounding).
    let up = rect(DVec3::new(0.25, 0.25, 0.5), DVec3::X * 0.5, DVec3::Y * 0.5);
    let down = rect(DVec3::new(0.25, 0.25, 0.5), DVec3::Y * 0.5, DVec3::X * 0.5);
    let quarters = |p: &Polygon| {
        let v = p.vertices();
        let (o, u, w) = (v[0], (v[1] - v[0]) / 2.0, (v[3] - v[0]) / 2.0);
        (0..4).map(|k| rect(o + u * (k % 2) as f64 + w * (k / 2) as f64, u, w)).collect::<Vec<_>>()
    };
    let bottom = rect(DVec3::ZERO, DVec3::X, DVec3::Y);
    let top = rect(DVec3::Z, DVec3::Y, DVec3::X);
    let scene = Scene::builder()
        .surface("bottom", vec![bottom], 1.0, None)
        .surface("top", vec![top], 1.0, None)
        .surface("plate_down", quarters(&down), 1.0, None)
        .surface("plate_up", quarters(&up), 1.0, None)
        .build();
    let vis = Visibility::new(&scene);
    let mut rng = Pcg64Mcg::new(5);
    let (mut to_down, mut to_up) = (0, 0);
    for (p, want) in [(0, 2..6), (1, 6..10)] {
        let poly = &scene.patches[p].polygon;
        let (s, f) = (PolygonSampler::new(poly), Frame::from_normal(poly.normal()));
        for _ in 0..20_000 {
            let x = s.sample(DVec2::new(rng.random(), rng.random()));
            let d = f.to_world(sample_uniform_hemisphere(DVec2::new(rng.random(), rng.random())));
            if let Some(h) = vis.first_hit(x, d, f64::INFINITY, Some(p)) {
                if let Occluder::Patch(q) = h.occluder {
                    if (2..10).contains(&q) {
                        assert!(want.contains(&q) && h.front_facing, "from {p}: {h:?}");
                        *if p == 0 { &mut to_down } else { &mut to_up } += 1;
                    }
                }
            }
        }
    }
    // Both sides see the plate (F ≈ 0.13 of 20 000 rays, uniform weighting aside).
    assert!(to_down > 1000 && to_up > 1000, "{to_down} {to_up}");
}

#[test]
fn occlusion_blocks_through_the_shade_only() {
    let scene = blocked_squares();
    let vis = Visibility::new(&scene);
    let c = |x, y, z| DVec3::new(x, y, z);
    assert!(vis.occluded(c(0.5, 0.5, 0.0), c(0.5, 0.5, 1.0), 0, 1));
    assert!(!vis.occluded(c(0.1, 0.1, 0.0), c(0.1, 0.1, 1.0), 0, 1));
    assert!(!vis.occluded(c(0.1, 0.5, 0.0), c(0.2, 0.5, 1.0), 0, 1));
    // Through the shade's edge region: x = 0.25 + 0.1 at mid height.
    assert!(vis.occluded(c(0.3, 0.5, 0.0), c(0.4, 0.5, 1.0), 0, 1));
    // Concave corner: floor point next to the wall sees a wall point; nothing in between.
    let scene = perpendicular_squares();
    let vis = Visibility::new(&scene);
    assert!(!vis.occluded(c(1e-9, 0.5, 0.0), c(0.0, 0.5, 1e-9), 0, 1));
    assert!(!vis.occluded(c(0.5, 0.5, 0.0), c(0.0, 0.2, 0.7), 0, 1));
}

#[test]
fn first_hit_distance_and_target_are_exact_to_f32() {
    let scene = blocked_squares();
    let vis = Visibility::new(&scene);
    let h = vis.first_hit(DVec3::new(0.5, 0.5, 0.0), DVec3::Z, f64::INFINITY, Some(0)).unwrap();
    assert_eq!(h.occluder, Occluder::Obstruction { obstruction: 0, polygon: 0 });
    assert!((h.t - 0.5).abs() < 1e-6 && !h.front_facing, "{h:?}");
    let h = vis.first_hit(DVec3::new(0.1, 0.9, 0.0), DVec3::Z, f64::INFINITY, Some(0)).unwrap();
    assert_eq!(h.occluder, Occluder::Patch(1));
    assert!((h.t - 1.0).abs() < 1e-6 && h.front_facing, "{h:?}");
    assert!(vis.first_hit(DVec3::new(0.1, 0.9, 0.0), DVec3::Z, 0.9, Some(0)).is_none());
}

#[test]
fn results_do_not_depend_on_the_scene_scale() {
    for scale in [1e-4, 1.0, 3e4] {
        let scene = Scene::builder()
            .surface("box", cube_faces(DVec3::splat(0.5 * scale), scale, true, 4).concat(), 1.0, None)
            .build();
        let vis = Visibility::new(&scene);
        // A ray from just above the floor, 1e-5 of the size from a wall, heading into it.
        let o = DVec3::new(1e-5, 0.5, 1e-6) * scale;
        let h = vis.first_hit(o, DVec3::new(-1.0, 0.0, 1e-3).normalize(), f64::INFINITY, None).unwrap();
        assert!(h.front_facing && (h.t / scale - 1e-5).abs() < 1e-6, "scale {scale}: {h:?}");
    }
}

#[test]
fn candidates_cover_every_real_blocker() {
    // Random quads (patches) and random triangles (obstructions) in a unit box.
    let mut rng = Pcg64Mcg::new(99);
    let mut rnd = |s: f64| DVec3::new(rng.random(), rng.random(), rng.random()) * s;
    let mut b = Scene::builder();
    for k in 0..40 {
        let (o, u, v) = (rnd(1.0), rnd(0.3) - 0.15, rnd(0.3) - 0.15);
        if let Ok(p) = Polygon::new(vec![o, o + u, o + u + v, o + v]) {
            b = b.surface(&format!("q{k}"), vec![p], 1.0, None);
        }
    }
    let obs: Vec<Polygon> = (0..40)
        .filter_map(|_| {
            let o = rnd(1.0);
            Polygon::triangle(o, o + rnd(0.2), o + rnd(0.2))
        })
        .collect();
    let scene = b.obstruction("junk", obs).build();
    let vis = Visibility::new(&scene);
    let n = scene.patches.len();
    let mut rng = Pcg64Mcg::new(3);
    let mut cands = Vec::new();
    let (mut found, mut pruned) = (0, 0);
    for i in 0..n {
        for j in 0..n {
            if i == j {
                continue;
            }
            vis.candidates_between(i, j, &mut cands);
            pruned += vis.occluder_count() - 2 - cands.len();
            let (pi, pj) = (&scene.patches[i].polygon, &scene.patches[j].polygon);
            let (si, sj) = (PolygonSampler::new(pi), PolygonSampler::new(pj));
            for _ in 0..200 {
                let x = si.sample(DVec2::new(rng.random(), rng.random()));
                let y = sj.sample(DVec2::new(rng.random(), rng.random()));
                let d = y - x;
                if pi.normal().dot(d) <= 0.0 || pj.normal().dot(d) >= 0.0 {
                    continue;
                }
                let len = d.length();
                if let Some(h) = vis.first_hit(x, d / len, len * (1.0 - 1e-6), Some(i)) {
                    if h.occluder == Occluder::Patch(j) {
                        continue;
                    }
                    let id =
                        (0..vis.occluder_count() as u32).find(|&k| vis.occluder(k) == h.occluder).unwrap();
                    assert!(
                        cands.binary_search(&id).is_ok(),
                        "pair ({i},{j}): blocker {:?} missing from {cands:?}",
                        h.occluder
                    );
                    found += 1;
                }
            }
        }
    }
    assert!(found > 100, "too few blocked segments to mean anything: {found}");
    assert!(pruned > n * n * 10, "the query should prune most occluders: {pruned}");
}

#[test]
fn padded_tree_keeps_triangle_tests_per_ray_low_on_axis_aligned_meshes() {
    // 65 × 65 quads per face, the crates.md §1.3 case (unpadded: 15–200 tests per ray).
    let scene = scene_of(cube_faces(DVec3::ZERO, 10.0, true, 65).concat());
    let vis = Visibility::new(&scene);
    let mut rng = Pcg64Mcg::new(1);
    let rays: Vec<(DVec3, DVec3)> = (0..20_000)
        .map(|_| (DVec3::new(rng.random(), rng.random(), rng.random()) * 8.0 - 4.0, sphere_dir(&mut rng)))
        .collect();
    let tests = vis.tests_per_ray(&rays);
    assert!(tests < 8.0, "{tests} triangle tests per ray");
}

#[test]
fn grazing_rays_from_concave_corners_neither_leak_nor_die_on_a_back_side() {
    // A box at coordinates that f32 cannot hold exactly; origins on the floor within 1e-9..1e-6
    // of the wall x = max (concave corner), rays nearly parallel to that wall, both ways.
    let (c, side) = (DVec3::new(0.3, 0.7, 0.1), 1.3);
    let faces = cube_faces(c, side, true, 1);
    let scene = scene_of(faces.concat());
    let vis = Visibility::new(&scene);
    let (floor, h) = (5, 0.5 * side);
    assert!(scene.patches[floor].polygon.normal().z > 0.99);
    let mut rng = Pcg64Mcg::new(21);
    let mut checked = 0;
    for _ in 0..2000 {
        let gap = 10f64.powf(rng.random_range(-9.0..-6.0));
        let o = DVec3::new(c.x + h - gap, c.y + rng.random_range(-0.6..0.6), c.z - h);
        for eps in [-1e-3, -1e-5, -1e-7, 1e-7, 1e-5, 1e-3] {
            let d = (DVec3::Z * 0.5 - DVec3::X * eps + DVec3::Y * rng.random_range(-0.5..0.5)).normalize();
            let hit = vis.first_hit(o, d, f64::INFINITY, Some(floor));
            assert!(matches!(hit, Some(h) if h.front_facing), "origin {o}, dir {d} (eps {eps}): {hit:?}");
            checked += 1;
        }
    }
    assert_eq!(checked, 12_000);
}

#[test]
fn origins_rounded_onto_a_corner_line_still_hit_the_neighbour() {
    // Found by a 115 M-ray run: a wall origin 4e-9 above the floor rounds onto the corner line
    // in f32; a ray heading into the floor then meets the floor's edge exactly edge-on.
    let faces = cube_faces(DVec3::splat(0.5), 1.0, true, 8);
    let scene = scene_of(faces.concat());
    let vis = Visibility::new(&scene);
    let samplers: Vec<PolygonSampler> =
        scene.patches.iter().map(|p| PolygonSampler::new(&p.polygon)).collect();
    let mut rng = Pcg64Mcg::new(8);
    for k in 0..20_000 {
        let mut o = DVec3::new(1.0, rng.random_range(0.01..0.99), 10f64.powf(rng.random_range(-10.0..-7.5)));
        if k == 0 {
            o = DVec3::new(1.0, 0.04668651873988524, 4.174100047935716e-9);
        }
        // Source: the x = 1 wall patch that holds o (normal −x).
        let src = (0..scene.patches.len())
            .find(|&p| scene.patches[p].polygon.normal().x < -0.5 && samplers[p].contains(o))
            .expect("a wall patch holds the origin");
        let d = if k == 0 {
            DVec3::new(-0.21831577956829956, -0.9457566391641795, -0.24058802935383475)
        } else {
            DVec3::new(
                -rng.random_range(0.01..1.0),
                rng.random_range(-1.0..1.0),
                -rng.random_range(0.01..1.0),
            )
            .normalize()
        };
        let hit = vis.first_hit(o, d, f64::INFINITY, Some(src));
        assert!(matches!(hit, Some(h) if h.front_facing), "origin {o}, dir {d}: {hit:?}");
    }
}
