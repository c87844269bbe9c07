//! Progress on stderr without a terminal: a line when a phase has run the delay, one per
//! interval while rows finish (counted on pairs done), one with the phase's time when it ends;
//! silence with `--quiet`; the numbers are the same either way.
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_lambert");
/// The log interval for the test, seconds: far below the run's length (and the phase delay
/// with it).
const EVERY: &str = "0.02";
const PREFIX: &str = "lambert: progress: ";

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
            "[[surface]]\nname = \"{name}\"\nrectangle = {{ origin = {o}, u = {u}, v = {v} }}\nsubdivide = [10, 10]\ntemperature = 300.0\nemissivity = 0.8\n\n"
        );
    }
    s = s.replacen("temperature = 300.0", "temperature = 1000.0", 1);
    let p = dir.join("cube.toml");
    std::fs::write(&p, s).unwrap();
    p
}

fn progress_lines(err: &str) -> Vec<&str> {
    err.lines().filter_map(|l| l.strip_prefix(PREFIX)).collect()
}

#[test]
fn a_long_run_without_a_terminal_logs_progress_lines_and_quiet_silences_them() {
    let dir = tempfile::tempdir().unwrap();
    let cube = scene(dir.path());
    let args = ["viewfactors", cube.to_str().unwrap(), "-m", "mc-cosine", "--samples", "5000"];
    let loud = Command::new(BIN).args(args).env("LAMBERT_PROGRESS_EVERY", EVERY).output().unwrap();
    let err = String::from_utf8_lossy(&loud.stderr);
    assert!(loud.status.success(), "{err}");
    let lines = progress_lines(&err);
    // The view-factor phase says when it started, then its counts, then its time.
    let started = lines.iter().position(|l| l.starts_with("view factors (started at "));
    let took = lines.iter().position(|l| l.starts_with("view factors took ") && l.ends_with(" s"));
    let counts: Vec<&str> = lines.iter().filter_map(|l| l.strip_prefix("view factors: ")).collect();
    assert!(started.is_some() && took.is_some() && !counts.is_empty(), "{err}");
    assert!(started < took, "{err}");
    // 600 patches, every row whole: 360,000 pairs, and the share never goes down.
    let mut last = 0.0;
    for l in &counts {
        assert!(l.contains("% of 360000 pairs (") && l.contains(" s elapsed"), "{l}");
        let share: f64 = l.split('%').next().unwrap().parse().unwrap();
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

#[test]
fn a_shard_counts_its_own_pairs() {
    let dir = tempfile::tempdir().unwrap();
    let cube = scene(dir.path());
    let part = dir.path().join("part_1");
    let args = [
        "viewfactors",
        cube.to_str().unwrap(),
        "-m",
        "mc-cosine",
        "--samples",
        "5000",
        "--shard",
        "1/3",
        "-o",
    ];
    let run = Command::new(BIN).args(args).arg(&part).env("LAMBERT_PROGRESS_EVERY", EVERY).output().unwrap();
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{err}");
    // Whole rows of 600 pairs, a third of the 600 rows: 120,000 pairs, and the count moves.
    let counts: Vec<&str> =
        progress_lines(&err).into_iter().filter_map(|l| l.strip_prefix("view factors: ")).collect();
    assert!(!counts.is_empty(), "{err}");
    assert!(counts.iter().all(|l| l.contains("% of 120000 pairs (")), "{err}");
    assert!(counts.iter().any(|l| !l.starts_with("0.0%")), "{err}");
}

/// Runs `args` with a 1 ms log interval (every phase of a millisecond or more is named with
/// its time): the run, and the solve phases (view factors, enforcement, solve) that said how
/// long they took, in order.
fn timed_phases(args: &[&str]) -> (std::process::Output, Vec<String>) {
    let run = Command::new(BIN).args(args).env("LAMBERT_PROGRESS_EVERY", "0.001").output().unwrap();
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{err}");
    let took = progress_lines(&err)
        .into_iter()
        .filter_map(|l| l.split_once(" took ").map(|(phase, _)| phase.to_string()))
        .filter(|p| ["view factors", "enforcement", "solve"].contains(&p.as_str()))
        .collect();
    (run, took)
}

#[test]
fn a_dense_solve_logs_each_phase_with_its_time() {
    let dir = tempfile::tempdir().unwrap();
    let cube = scene(dir.path());
    // 600 unknowns: the view factors, the closure and the dense solve each take milliseconds,
    // in this order (loading, the blockers' set-up and writing may be quicker).
    let (loud, order) = timed_phases(&["solve", cube.to_str().unwrap(), "--patches"]);
    assert_eq!(order, ["view factors", "enforcement", "solve"], "{}", String::from_utf8_lossy(&loud.stderr));
    let quiet = Command::new(BIN)
        .args(["solve", cube.to_str().unwrap(), "--patches", "-q"])
        .env("LAMBERT_PROGRESS_EVERY", "0.001")
        .output()
        .unwrap();
    assert!(quiet.status.success() && quiet.stderr.is_empty(), "{}", String::from_utf8_lossy(&quiet.stderr));
    assert_eq!(loud.stdout, quiet.stdout, "the report never changes the numbers");
}

#[test]
fn a_clustered_solve_logs_its_enforcement_and_solve_too() {
    // The hierarchical route builds its links in the view-factor phase, then enforces and
    // solves on them: each phase named with its time, in order.
    let dir = tempfile::tempdir().unwrap();
    let cube = scene(dir.path());
    let (run, took) =
        timed_phases(&["solve", cube.to_str().unwrap(), "--patches", "--exchange", "hierarchical"]);
    assert_eq!(took, ["view factors", "enforcement", "solve"], "{}", String::from_utf8_lossy(&run.stderr));
}
