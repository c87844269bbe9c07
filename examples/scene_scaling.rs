//! Scene loading and patching throughput: `cargo run --release --features studies --example scene_scaling`.
//!
//! - a .glb with N triangles (a k×k grid of quads under a two-level node hierarchy);
//! - TOML scenes whose surfaces are split into many patches (rectangle grid, non-convex
//!   polygon grid, disk rings, mesh refinement by max_patch_size).
//!
//! Prints the median of 3 wall times and the peak resident memory.
use lambert::scene;
use std::path::Path;
use std::time::Instant;

fn glb(path: &Path, k: usize) {
    let mut pos: Vec<u8> = Vec::new();
    for j in 0..=k {
        for i in 0..=k {
            for c in [i as f32 / k as f32, j as f32 / k as f32, 0.0] {
                pos.extend(c.to_le_bytes());
            }
        }
    }
    let mut idx: Vec<u8> = Vec::new();
    let v = |i: usize, j: usize| (j * (k + 1) + i) as u32;
    for j in 0..k {
        for i in 0..k {
            for t in [v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j), v(i + 1, j + 1), v(i, j + 1)] {
                idx.extend(t.to_le_bytes());
            }
        }
    }
    let n = (k + 1) * (k + 1);
    let doc = serde_json::json!({
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"name": "root", "translation": [1, 2, 3], "children": [1]},
                  {"name": "plate", "rotation": [0.0, 0.0, 0.38268343, 0.9238795], "scale": [2, 2, 2], "mesh": 0}],
        "meshes": [{"name": "grid", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5125, "count": 6 * k * k, "type": "SCALAR"}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": pos.len()},
                        {"buffer": 0, "byteOffset": pos.len(), "byteLength": idx.len()}],
        "buffers": [{"byteLength": pos.len() + idx.len()}],
    });
    let mut js = serde_json::to_vec(&doc).unwrap();
    while !js.len().is_multiple_of(4) {
        js.push(b' ');
    }
    let bin: Vec<u8> = pos.into_iter().chain(idx).collect();
    let total = 12 + 8 + js.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((js.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(js);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    std::fs::write(path, out).unwrap();
}

/// Median of 3 runs, seconds, and the patch count.
fn time(path: &Path) -> (f64, usize) {
    let mut t = Vec::new();
    let mut patches = 0;
    for _ in 0..3 {
        let start = Instant::now();
        let s = scene::load(path).unwrap_or_else(|e| panic!("{e}"));
        t.push(start.elapsed().as_secs_f64());
        patches = s.patches.len();
    }
    t.sort_by(f64::total_cmp);
    (t[1], patches)
}

fn peak_rss_mb() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find(|l| l.starts_with("VmHWM:"))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|kb| kb.parse::<f64>().ok())
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

fn main() {
    let dir = tempfile::tempdir().unwrap();
    println!("{:<44} {:>10} {:>10} {:>12}", "scene", "patches", "time [s]", "patches/s");
    let report =
        |name: &str, (t, n): (f64, usize)| println!("{name:<44} {n:>10} {t:>10.4} {:>12.3e}", n as f64 / t);
    for k in [100, 224, 500] {
        let p = dir.path().join(format!("grid{k}.glb"));
        glb(&p, k);
        report(&format!("glb, {} triangles", 2 * k * k), time(&p));
    }
    let star: Vec<String> = (0..200)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / 200.0;
            let r = if i % 2 == 0 { 1.0 } else { 0.45 };
            format!("[{:.17},{:.17},0]", r * a.cos(), r * a.sin())
        })
        .collect();
    let toml_cases = [
        (
            "rectangle subdivide 500x500",
            "rectangle = { origin = [0,0,0], u = [1,0,0], v = [0,1,0] }\nsubdivide = [500, 500]".to_string(),
        ),
        (
            "rectangle max_patch_size 0.003 (1 m^2)",
            "rectangle = { origin = [0,0,0], u = [1,0,0], v = [0,1,0] }\nmax_patch_size = 0.003".to_string(),
        ),
        (
            "200-vertex star polygon subdivide 64x64",
            format!("polygon = [{}]\nsubdivide = [64, 64]", star.join(",")),
        ),
        (
            "200-vertex star polygon subdivide 256x256",
            format!("polygon = [{}]\nsubdivide = [256, 256]", star.join(",")),
        ),
        (
            "disk 64 segments, rings x sectors 64x64",
            "disk = { center = [0,0,0], normal = [0,0,1], radius = 1 }\nsubdivide = [64, 64]".to_string(),
        ),
        (
            "disk max_patch_size 0.01",
            "disk = { center = [0,0,0], normal = [0,0,1], radius = 1 }\nmax_patch_size = 0.01".to_string(),
        ),
    ];
    for (name, body) in toml_cases {
        let p = dir.path().join("s.toml");
        std::fs::write(&p, format!("[[surface]]\nname = \"s\"\n{body}\n")).unwrap();
        report(name, time(&p));
    }
    let p = dir.path().join("m.toml");
    std::fs::write(&p, "[[model]]\nfile = \"grid100.glb\"\nmax_patch_size = 0.01\n").unwrap();
    report("glb 20k triangles, max_patch_size 0.01", time(&p));
    println!("peak resident memory: {:.0} MB", peak_rss_mb());
}
