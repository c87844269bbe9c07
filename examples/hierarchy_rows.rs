//! Row sums of the hierarchical exchange against the dense path, per patch and per surface,
//! with each row's link error bound, and the largest entry differences of the worst row:
//! where a link's area sharing moves exchange between patches, and whether the bounds hold.
//!
//! Run: cargo run --release --features studies --example hierarchy_rows -- SCENE.toml [TOLERANCE]
use lambert::exchange::hierarchy::Hierarchy;
use lambert::exchange::operator::Operator;
fn main() {
    let path = std::env::args().nth(1).unwrap();
    let tol: f64 = std::env::args().nth(2).map_or(1e-3, |s| s.parse().unwrap());
    let scene = lambert::scene::load(std::path::Path::new(&path)).unwrap();
    let vf = lambert::viewfactor::Params::default();
    let h = Hierarchy::build(&scene, &vf, tol, &lambert::solve::clustered::budget(&scene)).unwrap();
    eprintln!("{:?}", h.stats);
    let n = scene.patches.len();
    let sums = h.matvec_scaled(None, &vec![1.0; n]);
    let errs = h.row_errors();
    let t = lambert::viewfactor::compute_triangle(&scene, &vf).unwrap().unwrap();
    let dsums = t.row_sums();
    let mut worst: Vec<(f64, usize)> =
        (0..n).map(|i| ((sums[i] - dsums[i]).abs() / h.areas()[i], i)).collect();
    worst.sort_by(|a, b| b.0.total_cmp(&a.0));
    for &(d, i) in worst.iter().take(10) {
        println!(
            "{} hier {:.6} dense {:.6} diff {:.3e} errbound {:.3e}",
            scene.patch_name(i),
            sums[i] / h.areas()[i],
            dsums[i] / h.areas()[i],
            d,
            errs[i] / h.areas()[i]
        );
    }
    let m = scene.surfaces.len();
    let (mut hs, mut ds, mut es, mut a) = (vec![0.0; m], vec![0.0; m], vec![0.0; m], vec![0.0; m]);
    for (i, p) in scene.patches.iter().enumerate() {
        hs[p.surface] += sums[i];
        ds[p.surface] += dsums[i];
        es[p.surface] += errs[i];
        a[p.surface] += h.areas()[i];
    }
    for k in 0..m {
        println!(
            "surface {} hier {:.6} dense {:.6} diff {:.3e} errbound {:.3e}",
            scene.surfaces[k].name,
            hs[k] / a[k],
            ds[k] / a[k],
            (hs[k] - ds[k]).abs() / a[k],
            es[k] / a[k]
        );
    }
    // per-entry check for the worst patch
    let i = worst[0].1;
    let mut e = vec![0.0; n];
    e[i] = 1.0;
    let row = h.matvec_scaled(None, &e);
    let mut diffs: Vec<(f64, usize)> = (0..n).map(|j| (row[j] - t.get(i.min(j), i.max(j)), j)).collect();
    diffs.sort_by(|a, b| b.0.abs().total_cmp(&a.0.abs()));
    for &(d, j) in diffs.iter().take(10) {
        println!(
            "  {} -> {}: hier {:.4e} dense {:.4e} diff {:.3e}",
            scene.patch_name(i),
            scene.patch_name(j),
            row[j],
            t.get(i.min(j), i.max(j)),
            d
        );
    }
}
