//! `lambert validate --quick`: the CI subset of the validation suite runs, passes and lists
//! every case of cases/ in its report.
use std::path::Path;
use std::process::Command;

#[test]
fn quick_suite_passes_and_reports_every_case() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = tempfile::tempdir().expect("temporary directory");
    let run = Command::new(env!("CARGO_BIN_EXE_lambert"))
        .args(["validate", "--quick", "--cases"])
        .arg(root.join("cases"))
        .arg("--out")
        .arg(out.path())
        .output()
        .expect("run lambert");
    let stdout = String::from_utf8_lossy(&run.stdout);
    let stderr = String::from_utf8_lossy(&run.stderr);
    let failures: Vec<&str> = stdout.lines().filter(|l| l.contains(" FAIL")).collect();
    assert_eq!(run.status.code(), Some(0), "validate failed:\n{}\n{stderr}", failures.join("\n"));
    let report = std::fs::read_to_string(out.path().join("report.md")).expect("report.md written");
    let mut cases = 0;
    for entry in std::fs::read_dir(root.join("cases")).unwrap() {
        let dir = entry.unwrap().path();
        if dir.join("reference.toml").exists() {
            let name = dir.file_name().unwrap().to_string_lossy().into_owned();
            assert!(report.contains(&format!("| {name} |")), "report.md does not list case {name}");
            cases += 1;
        }
    }
    assert!(cases >= 25, "only {cases} cases with a reference.toml");
    for chart in ["speed_accuracy_cube", "stability_far", "mc_convergence"] {
        assert!(out.path().join(format!("{chart}.png")).exists(), "{chart}.png missing");
        assert!(out.path().join(format!("{chart}.svg")).exists(), "{chart}.svg missing");
    }
}

#[test]
fn a_missing_cases_folder_is_bad_usage() {
    let out = tempfile::tempdir().expect("temporary directory");
    let run = Command::new(env!("CARGO_BIN_EXE_lambert"))
        .args(["validate", "--quick", "--cases", "/nonexistent/cases", "--out"])
        .arg(out.path())
        .output()
        .expect("run lambert");
    assert_eq!(run.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&run.stderr).contains("/nonexistent/cases"));
}

/// A one-case suite run through the library: a wrong reference fails each method held tighter
/// than the offset, and passes only where the method's tolerance covers it.
#[test]
fn wrong_references_fail_where_the_tolerance_is_tighter() {
    use lambert::validate::{runner, Budget, Case, Status};
    let dir = tempfile::tempdir().expect("temporary directory");
    std::fs::write(
        dir.path().join("scene.toml"),
        "[ambient]\ntemperature = 300.0\n\n[[surface]]\nname = \"bottom\"\nrectangle = { origin = [0,0,0], u = [1,0,0], v = [0,1,0] }\n\n[[surface]]\nname = \"top\"\nrectangle = { origin = [0,0,1], u = [0,1,0], v = [1,0,0] }\n\n[[surface]]\nname = \"blocker\"\npolygon = [[0.25,0.25,0.5],[0.25,0.75,0.5],[0.75,0.75,0.5],[0.75,0.25,0.5]]\nrole = \"obstruction\"\n",
    )
    .unwrap();
    // The obstructed C-11 value, off by 1e-6: every exact method must fail it.
    std::fs::write(
        dir.path().join("reference.toml"),
        "title = \"t\"\ncitation = \"c\"\n[skip]\n\"single-plane\" = \"not needed\"\n\n[[viewfactor]]\nfrom = \"bottom\"\nto = \"top\"\nvalue = 0.0995072946\nsource = \"o1 + 1e-6\"\n",
    )
    .unwrap();
    let case = Case::load(dir.path()).expect("case loads");
    let checks = runner::run_case(&case, &Budget::quick());
    let status = |m: &str| checks.iter().find(|c| c.method == m).map(|c| c.status.clone()).expect(m);
    assert!(matches!(status("single-plane"), Status::Skipped(_)));
    // Monte Carlo at 1e5 rays cannot resolve 1e-6: within 4σ it passes.
    assert_eq!(status("mc-cosine"), Status::Pass, "{checks:#?}");
    // The exact method computes it (shadowed) and must fail the 1e-6 offset.
    assert!(matches!(status("analytic"), Status::Fail(_)), "{checks:#?}");
    // `auto` is held to its 1e-4 goal, which the offset is inside.
    assert_eq!(status("auto"), Status::Pass, "{checks:#?}");
    assert!(checks
        .iter()
        .all(|c| !matches!(c.status, Status::Pass) || c.error().unwrap() <= c.tolerance.unwrap()));
}
