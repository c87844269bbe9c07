//! `-q` prints only errors and warnings, for every subcommand: summary lines (timings, row
//! sums, the route, enforcement) go, warnings stay line for line, and stdout is unchanged.
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_lambert");

fn run(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().expect("run lambert")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn case(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("cases").join(name).join("scene.toml").display().to_string()
}

/// Runs `args` with and without `-q`: both succeed with the same stdout; returns both stderrs.
fn loud_and_quiet(args: &[&str]) -> (String, String) {
    let loud = run(args);
    let mut q = args.to_vec();
    q.push("-q");
    let quiet = run(&q);
    assert!(loud.status.success() && quiet.status.success(), "{}\n{}", stderr(&loud), stderr(&quiet));
    assert_eq!(loud.stdout, quiet.stdout, "{args:?}: -q changes no output");
    (stderr(&loud), stderr(&quiet))
}

#[test]
fn quiet_runs_of_shipped_cases_print_nothing_on_stderr() {
    let dir = tempfile::tempdir().unwrap();
    let furnace = case("cube_furnace");
    let e3 = case("e3_cube_furnace");
    let result = dir.path().join("result.csv");
    let png = dir.path().join("picture.png");
    let sensors = dir.path().join("sensors.csv");
    std::fs::write(&sensors, "x,y,z,nx,ny,nz\n0.5,0.5,0.5,0,0,1\n").unwrap();
    let runs: [Vec<&str>; 6] = [
        vec!["viewfactors", &furnace],
        vec!["viewfactors", &furnace, "--patches", "--enforce", "closure"],
        vec!["viewfactors", &furnace, "--points", sensors.to_str().unwrap()],
        vec!["solve", &e3],
        vec!["solve", &e3, "-m", "mc-cosine", "--samples", "2000", "--solver", "jacobi"],
        vec!["solve", &e3, "-o", result.to_str().unwrap()],
    ];
    for args in &runs {
        let (loud, quiet) = loud_and_quiet(args);
        assert!(!loud.is_empty(), "{args:?}: a summary without -q");
        assert_eq!(quiet, "", "{args:?}");
    }
    // `render` (after the solve above wrote its result) and -q before the subcommand.
    let render = ["render", &e3, result.to_str().unwrap(), "-o", png.to_str().unwrap()];
    let loud = run(&render);
    assert!(loud.status.success() && stderr(&loud).contains("lambert: render:"), "{}", stderr(&loud));
    let quiet = run(&[&["-q"][..], &render[..]].concat());
    assert!(quiet.status.success() && quiet.stderr.is_empty(), "{}", stderr(&quiet));
}

/// A hot floor and a 1 m² panel 1 m above it facing away from it, open to 300 K.
fn flipped_panel(dir: &Path) -> PathBuf {
    let text =
        "[ambient]\ntemperature = 300.0\n\n[defaults]\nemissivity = 0.9\n\n[[surface]]\nname = \"floor\"\n\
         rectangle = { origin = [0, 0, 0], u = [1, 0, 0], v = [0, 1, 0] }\ntemperature = 1000.0\n\n\
         [[surface]]\nname = \"panel\"\nrectangle = { origin = [0, 0, 1], u = [1, 0, 0], v = [0, 1, 0] }\n\
         temperature = 300.0\n";
    let p = dir.join("flipped.toml");
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn quiet_keeps_exactly_the_warning_lines() {
    let dir = tempfile::tempdir().unwrap();
    let flipped = flipped_panel(dir.path());
    let scene = flipped.to_str().unwrap();
    for args in [vec!["viewfactors", scene], vec!["solve", scene], vec!["solve", scene, "--patches"]] {
        let (loud, quiet) = loud_and_quiet(&args);
        let warnings: Vec<&str> = loud.lines().filter(|l| l.starts_with("lambert: warning: ")).collect();
        assert!(warnings.iter().any(|w| w.contains("'panel' faces away")), "{args:?}: {loud}");
        assert!(loud.lines().count() > warnings.len(), "{args:?}: notes besides the warnings: {loud}");
        assert_eq!(quiet.lines().collect::<Vec<_>>(), warnings, "{args:?}");
    }
}

#[test]
fn an_error_still_shows_under_quiet() {
    let o = run(&["solve", "no-such-scene.toml", "-q"]);
    assert_eq!(o.status.code(), Some(2));
    let err = stderr(&o);
    assert!(err.starts_with("lambert: error: ") && err.contains("no-such-scene.toml"), "{err}");
}
