//! Entry-by-entry difference of two `viewfactors --shard` parts of the same scene and rows
//! (validation/cad.md, the channel's part rows): `part_diff SCENE A.part B.part [TOL]` prints
//! the largest |ΔA_iF_ij| over the pair's goal `TOL`·min(A_i, A_j) (default 1e-4), the entry
//! where it is, and how many entries moved at all.
use lambert::viewfactor::shard;
use std::collections::HashMap;
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let scene = lambert::scene::load(Path::new(&args[1])).expect("scene loads");
    let (a, b) = (
        shard::read(Path::new(&args[2])).expect("part A"),
        shard::read(Path::new(&args[3])).expect("part B"),
    );
    let tol: f64 = args.get(4).map_or(1e-4, |s| s.parse().expect("TOL is a number"));
    assert_eq!(a.rows(), b.rows(), "the parts hold the same rows");
    let area = |k: usize| scene.patches[k].polygon.area();
    let (mut worst, mut at, mut moved, mut entries) = (0.0f64, (0, 0), 0usize, 0usize);
    for (k, (ra, rb)) in a.share.rows.iter().zip(&b.share.rows).enumerate() {
        let i = a.share.first + k;
        let mut m: HashMap<u32, (f64, f64)> = HashMap::new();
        for e in &ra.entries {
            m.entry(e.j).or_default().0 = e.s;
        }
        for e in &rb.entries {
            m.entry(e.j).or_default().1 = e.s;
        }
        for (&j, &(sa, sb)) in &m {
            entries += 1;
            if sa != sb {
                moved += 1;
            }
            let r = (sa - sb).abs() / (tol * area(i).min(area(j as usize)));
            if r > worst {
                (worst, at) = (r, (i, j as usize));
            }
        }
    }
    println!(
        "rows {:?}: {entries} entries, {moved} differ; largest |dS| / goal {worst:.3e} at ({}, {})",
        a.rows(),
        at.0,
        at.1
    );
}
