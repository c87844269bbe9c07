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
