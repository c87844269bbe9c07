//! Ray throughput on the crates.md §1.5 scene (98,700 triangles): a bare obvhs closest-hit
//! loop, lambert's visibility layer on the same rays, and the mc-cosine engine casting the
//! same number of rays. `cargo bench --bench rays`; full table: `examples/rays.rs`.
#[path = "../tests/common/mod.rs"]
mod common;

use common::{bench_scene, cosine_rays};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use glam::Vec3A;
use lambert::viewfactor::{compute, Level, Method, Params};
use lambert::visibility::Visibility;
use obvhs::{aabb::Aabb, ray::Ray, ray::RayHit, rt_triangle::RtTriangle, Boundable, BvhBuildParams};
use rayon::prelude::*;

/// Rays per patch per iteration (49,350 patches).
const PER_PATCH: usize = 4;

struct PaddedBox(Aabb);
impl Boundable for PaddedBox {
    fn aabb(&self) -> Aabb {
        self.0
    }
}

fn rays(c: &mut Criterion) {
    let scene = bench_scene();
    let rays = cosine_rays(&scene, PER_PATCH);
    let f32_rays: Vec<(u32, Vec3A, Vec3A)> =
        rays.iter().map(|&(p, o, d)| (p, o.as_vec3a(), d.as_vec3a())).collect();
    // Bare loop: padded CWBVH (medium), RtTriangle in leaf order, source patch skipped.
    let mut tris = Vec::new();
    let mut owner = Vec::new();
    for (p, patch) in scene.patches.iter().enumerate() {
        for [a, b, c] in patch.polygon.triangulate() {
            tris.push(RtTriangle::new(a.as_vec3a(), b.as_vec3a(), c.as_vec3a()));
            owner.push(p as u32);
        }
    }
    let pad = Vec3A::splat(1.7e-4);
    let boxes: Vec<PaddedBox> = tris
        .iter()
        .map(|t| {
            let a = t.aabb();
            PaddedBox(Aabb::new(a.min - pad, a.max + pad))
        })
        .collect();
    let bvh =
        obvhs::cwbvh::builder::build_cwbvh(&boxes, BvhBuildParams::medium_build(), &mut Default::default());
    let tris: Vec<RtTriangle> = bvh.primitive_indices.iter().map(|&i| tris[i as usize]).collect();
    let owner: Vec<u32> = bvh.primitive_indices.iter().map(|&i| owner[i as usize]).collect();
    let vis = Visibility::new(&scene);

    let mut g = c.benchmark_group("rays");
    g.sample_size(10);
    g.throughput(Throughput::Elements(rays.len() as u64));
    g.bench_function("bare_obvhs_closest_hit", |b| {
        b.iter(|| {
            f32_rays
                .par_chunks(4096)
                .map(|c| {
                    c.iter()
                        .filter(|(p, o, d)| {
                            let mut hit = RayHit::none();
                            bvh.ray_traverse(Ray::new_inf(*o, *d), &mut hit, |r, id| {
                                if owner[id] == *p {
                                    f32::INFINITY
                                } else {
                                    tris[id].intersect(r)
                                }
                            })
                        })
                        .count()
                })
                .sum::<usize>()
        })
    });
    g.bench_function("visibility_first_hit", |b| {
        b.iter(|| {
            rays.par_chunks(4096)
                .map(|c| {
                    c.iter()
                        .filter(|(p, o, d)| vis.first_hit(*o, *d, f64::INFINITY, Some(*p as usize)).is_some())
                        .count()
                })
                .sum::<usize>()
        })
    });
    let params = Params { method: Method::McCosine, samples: PER_PATCH, ..Params::default() };
    g.bench_function("engine_mc_cosine_with_build", |b| {
        b.iter(|| compute(&scene, &params, Level::Surface).unwrap())
    });
    g.finish();
}

criterion_group!(benches, rays);
criterion_main!(benches);
