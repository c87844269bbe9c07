//! View3D `.vs3` files end to end from the CLI: a bare `.vs3` as the scene (its `eps` and
//! `encl` as run defaults, command-line options winning), a `[[model]]` inside a TOML scene
//! for `solve`, and refusals with exit 2 that keep an earlier output.
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_lambert");
/// Howell C-11: unit squares facing each other at gap 1.
const F_OPPOSITE: f64 = 0.199_824_895_698_387_5;
/// Exact method, and closure rescaling of rows already exact to that level.
const EXACT_TOL: f64 = 1e-9;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/vs3").join(name)
}

fn run(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().expect("run lambert")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// F(from → to) from a `viewfactors` CSV.
fn factor(csv: &str, from: &str, to: &str) -> f64 {
    csv.lines()
        .skip(1)
        .map(|l| l.split(',').collect::<Vec<_>>())
        .find(|f| f[0] == from && f[1] == to)
        .unwrap_or_else(|| panic!("no row {from},{to} in\n{csv}"))[2]
        .parse()
        .unwrap()
}

#[test]
fn a_view3d_file_runs_with_its_own_eps_and_enclosure() {
    let cube = data("cube.vs3");
    let o = run(&["viewfactors", cube.to_str().unwrap()]);
    let err = text(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("tolerance 0.000001 from the scene file (View3D eps)"), "{err}");
    assert!(
        err.contains("enforce closure: the scene file declares a closed enclosure (View3D encl = 1)"),
        "{err}"
    );
    let csv = text(&o.stdout);
    assert!(csv.starts_with("from,to,factor"));
    assert!((factor(&csv, "floor", "ceiling") - F_OPPOSITE).abs() < EXACT_TOL);

    // The command line wins over the file.
    let o = run(&["viewfactors", cube.to_str().unwrap(), "--tolerance", "1e-4", "--enforce", "none"]);
    let err = text(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(!err.contains("from the scene file") && !err.contains("enforce closure"), "{err}");
}

#[test]
fn an_open_view3d_file_sends_the_rest_to_the_ambient() {
    let f = data("blocked_squares.vs3");
    let o = run(&["viewfactors", f.to_str().unwrap(), "-m", "analytic"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let csv = text(&o.stdout);
    // The top sees the bottom past the plate, and the plate's front; the rest leaves.
    let rest = factor(&csv, "top", "ambient");
    let seen: f64 = ["bottom", "plate"].iter().map(|t| factor(&csv, "top", t)).sum();
    assert!((rest + seen - 1.0).abs() < EXACT_TOL, "top: ambient {rest} + surfaces {seen}");
    assert!(!csv.contains("bottom,plate,"), "the plate faces away from the bottom");
}

#[test]
fn solve_on_a_scene_with_a_view3d_model() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(data("l_room.vs3"), dir.path().join("room.vs3")).unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(
        &scene,
        "[defaults]\ntemperature = 300.0\n\n[[model]]\nfile = \"room.vs3\"\n\n\
         [[surface]]\nname = \"floor\"\ntemperature = 1000.0\n",
    )
    .unwrap();
    let o = run(&["solve", scene.to_str().unwrap()]);
    let err = text(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("control values (encl, emit, eps) of a [[model]] are ignored"), "{err}");
    let out = text(&o.stdout);
    let rows: Vec<Vec<&str>> = out.lines().skip(1).map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 8, "eight surfaces after combining, closed (no ambient row)");
    let floor = rows.iter().find(|r| r[0] == "floor").unwrap();
    assert_eq!(floor[2], "0.9", "emittance from the View3D file");
    let q: Vec<f64> = rows.iter().map(|r| r[5].parse().unwrap()).collect();
    let max = q.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(q[0] > 0.0 && q.iter().sum::<f64>().abs() < 1e-9 * max, "{q:?}");
}

#[test]
fn bad_view3d_files_exit_2_name_file_and_line_and_keep_the_output() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.vs3");
    std::fs::write(&bad, "F 3\nV 1 0 0 0\nV 2 1 0 0\nV 3 1 1 0\nS 1 1 2 3 0 1 0 0.5 sub\n").unwrap();
    let out = dir.path().join("vf.csv");
    std::fs::write(&out, "from,to,factor\nearlier,result,0.5\n").unwrap();
    let o = run(&["viewfactors", bad.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("bad.vs3:5: surface 1 is a subsurface of surface 1"), "{err}");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "from,to,factor\nearlier,result,0.5\n");

    // No boundary conditions in a bare View3D file: solve says which surface lacks one.
    let o = run(&["solve", data("cube.vs3").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    let err = text(&o.stderr);
    assert!(err.contains("cube.vs3") && err.contains("floor"), "{err}");
}
