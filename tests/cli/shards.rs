//! `viewfactors --shard I/K` and `lambert merge`: the merged parts are the single run's file,
//! byte for byte, for K = 1, 2, 3 and parts in any order (analytic, auto and Monte Carlo,
//! per patch and per surface, with enforcement); every bad merge is refused (exit 2, naming
//! the file) and leaves the earlier output and the parts as they were.
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_lambert");

fn run(dir: &Path, args: &[&str]) -> Output {
    Command::new(BIN).current_dir(dir).args(args).output().expect("run lambert")
}

fn ok(dir: &Path, args: &[&str]) -> Output {
    let o = run(dir, args);
    assert!(o.status.success(), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
    o
}

/// Runs `args`, expects exit 2 and returns stderr.
fn refused(dir: &Path, args: &[&str]) -> String {
    let o = run(dir, args);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(2), "{args:?} should be refused: {err}");
    assert!(!err.contains("internal error"), "{err}");
    err
}

fn case(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("cases").join(name).join("scene.toml").to_str().unwrap().into()
}

/// Two squares with a blocker between them, 4 × 4 patches each (open scene).
fn blocked() -> String {
    case("o1_squares_centred_blocker")
}

/// Writes the parts of `K` shards of `viewfactors SCENE ARGS` into `dir`; returns their paths.
fn parts(dir: &Path, scene: &str, args: &[&str], k: usize, tag: &str) -> Vec<String> {
    (0..k)
        .map(|i| {
            let path = dir.join(format!("{tag}_part_{i}")).to_str().unwrap().to_string();
            let shard = format!("{i}/{k}");
            let mut all = vec!["viewfactors", scene, "--shard", &shard, "-o", &path];
            all.extend_from_slice(args);
            ok(dir, &all);
            path
        })
        .collect()
}

/// The single run's CSV and the merged CSV of K = 1, 2, 3 shards (parts given rotated or
/// reversed) are the same bytes.
fn assert_merge_is_single_run(scene: &str, args: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let single = d.join("single.csv");
    let mut all = vec!["viewfactors", scene, "-o", single.to_str().unwrap()];
    all.extend_from_slice(args);
    ok(d, &all);
    let want = std::fs::read(&single).unwrap();
    assert!(want.len() > 100, "{args:?}: the single run wrote {} bytes", want.len());
    for k in 1..=3 {
        let mut files = parts(d, scene, args, k, &format!("k{k}"));
        if k == 2 {
            files.rotate_left(1);
        } else {
            files.reverse();
        }
        let merged = d.join(format!("merged_{k}.csv"));
        let mut m = vec!["merge", "-o", merged.to_str().unwrap()];
        m.extend(files.iter().map(String::as_str));
        let o = ok(d, &m);
        let got = std::fs::read(&merged).unwrap();
        assert!(got == want, "{args:?}: merging {k} shards differs from the single run");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(&format!("merging {k} parts")), "{err}");
    }
}

#[test]
fn analytic_rows_merge_to_the_single_run() {
    assert_merge_is_single_run(&blocked(), &["-m", "analytic", "--patches"]);
}

#[test]
fn auto_rows_merge_to_the_single_run_per_patch_and_per_surface() {
    assert_merge_is_single_run(&blocked(), &["--patches"]);
    assert_merge_is_single_run(&blocked(), &["--tolerance", "1e-3"]);
}

#[test]
fn monte_carlo_rows_merge_to_the_single_run() {
    // Seeds are per row: shard i draws the same streams as the single run's rows.
    assert_merge_is_single_run(
        &blocked(),
        &["-m", "mc-cosine", "--samples", "2000", "--patches", "--seed", "7"],
    );
    assert_merge_is_single_run(&blocked(), &["-m", "mc-area", "--samples", "300"]);
}

#[test]
fn enforced_rows_of_a_closed_scene_merge_to_the_single_run() {
    // Closure is enforced at the merge, on every row, as in the single run.
    assert_merge_is_single_run(
        &case("cube_furnace"),
        &["-m", "analytic", "--enforce", "closure", "--patches"],
    );
}

#[test]
fn a_merged_csv_feeds_solve_like_the_single_run() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = case("cube_furnace");
    let files = parts(d, &scene, &["-m", "analytic"], 2, "s");
    ok(d, &["merge", &files[0], &files[1], "-o", "merged.csv"]);
    ok(d, &["viewfactors", &scene, "-m", "analytic", "-o", "single.csv"]);
    ok(d, &["solve", &scene, "--viewfactors", "merged.csv", "-o", "a.csv"]);
    ok(d, &["solve", &scene, "--viewfactors", "single.csv", "-o", "b.csv"]);
    assert_eq!(std::fs::read(d.join("a.csv")).unwrap(), std::fs::read(d.join("b.csv")).unwrap());
}

/// A directory with the 3 parts of a run and an earlier `merged.csv`.
fn three_parts() -> (tempfile::TempDir, Vec<String>) {
    let dir = tempfile::tempdir().unwrap();
    let files = parts(dir.path(), &blocked(), &["-m", "analytic", "--patches"], 3, "p");
    std::fs::write(dir.path().join("merged.csv"), "earlier\n").unwrap();
    (dir, files)
}

/// Merges `files` into `merged.csv`, expects a refusal naming `names`, and checks that the
/// earlier `merged.csv` is untouched.
fn refused_merge(d: &Path, files: &[&str], names: &str, says: &str) {
    let mut m = vec!["merge", "-o", "merged.csv"];
    m.extend_from_slice(files);
    let err = refused(d, &m);
    assert!(err.contains(names), "the refusal should name {names}: {err}");
    assert!(err.contains(says), "the refusal should say '{says}': {err}");
    assert_eq!(std::fs::read_to_string(d.join("merged.csv")).unwrap(), "earlier\n");
}

#[test]
fn a_missing_or_repeated_shard_is_refused() {
    let (dir, f) = three_parts();
    let d = dir.path();
    refused_merge(d, &[&f[0], &f[2]], "p_part_0", "shard(s) 1/3 are missing");
    refused_merge(d, &[&f[0], &f[1], &f[1], &f[2]], "p_part_1", "each shard is given once");
}

#[test]
fn parts_of_other_runs_are_refused() {
    let (dir, f) = three_parts();
    let d = dir.path();
    // Another tolerance: the same K, another hash of the options.
    let other = parts(d, &blocked(), &["-m", "analytic", "--patches", "--tolerance", "1e-5"], 3, "q");
    refused_merge(d, &[&f[0], &other[1], &f[2]], "q_part_1", "another scene or with other options");
    // Another K.
    let two = parts(d, &blocked(), &["-m", "analytic", "--patches"], 2, "r");
    refused_merge(d, &[&f[0], &f[1], &two[1]], "r_part_1", "the parts of one run share K");
}

#[test]
fn truncated_damaged_and_foreign_parts_are_refused() {
    let (dir, f) = three_parts();
    let d = dir.path();
    let bytes = std::fs::read(&f[1]).unwrap();
    let cut = d.join("cut");
    std::fs::write(&cut, &bytes[..bytes.len() - 10]).unwrap();
    refused_merge(d, &[&f[0], cut.to_str().unwrap(), &f[2]], "cut", "truncated");
    let mut flipped = bytes.clone();
    let last = flipped.len() - 5;
    flipped[last] ^= 0x40;
    let bad = d.join("flipped");
    std::fs::write(&bad, flipped).unwrap();
    refused_merge(d, &[&f[0], bad.to_str().unwrap(), &f[2]], "flipped", "damaged");
    let csv = d.join("table.csv");
    std::fs::write(&csv, "from,to,factor\na,b,0.5\n").unwrap();
    refused_merge(
        d,
        &[&f[0], csv.to_str().unwrap(), &f[2]],
        "table.csv",
        "not a lambert view-factor part (the file a --shard run writes)",
    );
}

#[test]
fn a_scene_changed_since_the_shards_is_refused() {
    let (dir, f) = three_parts();
    let d = dir.path();
    let moved = d.join("moved.toml");
    let text = std::fs::read_to_string(blocked()).unwrap().replace("0.25, 0.25, 0.5", "0.2, 0.25, 0.5");
    std::fs::write(&moved, text).unwrap();
    let mut m = vec!["merge", "-o", "merged.csv", "--scene", moved.to_str().unwrap()];
    m.extend(f.iter().map(String::as_str));
    let err = refused(d, &m);
    assert!(err.contains("p_part_0") && err.contains("another scene geometry"), "{err}");
    assert_eq!(std::fs::read_to_string(d.join("merged.csv")).unwrap(), "earlier\n");
    // The same geometry under another path merges.
    let copy = d.join("copy.toml");
    std::fs::copy(blocked(), &copy).unwrap();
    m[4] = copy.to_str().unwrap();
    ok(d, &m);
}

#[test]
fn a_merge_never_overwrites_a_part() {
    let (dir, f) = three_parts();
    let d = dir.path();
    let before = std::fs::read(&f[1]).unwrap();
    let err = refused(d, &["merge", &f[0], &f[1], &f[2], "-o", &f[1]]);
    assert!(err.contains("a part file given to lambert merge"), "{err}");
    assert_eq!(std::fs::read(&f[1]).unwrap(), before);
}

#[test]
fn bad_shard_options_are_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = blocked();
    for (shard, says) in [
        ("3/3", "numbered 0 to 2"),
        ("0/0", "K must be 1"),
        ("a/2", "whole numbers"),
        ("1-3", "give I/K"),
        ("-1/3", "whole numbers"),
    ] {
        let err = refused(d, &["viewfactors", &s, "--shard", shard, "-o", "part"]);
        assert!(err.contains(says), "--shard {shard}: {err}");
    }
    assert!(refused(d, &["viewfactors", &s, "--shard", "0/2"]).contains("give -o FILE"));
    assert!(refused(d, &["viewfactors", &s, "--shard", "0/2", "-o", "-"]).contains("give -o FILE"));
    assert!(refused(d, &["viewfactors", &s, "--shard", "0/2", "-o", "p", "--vtk", "a.vtu"]).contains("--vtk"));
    let pts = d.join("points.csv");
    std::fs::write(&pts, "x,y,z,nx,ny,nz\n0.5,0.5,0.1,0,0,1\n").unwrap();
    let err =
        refused(d, &["viewfactors", &s, "--points", pts.to_str().unwrap(), "--shard", "0/2", "-o", "p"]);
    assert!(err.contains("--points"), "{err}");
    // `solve` has no shards: its view factors come from a merged CSV (--viewfactors).
    assert!(refused(d, &["solve", &s, "--shard", "0/2", "-o", "p"]).contains("--shard"));
    assert!(!d.join("part").exists() && !d.join("p").exists(), "a refused shard wrote a part");
    let nothing: Vec<PathBuf> = std::fs::read_dir(d).unwrap().map(|e| e.unwrap().path()).collect();
    assert_eq!(nothing, vec![pts]);
}
