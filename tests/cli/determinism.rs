//! Every `solve` path gives byte-identical output on 1 and 2 threads (SPEC: "the same seed
//! gives the same result whatever the thread count"): the lean dense path, saved view factors
//! and conductances (dense LLT), the hierarchical links, Jacobi, Gauss–Seidel and semi-gray
//! bands. The furnace has 600 patches: enough for faer's parallel kernels, whose split of a
//! sum followed the thread count before they were made sequential.
use std::path::Path;
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_lambert");

fn run(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().expect("run lambert")
}

/// The cube furnace with 10 × 10 patches per face.
fn furnace(dir: &Path) -> String {
    let text =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/cube_furnace/scene.toml"))
            .unwrap()
            .replace("subdivide = [4, 4]", "subdivide = [10, 10]");
    let path = dir.join("furnace.toml");
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_string()
}

/// Runs `solve SCENE ARGS -o out --threads t` and returns the bytes of `out` and of every
/// extra file named in `files`.
fn outputs(dir: &Path, scene: &str, args: &[&str], files: &[&str], threads: usize) -> Vec<Vec<u8>> {
    let out = dir.join(format!("out_{threads}.csv"));
    let t = threads.to_string();
    let mut all = vec!["solve", scene, "-o", out.to_str().unwrap(), "--threads", &t];
    all.extend_from_slice(args);
    let o = run(&all);
    assert!(o.status.success(), "{all:?}: {}", String::from_utf8_lossy(&o.stderr));
    std::iter::once(out.to_path_buf())
        .chain(files.iter().map(|f| dir.join(f)))
        .map(|p| std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display())))
        .collect()
}

fn assert_same_on_1_and_2_threads(dir: &Path, scene: &str, what: &str, args: &[&str], files: &[&str]) {
    let one = outputs(dir, scene, args, files, 1);
    let two = outputs(dir, scene, args, files, 2);
    for (k, (a, b)) in one.iter().zip(&two).enumerate() {
        let name = if k == 0 { "the solve CSV" } else { files[k - 1] };
        assert!(a == b, "{what}: {name} differs between --threads 1 and 2");
    }
}

#[test]
fn every_solve_path_is_byte_identical_on_one_and_two_threads() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = furnace(d);
    let vf = d.join("vf.csv");
    let o = run(&["viewfactors", &scene, "--patches", "-o", vf.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let radk = d.join("radk.csv");
    let cases: [(&str, Vec<&str>, Vec<&str>); 6] = [
        ("lean dense", vec![], vec![]),
        ("--viewfactors (dense LLT)", vec!["--patches", "--viewfactors", vf.to_str().unwrap()], vec![]),
        ("--conductances", vec!["--patches", "--conductances", radk.to_str().unwrap()], vec!["radk.csv"]),
        ("hierarchical", vec!["--exchange", "hierarchical"], vec![]),
        ("jacobi", vec!["--solver", "jacobi"], vec![]),
        ("gauss-seidel", vec!["--solver", "gauss-seidel"], vec![]),
    ];
    for (what, args, files) in &cases {
        assert_same_on_1_and_2_threads(d, &scene, what, args, files);
    }
}

#[test]
fn semi_gray_bands_are_byte_identical_on_one_and_two_threads() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = furnace(d);
    let text = std::fs::read_to_string(&scene).unwrap().replace(
        "emissivity = 0.8\ntemperature = 1000.0",
        "emissivity = 0.8\nemissivity_bands = [0.3, 0.8]\ntemperature = 1000.0",
    ) + "\n[[band]]\nname = \"short\"\nlower = 0.0\nupper = 4.0\n\n[[band]]\nname = \"long\"\nlower = 4.0\n";
    std::fs::write(&scene, text).unwrap();
    assert_same_on_1_and_2_threads(d, &scene, "bands", &["--patches"], &[]);
}
