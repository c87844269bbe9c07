//! Progress on stderr without a terminal: a line per interval of a long run, counted on pairs
//! done, and silence with `--quiet`; the numbers are the same either way.
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_lambert");
/// The log interval for the test, seconds: far below the run's length.
const EVERY: &str = "0.02";

/// A closed cube, 10 × 10 patches per face, by Monte Carlo with enough rays to run for a while.
fn scene(dir: &std::path::Path) -> std::path::PathBuf {
    let faces = [
        ("floor", "[0,0,0]", "[1,0,0]", "[0,1,0]"),
        ("ceiling", "[0,0,1]", "[0,1,0]", "[1,0,0]"),
        ("wall_y0", "[0,0,0]", "[0,0,1]", "[1,0,0]"),
        ("wall_y1", "[0,1,0]", "[1,0,0]", "[0,0,1]"),
        ("wall_x0", "[0,0,0]", "[0,1,0]", "[0,0,1]"),
        ("wall_x1", "[1,0,0]", "[0,0,1]", "[0,1,0]"),
    ];
    let mut s = String::new();
    for (name, o, u, v) in faces {
        s += &format!(
            "[[surface]]\nname = \"{name}\"\nrectangle = {{ origin = {o}, u = {u}, v = {v} }}\nsubdivide = [10, 10]\n\n"
        );
    }
    let p = dir.join("cube.toml");
    std::fs::write(&p, s).unwrap();
    p
}

#[test]
fn a_long_run_without_a_terminal_logs_progress_lines_and_quiet_silences_them() {
    let dir = tempfile::tempdir().unwrap();
    let cube = scene(dir.path());
    let args = ["viewfactors", cube.to_str().unwrap(), "-m", "mc-cosine", "--samples", "5000"];
    let loud = Command::new(BIN).args(args).env("LAMBERT_PROGRESS_EVERY", EVERY).output().unwrap();
    let err = String::from_utf8_lossy(&loud.stderr);
    assert!(loud.status.success(), "{err}");
    let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("lambert: progress: ")).collect();
    assert!(!lines.is_empty(), "no progress line in:\n{err}");
    // 600 patches, every row whole: 360,000 pairs, and the share never goes down.
    let mut last = 0.0;
    for l in &lines {
        assert!(l.contains("% of 360000 pairs (") && l.contains(" s elapsed"), "{l}");
        let share: f64 = l["lambert: progress: ".len()..].split('%').next().unwrap().parse().unwrap();
        assert!((last..=100.0).contains(&share), "{share} after {last}");
        last = share;
    }
    let quiet =
        Command::new(BIN).args(args).arg("--quiet").env("LAMBERT_PROGRESS_EVERY", EVERY).output().unwrap();
    let qerr = String::from_utf8_lossy(&quiet.stderr);
    assert!(quiet.status.success(), "{qerr}");
    assert!(!qerr.contains("progress"), "{qerr}");
    assert_eq!(loud.stdout, quiet.stdout, "the report never changes the numbers");
}
