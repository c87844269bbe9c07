//! Independent audit of rows of a view-factor CSV (validation/cad.md, the row audit):
//! `row_audit SCENE CSV RAYS ROW...` casts RAYS cosine-weighted rays from each named patch
//! (uniform origins), finds each ray's nearest hit by brute force over every patch polygon (no
//! lambert code past the scene loader), and compares the hit shares with the CSV's row entry by
//! entry: z = (F − share) / √(σ² + σ_rays²), with σ_rays the binomial error of the count (at
//! least one ray's worth). A ray whose nearest hit is a polygon's back (an open mesh) counts for
//! no patch, as a view factor takes none there. Prints per row its sum, escaped rays (none
//! hit, or a back) and the worst |z|, then every entry beyond [`Z_FLAG`] and [`DIFF_FLAG`].
use glam::DVec3;
use rayon::prelude::*;
use std::collections::HashMap;
use std::path::Path;

/// Standard errors beyond which an entry is flagged.
const Z_FLAG: f64 = 5.0;
/// Absolute difference below which an entry is not flagged (a handful of rays on a small F).
const DIFF_FLAG: f64 = 3e-4;

/// Möller–Trumbore: the ray parameter of the hit of o + t·d on triangle (a, b, c), if any.
fn hit(o: DVec3, d: DVec3, [a, b, c]: [DVec3; 3]) -> Option<f64> {
    let (ab, ac) = (b - a, c - a);
    let p = d.cross(ac);
    let det = ab.dot(p);
    if det.abs() < 1e-300 {
        return None;
    }
    let inv = 1.0 / det;
    let t = o - a;
    let u = t.dot(p) * inv;
    let q = t.cross(ab);
    let v = d.dot(q) * inv;
    (u >= 0.0 && v >= 0.0 && u + v <= 1.0).then(|| ac.dot(q) * inv)
}

/// A point of the polygon `v` from two uniform numbers (a parallelogram or a triangle).
fn point(v: &[DVec3], mut a: f64, mut b: f64) -> DVec3 {
    if v.len() == 4 {
        return v[0] + (v[1] - v[0]) * a + (v[3] - v[0]) * b;
    }
    if a + b > 1.0 {
        (a, b) = (1.0 - a, 1.0 - b);
    }
    v[0] + (v[1] - v[0]) * a + (v[2] - v[0]) * b
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let scene = lambert::scene::load(Path::new(&args[1])).expect("scene loads");
    let csv = std::fs::read_to_string(&args[2]).expect("CSV reads");
    let rays: usize = args[3].parse().expect("RAYS");
    let n = scene.patches.len();
    let index: HashMap<String, usize> = (0..n).map(|p| (scene.patch_name(p), p)).collect();
    let tris: Vec<(usize, [DVec3; 3])> = scene
        .patches
        .iter()
        .enumerate()
        .flat_map(|(p, patch)| {
            let v = patch.polygon.vertices();
            (1..v.len() - 1).map(move |k| (p, [v[0], v[k], v[k + 1]]))
        })
        .collect();
    let mut flagged = Vec::new();
    for name in &args[4..] {
        let i = index[name.as_str()];
        let poly = &scene.patches[i].polygon;
        let (v, nrm) = (poly.vertices(), poly.normal());
        let e1 = nrm.any_orthonormal_pair().0;
        let e2 = nrm.cross(e1);
        // Halton (2, 3, 5, 7) points: origins and cosine-weighted directions.
        let radical = |mut k: usize, b: usize| {
            let (mut f, mut r) = (1.0, 0.0);
            while k > 0 {
                f /= b as f64;
                r += f * (k % b) as f64;
                k /= b;
            }
            r
        };
        let counts = (1..=rays)
            .into_par_iter()
            .fold(
                || vec![0u64; n + 1],
                |mut c, k| {
                    let o = point(v, radical(k, 2), radical(k, 3));
                    let (r1, r2) = (radical(k, 5), radical(k, 7));
                    let (r, phi) = (r1.sqrt(), std::f64::consts::TAU * r2);
                    let d = e1 * (r * phi.cos()) + e2 * (r * phi.sin()) + nrm * (1.0 - r1).sqrt();
                    let nearest = tris
                        .iter()
                        .filter(|(p, _)| *p != i)
                        .filter_map(|(p, t)| hit(o, d, *t).filter(|&s| s > 1e-12).map(|s| (s, *p)))
                        .min_by(|a, b| a.0.total_cmp(&b.0));
                    // A back face takes no view factor: the ray counts as escaped.
                    let front = nearest.filter(|h| scene.patches[h.1].polygon.normal().dot(d) < 0.0);
                    c[front.map_or(n, |h| h.1)] += 1;
                    c
                },
            )
            .reduce(|| vec![0u64; n + 1], |a, b| a.iter().zip(&b).map(|(x, y)| x + y).collect());
        let mut row: HashMap<usize, (f64, f64)> = HashMap::new();
        for line in csv.lines().skip(1) {
            let f: Vec<&str> = line.split(',').collect();
            if f.len() >= 4 && f[0] == name.as_str() {
                row.insert(index[f[1]], (f[2].parse().unwrap(), f[3].parse().unwrap_or(0.0)));
            }
        }
        let mut worst = (0.0f64, 0usize);
        for (j, &count) in counts[..n].iter().enumerate() {
            let share = count as f64 / rays as f64;
            let (f, se) = row.get(&j).copied().unwrap_or((0.0, 0.0));
            let se_rays = (share * (1.0 - share) / rays as f64).sqrt().max(1.0 / rays as f64);
            let z = (f - share) / (se * se + se_rays * se_rays).sqrt();
            if z.abs() > worst.0.abs() {
                worst = (z, j);
            }
            if z.abs() > Z_FLAG && (f - share).abs() > DIFF_FLAG {
                flagged.push(format!(
                    "{name} -> {}: F {f:.5e} ± {se:.1e}, rays {share:.5e} ± {se_rays:.1e}, z {z:.1}",
                    scene.patch_name(j)
                ));
            }
        }
        let sum: f64 = row.values().map(|e| e.0).sum();
        println!(
            "{name}: row sum {sum:.5}, escaped {}, worst z {:.1} ({})",
            counts[n],
            worst.0,
            scene.patch_name(worst.1)
        );
    }
    println!("flagged {}", flagged.len());
    for f in flagged {
        println!("{f}");
    }
}
