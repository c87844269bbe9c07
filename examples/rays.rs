//! Ray throughput of the Monte Carlo engine against a bare obvhs traversal loop on the same
//! scene and rays (research/crates.md §1.5: a 10 m box with 65×65 quads per face plus 250
//! interior boxes of 4×4 quads per face, 98,700 triangles).
//!
//! `cargo run --release --features studies --example rays [rays_per_patch] [all]` — numbers go to validation/rays.md.
//! Other modes (second argument): `interleave [rounds]` (one thread, the core variants
//! round-robin, best CPU time of each: ratios robust to a changing load) and
//! `profile-{sobol,random,uniform-sobol,uniform-random}` (one engine run for perf, with its
//! CPU time and a digest of the output bits).
//! Variants: obvhs build presets, CWBVH vs BVH2, ray order (patch order, shuffled, sorted by
//! direction octant within a patch), our watertight visibility layer, the full engine.
#[path = "../tests/common/mod.rs"]
mod common;

use common::{bench_scene, cosine_rays};
use glam::Vec3A;
use lambert::scene::Scene;
use lambert::viewfactor::monte_carlo::{compute_with, McOptions, Sampler};
use lambert::viewfactor::{Level, Method, Params};
use lambert::visibility::Visibility;
use obvhs::{aabb::Aabb, ray::Ray, ray::RayHit, rt_triangle::RtTriangle, Boundable, BvhBuildParams};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;
use std::time::Instant;

struct PaddedBox(Aabb);
impl Boundable for PaddedBox {
    fn aabb(&self) -> Aabb {
        self.0
    }
}

/// The bare loop's data: padded boxes, RtTriangles in leaf order, owner patch per slot.
struct Bare {
    tris: Vec<RtTriangle>,
    owner: Vec<u32>,
    boxes: Vec<PaddedBox>,
}

fn bare(scene: &Scene) -> Bare {
    let mut tris = Vec::new();
    let mut owner = Vec::new();
    for (p, patch) in scene.patches.iter().enumerate() {
        for [a, b, c] in patch.polygon.triangulate() {
            tris.push(RtTriangle::new(a.as_vec3a(), b.as_vec3a(), c.as_vec3a()));
            owner.push(p as u32);
        }
    }
    let pad = Vec3A::splat(1e-5 * 10.0 * 3f32.sqrt());
    let boxes = tris
        .iter()
        .map(|t| {
            let a = t.aabb();
            PaddedBox(Aabb::new(a.min - pad, a.max + pad))
        })
        .collect();
    Bare { tris, owner, boxes }
}

/// CPU seconds (user + system) of this process so far, from /proc/self/stat (100 Hz ticks).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let fields: Vec<&str> = stat.rsplit(')').next().unwrap_or("").split_whitespace().collect();
    let tick = |k: usize| fields.get(k).and_then(|x| x.parse::<f64>().ok()).unwrap_or(0.0);
    (tick(11) + tick(12)) / 100.0
}

/// (wall s, CPU s, hits) of one run on a pool of `threads`.
fn timed<F: Fn() -> u64 + Sync>(threads: usize, f: F) -> (f64, f64, u64) {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    let (t, c) = (Instant::now(), cpu_seconds());
    let hits = pool.install(&f);
    (t.elapsed().as_secs_f64(), cpu_seconds() - c, hits)
}

/// Prints wall-clock Mrays/s on 1 and 2 threads and Mrays per CPU-second (load-independent).
fn report(label: &str, rays: usize, base: &mut Option<f64>, f: impl Fn() -> u64 + Sync) {
    let mut wall = [0.0; 2];
    let mut cpu = f64::INFINITY;
    let mut hits = 0;
    for (k, th) in [1, 2].into_iter().enumerate() {
        // Best of two runs: the machine is shared.
        let runs: Vec<_> = (0..2).map(|_| timed(th, &f)).collect();
        wall[k] = rays as f64 / runs.iter().map(|r| r.0).fold(f64::INFINITY, f64::min) / 1e6;
        cpu = runs.iter().map(|r| r.1).fold(cpu, f64::min);
        hits = runs[0].2;
    }
    let per_cpu = rays as f64 / cpu / 1e6;
    let b = *base.get_or_insert(per_cpu);
    let rel = 100.0 * per_cpu / b;
    println!(
        "| {label} | {:.2} | {:.2} | {per_cpu:.2} | {rel:.0} % | {:.4} |",
        wall[0],
        wall[1],
        hits as f64 / rays as f64
    );
}

fn main() {
    let per_patch: usize = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(24);
    // `all` adds the tuning sweep: build presets, ray orders, BVH2.
    let sweep = std::env::args().nth(2).is_some_and(|a| a == "all");
    let scene = bench_scene();
    // `profile-sobol` / `profile-random`: one engine run on one thread, for perf.
    if let Some(mode) = std::env::args().nth(2).and_then(|a| a.strip_prefix("profile-").map(str::to_owned)) {
        let sampler = if mode.contains("random") { Sampler::Random } else { Sampler::Sobol };
        let method = if mode.contains("uniform") { Method::McUniform } else { Method::McCosine };
        let params = Params { method, samples: per_patch, seed: 1, ..Params::default() };
        let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
        let c = cpu_seconds();
        let vf =
            pool.install(|| compute_with(&scene, &params, Level::Surface, McOptions { sampler }).unwrap());
        let cpu = cpu_seconds() - c;
        let rays = (scene.patches.len() * per_patch) as f64;
        // FNV-1a over every reported factor and standard error: equal bits, equal output.
        let bits =
            vf.rows.iter().flatten().flat_map(|e| [e.to as u64, e.factor.to_bits(), e.std_error.to_bits()]);
        let digest = bits.fold(0xcbf2_9ce4_8422_2325u64, |h, x| (h ^ x).wrapping_mul(0x100_0000_01b3));
        println!("{mode}: {cpu:.3} CPU-s, {:.2} Mrays per CPU-s, digest {digest:016x}", rays / cpu / 1e6);
        return;
    }
    let rays = cosine_rays(&scene, per_patch);
    let b = bare(&scene);
    // `interleave [rounds]`: the core variants on one thread, round-robin so that a changing
    // machine load hits them alike; best CPU time of each.
    if std::env::args().nth(2).is_some_and(|a| a == "interleave") {
        let rounds = std::env::args().nth(3).and_then(|s| s.parse().ok()).unwrap_or(3);
        interleave(&scene, &b, &rays, per_patch, rounds);
        return;
    }
    println!("scene: {} patches, {} triangles, {} rays", scene.patches.len(), b.tris.len(), rays.len());
    println!(
        "load average at start: {}",
        std::fs::read_to_string("/proc/loadavg").unwrap_or_default().trim()
    );
    println!();
    println!(
        "| variant | wall Mrays/s 1T | wall Mrays/s 2T | Mrays per CPU-s | vs bare medium | hit fraction |"
    );
    println!("|---|---|---|---|---|---|");
    let f32_rays: Vec<(u32, Vec3A, Vec3A)> =
        rays.iter().map(|&(p, o, d)| (p, o.as_vec3a(), d.as_vec3a())).collect();
    let mut base = None;
    let presets = [
        ("medium", BvhBuildParams::medium_build()),
        ("fastest", BvhBuildParams::fastest_build()),
        ("fast", BvhBuildParams::fast_build()),
        ("very_slow", BvhBuildParams::very_slow_build()),
    ];
    for (name, preset) in presets.into_iter().take(if sweep { 4 } else { 1 }) {
        let t = Instant::now();
        let bvh = obvhs::cwbvh::builder::build_cwbvh(&b.boxes, preset, &mut Default::default());
        let build = t.elapsed().as_secs_f64() * 1e3;
        let tris: Vec<RtTriangle> = bvh.primitive_indices.iter().map(|&i| b.tris[i as usize]).collect();
        let owner: Vec<u32> = bvh.primitive_indices.iter().map(|&i| b.owner[i as usize]).collect();
        let cast = |rs: &[(u32, Vec3A, Vec3A)]| -> u64 {
            rs.par_chunks(4096)
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
                        .count() as u64
                })
                .sum()
        };
        let name = format!("bare obvhs CWBVH {name} (build {build:.0} ms), patch order");
        if name.contains("medium") && sweep {
            report(&name, rays.len(), &mut base, || cast(&f32_rays));
            let mut shuffled = f32_rays.clone();
            let mut rng = Pcg64Mcg::seed_from_u64(1);
            for k in (1..shuffled.len()).rev() {
                shuffled.swap(k, rng.random_range(0..=k));
            }
            report("bare obvhs CWBVH medium, shuffled rays", rays.len(), &mut base, || cast(&shuffled));
            let mut octant = f32_rays.clone();
            octant.sort_by_key(|(p, _, d)| (*p, d.cmplt(Vec3A::ZERO).bitmask()));
            report("bare obvhs CWBVH medium, octant-sorted within patch", rays.len(), &mut base, || {
                cast(&octant)
            });
        } else {
            report(&name, rays.len(), &mut base, || cast(&f32_rays));
        }
    }
    if sweep {
        let bvh = obvhs::bvh2::builder::build_bvh2(
            &b.boxes,
            BvhBuildParams::medium_build(),
            &mut Default::default(),
        );
        let tris: Vec<RtTriangle> = bvh.primitive_indices.iter().map(|&i| b.tris[i as usize]).collect();
        let owner: Vec<u32> = bvh.primitive_indices.iter().map(|&i| b.owner[i as usize]).collect();
        report("bare obvhs BVH2 medium, patch order", rays.len(), &mut base, || {
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
                        .count() as u64
                })
                .sum()
        });
    }
    let vis = Visibility::new(&scene);
    report("lambert Visibility::first_hit (watertight, f64 API)", rays.len(), &mut base, || {
        rays.par_chunks(4096)
            .map(|c| {
                c.iter()
                    .filter(|(p, o, d)| vis.first_hit(*o, *d, f64::INFINITY, Some(*p as usize)).is_some())
                    .count() as u64
            })
            .sum()
    });
    for (sampler, label) in [(Sampler::Random, "random"), (Sampler::Sobol, "sobol")] {
        let params = Params { method: Method::McCosine, samples: per_patch, seed: 1, ..Params::default() };
        let label = format!("engine mc-cosine ({label}), surface level, incl. BVH build");
        report(&label, rays.len(), &mut base, || {
            let vf = compute_with(&scene, &params, Level::Surface, McOptions { sampler }).unwrap();
            (vf.patch_row_sums.iter().sum::<f64>() * per_patch as f64).round() as u64
        });
    }
}

/// Round-robin one-thread runs of the bare loop, `Visibility::first_hit` and the engine (both
/// samplers); prints the best Mrays per CPU-second of each and its ratio to the bare loop.
fn interleave(
    scene: &Scene,
    b: &Bare,
    rays: &[(u32, glam::DVec3, glam::DVec3)],
    per_patch: usize,
    rounds: usize,
) {
    let bvh =
        obvhs::cwbvh::builder::build_cwbvh(&b.boxes, BvhBuildParams::medium_build(), &mut Default::default());
    let tris: Vec<RtTriangle> = bvh.primitive_indices.iter().map(|&i| b.tris[i as usize]).collect();
    let owner: Vec<u32> = bvh.primitive_indices.iter().map(|&i| b.owner[i as usize]).collect();
    let f32_rays: Vec<(u32, Vec3A, Vec3A)> =
        rays.iter().map(|&(p, o, d)| (p, o.as_vec3a(), d.as_vec3a())).collect();
    let vis = Visibility::new(scene);
    let engine = |sampler| {
        let params = Params { method: Method::McCosine, samples: per_patch, seed: 1, ..Params::default() };
        let vf = compute_with(scene, &params, Level::Surface, McOptions { sampler }).unwrap();
        (vf.patch_row_sums.iter().sum::<f64>() * per_patch as f64).round() as u64
    };
    let variants: [(&str, &(dyn Fn() -> u64 + Sync)); 4] = [
        ("bare obvhs CWBVH medium, patch order", &|| {
            f32_rays
                .iter()
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
                .count() as u64
        }),
        ("lambert Visibility::first_hit", &|| {
            rays.iter()
                .filter(|(p, o, d)| vis.first_hit(*o, *d, f64::INFINITY, Some(*p as usize)).is_some())
                .count() as u64
        }),
        ("engine mc-cosine, random, incl. BVH build", &|| engine(Sampler::Random)),
        ("engine mc-cosine, Sobol, incl. BVH build", &|| engine(Sampler::Sobol)),
    ];
    let mut best = [f64::INFINITY; 4];
    for _ in 0..rounds {
        for (k, (_, f)) in variants.iter().enumerate() {
            best[k] = best[k].min(timed(1, f).1);
        }
    }
    println!("| variant | Mrays per CPU-s (1 thread, best of {rounds}) | vs bare |");
    println!("|---|---|---|");
    for (k, (label, _)) in variants.iter().enumerate() {
        println!(
            "| {label} | {:.2} | {:.0} % |",
            rays.len() as f64 / best[k] / 1e6,
            100.0 * best[0] / best[k]
        );
    }
    println!("load average at end: {}", std::fs::read_to_string("/proc/loadavg").unwrap_or_default().trim());
}
