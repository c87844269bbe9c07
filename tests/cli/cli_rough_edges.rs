//! What a new user meets first, end to end from the CLI: input values written back as given,
//! deep space at 0 K, the °C warning, honest stderr summaries, leak messages that name an
//! outward-facing closed mesh, and defaults shown by `--help`.
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_lambert");

fn run(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().expect("run lambert")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

fn scene(dir: &Path, toml: &str) -> PathBuf {
    let p = dir.join("scene.toml");
    std::fs::write(&p, toml).unwrap();
    p
}

/// A unit cube: floor at `floor_t` ε 0.8 split 4×4 (area-weighted means of 0.8 and 1000 are not
/// 0.8 and 1000 in floating point), the other faces as `rest`; with an `[ambient]` the ceiling
/// is left out (open top).
fn cube(ambient: &str, floor_t: f64, rest: &str) -> String {
    let faces = [
        ("ceiling", "[0,0,1]", "[0,1,0]", "[1,0,0]"),
        ("wall_y0", "[0,0,0]", "[0,0,1]", "[1,0,0]"),
        ("wall_y1", "[0,1,0]", "[1,0,0]", "[0,0,1]"),
        ("wall_x0", "[0,0,0]", "[0,1,0]", "[0,0,1]"),
        ("wall_x1", "[1,0,0]", "[0,0,1]", "[0,1,0]"),
    ];
    let mut s = format!(
        "{ambient}\n[[surface]]\nname = \"floor\"\nrectangle = {{ origin = [0,0,0], u = [1,0,0], v = [0,1,0] }}\n\
         emissivity = 0.8\ntemperature = {floor_t:?}\nsubdivide = [4, 4]\n"
    );
    for (name, o, u, v) in faces.into_iter().filter(|f| ambient.is_empty() || f.0 != "ceiling") {
        s += &format!(
            "\n[[surface]]\nname = \"{name}\"\nrectangle = {{ origin = {o}, u = {u}, v = {v} }}\nsubdivide = [3, 3]\n{rest}\n"
        );
    }
    s
}

fn row<'a>(csv: &'a str, name: &str) -> Vec<&'a str> {
    csv.lines()
        .find(|l| l.starts_with(&format!("{name},")))
        .unwrap_or_else(|| panic!("{name} in {csv}"))
        .split(',')
        .collect()
}

#[test]
fn solve_writes_input_values_back_as_given() {
    let dir = tempfile::tempdir().unwrap();
    let p = scene(dir.path(), &cube("", 1000.0, "emissivity = 0.7\nheat_flux = 0.0"));
    let o = run(&["solve", p.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let csv = text(&o.stdout);
    let floor = row(&csv, "floor");
    assert_eq!((floor[2], floor[3]), ("0.8", "1000"), "{csv}");
    let wall = row(&csv, "wall_y0");
    assert_eq!((wall[2], wall[4]), ("0.7", "0"), "{csv}");
    // Per patch as well: every floor patch carries the given temperature exactly.
    let o = run(&["solve", p.to_str().unwrap(), "--patches"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let csv = text(&o.stdout);
    for k in 0..16 {
        let r = row(&csv, &format!("floor#{k}"));
        assert_eq!((r[2], r[3]), ("0.8", "1000"), "{csv}");
    }
    // The energy-balance totals are printed in the shortest round-trip form, not `{:.6e}`.
    let err = text(&o.stderr);
    let line = err.lines().find(|l| l.contains("energy balance")).expect("balance line");
    let max: &str = line.split("max |heat_rate| = ").nth(1).unwrap().split(' ').next().unwrap();
    let v: f64 = max.parse().unwrap();
    assert_eq!(format!("{v}"), max, "{line}");
}

#[test]
fn deep_space_at_zero_kelvin_is_accepted_and_finite() {
    let dir = tempfile::tempdir().unwrap();
    let p = scene(
        dir.path(),
        &cube("[ambient]\ntemperature = 0.0\n", 1000.0, "emissivity = 0.5\nheat_flux = 0.0"),
    );
    let o = run(&["solve", p.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let csv = text(&o.stdout);
    let amb = row(&csv, "ambient");
    assert_eq!((amb[3], amb[6]), ("0", "0"), "{csv}");
    let q: f64 = amb[5].parse().unwrap();
    assert!(q.is_finite() && q < 0.0, "the environment at 0 K only absorbs: {csv}");
    for l in csv.lines().skip(1) {
        assert!(!l.contains("NaN") && !l.contains("inf"), "{csv}");
    }
    // Below 0 K is still refused.
    let p = scene(
        dir.path(),
        &cube("[ambient]\ntemperature = -1.0\n", 1000.0, "emissivity = 0.5\nheat_flux = 0.0"),
    );
    let o = run(&["solve", p.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("ambient temperature is -1 K"), "{}", text(&o.stderr));
}

#[test]
fn celsius_temperatures_get_a_warning_and_the_run_goes_on() {
    let dir = tempfile::tempdir().unwrap();
    let p = scene(dir.path(), &cube("", 1000.0, "emissivity = 0.5\ntemperature = 25.0"));
    let o = run(&["solve", p.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let err = text(&o.stderr);
    assert!(
        err.contains("surface 'wall_y0': temperature 25 K is below 100 K while the scene reaches 1000 K")
            && err.contains("was 25 °C (298.15 K) meant?"),
        "{err}"
    );
    // A cold scene (a cryostat at 4 K and 77 K) is not second-guessed.
    let p = scene(dir.path(), &cube("", 77.0, "emissivity = 0.5\ntemperature = 4.0"));
    let o = run(&["solve", p.to_str().unwrap()]);
    assert!(o.status.success() && !text(&o.stderr).contains("°C"), "{}", text(&o.stderr));
}

#[test]
fn stderr_names_what_produced_the_rows_and_the_worst_surface() {
    let dir = tempfile::tempdir().unwrap();
    let p = scene(dir.path(), &cube("", 1000.0, "emissivity = 0.5\nheat_flux = 0.0"));
    let o = run(&["viewfactors", p.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let (out, err) = (text(&o.stdout), text(&o.stderr));
    assert!(out.lines().skip(1).all(|l| l.split(',').nth(4) == Some("analytic")), "{out}");
    assert!(err.contains("method auto (entries by analytic)"), "{err}");
    let line = err.lines().find(|l| l.contains("max |row sum - 1|")).expect("row-sum line");
    assert!(line.contains("(surface ") && !line.contains('#'), "per-surface run names a surface: {line}");
    let o = run(&["viewfactors", p.to_str().unwrap(), "--patches"]);
    let err = text(&o.stderr);
    let line = err.lines().find(|l| l.contains("max |row sum - 1|")).expect("row-sum line");
    assert!(line.contains("(patch ") && line.contains('#'), "{line}");
    // A method that does not choose per pair is reported as requested.
    let o = run(&["viewfactors", p.to_str().unwrap(), "-m", "analytic"]);
    assert!(text(&o.stderr).contains("method analytic,") || text(&o.stderr).contains("method analytic\n"));
}

#[test]
fn an_outward_closed_mesh_is_named_in_the_leak_warning_and_refusal() {
    let gltf = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/gltf/outward_box.gltf");
    let o = run(&["viewfactors", gltf.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let err = text(&o.stderr);
    assert!(err.contains("closed scene leaks"), "{err}");
    assert!(err.contains("Surface 'room' is a closed mesh whose normals all face outward"), "{err}");
    // Every row sums to 0: printed as 0, never -0.000000.
    assert!(err.contains("room (row sum 0)") && !err.contains("-0.000000"), "{err}");
    let o = run(&["viewfactors", gltf.to_str().unwrap(), "--enforce", "closure"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    let err = text(&o.stderr);
    assert!(err.contains("leaks") && err.contains("normals all face outward"), "{err}");
    // The inward box (cases/box_interior) is an enclosure: no hint.
    let inward = Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/box_interior/box.glb");
    let o = run(&["viewfactors", inward.to_str().unwrap()]);
    assert!(o.status.success() && !text(&o.stderr).contains("outward"), "{}", text(&o.stderr));
}

#[test]
fn help_shows_the_defaults_of_tolerance_and_enforce() {
    for cmd in ["viewfactors", "solve"] {
        let o = run(&[cmd, "--help"]);
        let out = text(&o.stdout);
        let tol = out.split("--tolerance").nth(1).unwrap_or_default();
        assert!(tol.split("--").next().unwrap().contains("[default: 1e-4]"), "{out}");
        let enf = out.split("--enforce").nth(1).unwrap_or_default();
        assert!(enf.split("\n  -").next().unwrap().contains("[default: none for `viewfactors`"), "{out}");
    }
}

#[test]
fn celsius_check_covers_any_plausible_pair_and_negative_values() {
    let dir = tempfile::tempdir().unwrap();
    let warned = |toml: &str| {
        let p = scene(dir.path(), toml);
        let o = run(&["solve", p.to_str().unwrap()]);
        assert!(o.status.success(), "{}", text(&o.stderr));
        text(&o.stderr)
    };
    // 200 K with 20 K walls: 20 °C is as plausible as at 300 K.
    let err = warned(&cube("", 200.0, "emissivity = 0.5\ntemperature = 20.0"));
    assert!(err.contains("temperature 20 K is below 100 K while the scene reaches 200 K"), "{err}");
    assert!(err.contains("was 20 °C (293.15 K) meant?"), "{err}");
    // An ambient at 20 beside a 300 K floor is a suspect too; deep space at 0 K is not.
    let err = warned(&cube("[ambient]\ntemperature = 20.0\n", 300.0, "emissivity = 0.5\nheat_flux = 0.0"));
    assert!(err.contains("the ambient: temperature 20 K is below 100 K"), "{err}");
    let err = warned(&cube("[ambient]\ntemperature = 0.0\n", 300.0, "emissivity = 0.5\nheat_flux = 0.0"));
    assert!(!err.contains("°C"), "{err}");
    // A cryogenic scene below 150 K stays silent (20 K inside a 77 K shield).
    let err = warned(&cube("", 77.0, "emissivity = 0.5\ntemperature = 20.0"));
    assert!(!err.contains("°C"), "{err}");
    // A negative temperature is refused, with the °C reading offered.
    let p = scene(dir.path(), &cube("", 300.0, "emissivity = 0.5\ntemperature = -20.0"));
    let o = run(&["solve", p.to_str().unwrap()]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("must be positive (kelvin)") && err.contains("was -20 °C (253.15 K) meant?"),
        "{err}"
    );
}

#[test]
fn negative_numbers_get_lambert_s_own_message() {
    let dir = tempfile::tempdir().unwrap();
    let p = scene(dir.path(), &cube("", 1000.0, "emissivity = 0.5\nheat_flux = 0.0"));
    let o = run(&["viewfactors", p.to_str().unwrap(), "--tolerance", "-1"]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("--tolerance must be in (0, 1), got -1"), "{err}");
    assert!(!err.contains("-- -1") && !err.contains("tip"), "{err}");
    for flag in ["--samples", "--threads", "--resolution"] {
        let o = run(&["viewfactors", p.to_str().unwrap(), flag, "-1"]);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{flag}: {err}");
        assert!(err.contains("invalid value '-1'") && !err.contains("-- -1"), "{flag}: {err}");
    }
}

#[test]
fn projection_methods_leave_std_error_empty() {
    let dir = tempfile::tempdir().unwrap();
    let p = scene(
        dir.path(),
        &cube("[ambient]\ntemperature = 0.0\n", 1000.0, "emissivity = 0.5\nheat_flux = 0.0"),
    );
    for (method, dense) in [("hemicube", false), ("single-plane", false), ("hemicube", true)] {
        let mut args = vec!["viewfactors", p.to_str().unwrap(), "-m", method, "--resolution", "16"];
        if dense {
            // Patch rows with enforcement take the packed store and its own CSV writer.
            args.extend(["--patches", "--enforce", "reciprocity"]);
        }
        let o = run(&args);
        assert!(o.status.success(), "{method}: {}", text(&o.stderr));
        let csv = text(&o.stdout);
        let rows: Vec<Vec<&str>> = csv.lines().skip(1).map(|l| l.split(',').collect()).collect();
        assert!(rows.iter().any(|r| r[1] == "ambient"), "{csv}");
        assert!(rows.iter().all(|r| r[3].is_empty() && r[4].contains(method)), "{method}: {csv}");
    }
    // Methods with an estimate still write it: 0 for the exact ones.
    let o = run(&["viewfactors", p.to_str().unwrap(), "-m", "analytic"]);
    let csv = text(&o.stdout);
    assert!(csv.lines().skip(1).all(|l| l.split(',').nth(3) == Some("0")), "{csv}");
}

#[test]
fn gray_emissivity_beside_band_emissivities_draws_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    // `cube` leaves the ceiling out when its first argument is not empty: the ambient closes it.
    let bands = "[ambient]\ntemperature = 300.0\n[[band]]\nname = \"solar\"\nlower = 0.0\nupper = 4.0\n\
                 [[band]]\nname = \"ir\"\nlower = 4.0\n";
    let p = scene(
        dir.path(),
        &cube(bands, 1000.0, "emissivity = 0.5\nemissivity_bands = [0.3, 0.6]\nheat_flux = 0.0"),
    );
    let o = run(&["solve", p.to_str().unwrap()]);
    let err = text(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("surface 'wall_y0': emissivity = 0.5 is not used by the solve")
            && err.contains("emissivity_bands = [0.3, 0.6]")
            && err.contains("scene.toml: line "),
        "{err}"
    );
    // Bands alone: no warning.
    let p = scene(dir.path(), &cube(bands, 1000.0, "emissivity_bands = [0.3, 0.6]\nheat_flux = 0.0"));
    let o = run(&["solve", p.to_str().unwrap()]);
    assert!(o.status.success() && !text(&o.stderr).contains("not used"), "{}", text(&o.stderr));
}
