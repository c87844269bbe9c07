//! The binary's outputs are safe by construction: an output that is an input, two outputs on
//! one file, or a folder that does not exist is refused (exit 2) before any work, naming both
//! roles; a failed or killed run leaves every earlier output as it was; and limits (threads,
//! samples, tolerance, memory under `ulimit -v`) and costs (a large mesh surface) are said up
//! front.
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_lambert");
const EARLIER: &str = "an earlier result\n";

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn run(dir: &Path, args: &[&str]) -> Output {
    Command::new(BIN).current_dir(dir).args(args).env_remove("LAMBERT_TEST_ABORT_AT").output().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A folder with the cube furnace as `s.toml`, the external-buffer glTF, a model scene that
/// loads it, and earlier results `good.csv`, `good.vtu` and `radk.csv`.
fn setup() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::copy(root().join("cases/cube_furnace/scene.toml"), d.join("s.toml")).unwrap();
    for f in ["external.gltf", "external.bin"] {
        std::fs::copy(root().join("tests/data/gltf").join(f), d.join(f)).unwrap();
    }
    std::fs::write(d.join("m.toml"), "[[model]]\nfile = \"external.gltf\"\ntemperature = 300.0\n").unwrap();
    for f in ["good.csv", "good.vtu", "radk.csv"] {
        std::fs::write(d.join(f), EARLIER).unwrap();
    }
    dir
}

/// Asserts exit 2 with every needle in stderr, nothing computed (no pair count printed) and
/// nothing on stdout; returns stderr.
fn refused(o: &Output, needles: &[&str]) -> String {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    for n in needles {
        assert!(err.contains(n), "missing '{n}' in: {err}");
    }
    assert!(!err.contains("pairs") && !err.contains("panicked"), "{err}");
    assert!(o.stdout.is_empty());
    err
}

fn unchanged(dir: &Path, files: &[&str]) {
    for f in files {
        assert_eq!(std::fs::read_to_string(dir.join(f)).unwrap(), EARLIER, "{f} was replaced");
    }
}

fn partials(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".partial"))
        .collect()
}

#[test]
fn an_output_that_is_an_input_is_refused_and_the_input_kept() {
    let dir = setup();
    let d = dir.path();
    let scene = std::fs::read(d.join("s.toml")).unwrap();
    let buffer = std::fs::read(d.join("external.bin")).unwrap();
    let o = run(d, &["viewfactors", "s.toml", "-o", "s.toml"]);
    refused(&o, &["-o s.toml is the scene file", "view-factor CSV"]);
    let o = run(d, &["viewfactors", "s.toml", "-o", "./s.toml"]);
    refused(&o, &["the scene file"]);
    // A [[model]] file and its external buffer, also through a hard link.
    let o = run(d, &["viewfactors", "m.toml", "-o", "external.gltf"]);
    refused(&o, &["-o external.gltf is a file that the scene m.toml loads"]);
    std::fs::hard_link(d.join("external.bin"), d.join("link.bin")).unwrap();
    let o = run(d, &["viewfactors", "m.toml", "-o", "link.bin"]);
    refused(&o, &["-o link.bin is a file that the scene m.toml loads (external.bin)"]);
    let o = run(d, &["solve", "m.toml", "--vtk", "external.bin.vtu", "-o", "external.bin"]);
    refused(&o, &["-o external.bin is a file"]);
    // The saved view factors of `solve --viewfactors`, and a deck over the scene.
    let vf = run(d, &["viewfactors", "s.toml", "-o", "vf.csv"]);
    assert!(vf.status.success(), "{}", stderr(&vf));
    let saved = std::fs::read(d.join("vf.csv")).unwrap();
    let o = run(d, &["solve", "s.toml", "--viewfactors", "vf.csv", "-o", "vf.csv"]);
    refused(&o, &["-o vf.csv is the --viewfactors input"]);
    let o = run(d, &["solve", "s.toml", "--conductances", "s.toml", "--format", "csv"]);
    refused(&o, &["--conductances s.toml is the scene file", "conductance deck"]);
    // render: the picture over the scene.
    std::fs::copy(d.join("s.toml"), d.join("scene.png")).unwrap();
    let o = run(d, &["render", "scene.png", "good.csv", "-o", "scene.png"]);
    refused(&o, &["-o scene.png is the scene file"]);
    assert_eq!(std::fs::read(d.join("s.toml")).unwrap(), scene);
    assert_eq!(std::fs::read(d.join("external.bin")).unwrap(), buffer);
    assert_eq!(std::fs::read(d.join("vf.csv")).unwrap(), saved);
    assert!(partials(d).is_empty(), "{:?}", partials(d));
}

#[test]
fn two_outputs_on_one_file_are_refused() {
    let dir = setup();
    let d = dir.path();
    let o = run(d, &["solve", "s.toml", "-o", "good.csv", "--conductances", "./good.csv"]);
    refused(&o, &["-o good.csv and --conductances ./good.csv are the same file"]);
    std::fs::hard_link(d.join("good.csv"), d.join("same.csv")).unwrap();
    let o = run(d, &["solve", "s.toml", "-o", "good.csv", "--conductances", "same.csv"]);
    refused(&o, &["same file"]);
    unchanged(d, &["good.csv"]);
}

#[test]
fn a_missing_folder_is_refused_before_any_work_and_earlier_outputs_stay() {
    let dir = setup();
    let d = dir.path();
    let o = run(d, &["solve", "s.toml", "-o", "good.csv", "--vtk", "nodir/x.vtu"]);
    refused(&o, &["--vtk nodir/x.vtu: the folder 'nodir' does not exist"]);
    let o = run(d, &["solve", "s.toml", "-o", "good.csv", "--conductances", "nodir/c.sin"]);
    refused(&o, &["--conductances nodir/c.sin: the folder 'nodir' does not exist"]);
    let o = run(d, &["viewfactors", "s.toml", "-o", "nodir/x.csv"]);
    refused(&o, &["-o nodir/x.csv: the folder 'nodir' does not exist"]);
    let o = run(d, &["render", "s.toml", "good.csv", "-o", "nodir/x.png"]);
    let err = refused(&o, &["-o nodir/x.png: the folder 'nodir' does not exist"]);
    assert!(!err.contains("Drawing backend") && !err.contains("Os {"), "{err}");
    // An output that names a folder.
    let o = run(d, &["viewfactors", "s.toml", "-o", "."]);
    refused(&o, &["-o .: this is a folder"]);
    unchanged(d, &["good.csv", "good.vtu", "radk.csv"]);
    assert!(partials(d).is_empty());
}

/// Kills the run right after each writer has written its temporary (the test hook of
/// `report::outputs`): every earlier output stays as it was, and the next run puts all three
/// in place and leaves no temporary.
#[test]
fn a_killed_run_leaves_the_earlier_outputs_and_the_next_run_cleans_up() {
    let dir = setup();
    let d = dir.path();
    let args = [
        "solve",
        "s.toml",
        "-o",
        "good.csv",
        "--vtk",
        "good.vtu",
        "--conductances",
        "radk.csv",
        "--patches",
        "-q",
    ];
    for key in ["conductances", "vtk", "output"] {
        let o =
            Command::new(BIN).current_dir(d).args(args).env("LAMBERT_TEST_ABORT_AT", key).output().unwrap();
        assert_eq!(o.status.code(), None, "{key}: the process must die by a signal: {}", stderr(&o));
        assert!(stderr(&o).contains("aborting after writing"), "{key}: {}", stderr(&o));
        unchanged(d, &["good.csv", "good.vtu", "radk.csv"]);
        assert!(!partials(d).is_empty(), "{key}: the abort left no temporary");
    }
    let o = run(d, &args);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(partials(d).is_empty(), "{:?}", partials(d));
    let csv = std::fs::read_to_string(d.join("good.csv")).unwrap();
    assert!(csv.starts_with("surface,area,emissivity"), "{csv}");
    assert!(std::fs::read_to_string(d.join("good.vtu")).unwrap().contains("<VTKFile"));
    assert!(std::fs::read_to_string(d.join("radk.csv")).unwrap().starts_with("from,to,radk"));
    // The picture of `render` alike.
    std::fs::write(d.join("pic.png"), EARLIER).unwrap();
    let args = ["render", "s.toml", "good.csv", "-o", "pic.png", "--size", "400x300"];
    let o =
        Command::new(BIN).current_dir(d).args(args).env("LAMBERT_TEST_ABORT_AT", "output").output().unwrap();
    assert_eq!(o.status.code(), None, "{}", stderr(&o));
    unchanged(d, &["pic.png"]);
    assert_eq!(partials(d), vec!["pic.png.partial".to_string()]);
    let o = run(d, &args);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::read(d.join("pic.png")).unwrap().starts_with(b"\x89PNG"));
    assert!(partials(d).is_empty());
}

/// Results to stdout come after every file has been written: a deck that cannot be written
/// (here: its temporary's name is taken by a folder) stops the run with nothing on stdout.
#[test]
fn stdout_is_written_after_the_files() {
    let dir = setup();
    let d = dir.path();
    std::fs::create_dir(d.join("radk.csv.partial")).unwrap();
    std::fs::write(d.join("radk.csv.partial/keep"), "x").unwrap();
    let o = run(d, &["solve", "s.toml", "--conductances", "radk.csv", "--patches"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("radk.csv.partial")
            && err.contains("cannot write the conductance deck (--conductances)"),
        "{err}"
    );
    assert!(o.stdout.is_empty(), "{}", String::from_utf8_lossy(&o.stdout));
    unchanged(d, &["radk.csv"]);
}

#[cfg(unix)]
#[test]
fn a_fifo_is_written_in_place() {
    let dir = setup();
    let d = dir.path();
    let fifo = d.join("pipe.csv");
    let made = Command::new("mkfifo").arg(&fifo).status();
    if !made.is_ok_and(|s| s.success()) {
        eprintln!("mkfifo is not available: skipped");
        return;
    }
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read_to_string(fifo).unwrap())
    };
    let o = run(d, &["viewfactors", "s.toml", "-o", "pipe.csv"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = reader.join().unwrap();
    assert!(text.starts_with("from,to,factor"), "{text}");
    use std::os::unix::fs::FileTypeExt;
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    assert!(partials(d).is_empty());
}

/// A write that fails (a full device) names the path, what was being written and the flag.
#[test]
fn a_failed_write_names_the_path_and_what_was_written() {
    if !Path::new("/dev/full").exists() {
        eprintln!("/dev/full is not available: skipped");
        return;
    }
    let dir = setup();
    let o = run(dir.path(), &["viewfactors", "s.toml", "-o", "/dev/full"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("/dev/full: cannot write the view-factor CSV (-o): "), "{err}");
}

#[test]
fn limits_are_refused_up_front() {
    let dir = setup();
    let d = dir.path();
    for n in ["0", "2000", "100000"] {
        let o = run(d, &["viewfactors", "s.toml", "--threads", n]);
        refused(&o, &[&format!("--threads {n}: give 1 to 1024 worker threads")]);
    }
    let o = run(d, &["viewfactors", "s.toml", "--tolerance", "1e-300"]);
    refused(&o, &["--tolerance 1e-300 is below 1e-13"]);
    let o = run(d, &["solve", "s.toml", "--tolerance", "1e-14"]);
    refused(&o, &["--tolerance 1e-14 is below 1e-13"]);
    let o = run(d, &["viewfactors", "s.toml", "-m", "mc-cosine", "--samples", "1000000000"]);
    refused(&o, &["--samples 1000000000 is above the cap of 100000000"]);
    // The largest thread count and the cap itself are accepted.
    let o = run(d, &["viewfactors", "s.toml", "--threads", "1024", "-o", "/dev/null"]);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// Runs `cmd` with a time limit (a check that fails would start a long computation).
fn output_within(mut cmd: Command, limit: Duration) -> Output {
    let mut child =
        cmd.stdout(std::process::Stdio::piped()).stderr(std::process::Stdio::piped()).spawn().unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > limit {
            let _ = child.kill();
            break;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    child.wait_with_output().unwrap()
}

/// A two-plate scene of 2 × 110² patches: its dense store needs about 2.9 GB.
fn plates(dir: &Path) -> PathBuf {
    let path = dir.join("plates.toml");
    std::fs::write(
        &path,
        "[[surface]]\nname = \"a\"\nrectangle = { origin = [0,0,0], u = [1,0,0], v = [0,1,0] }\nsubdivide = [110, 110]\n\
         [[surface]]\nname = \"b\"\nrectangle = { origin = [0,0,1], u = [0,1,0], v = [1,0,0] }\nsubdivide = [110, 110]\n",
    )
    .unwrap();
    path
}

/// Under an address-space limit (`ulimit -v`) the dense store is refused with exit 2 and the
/// limit named, instead of an abort part-way through.
#[cfg(target_os = "linux")]
#[test]
fn the_memory_check_sees_the_address_space_limit() {
    let dir = tempfile::tempdir().unwrap();
    let scene = plates(dir.path());
    let mut cmd = Command::new("sh");
    cmd.args(["-c", "ulimit -v 2000000 && exec \"$0\" \"$@\"", BIN, "viewfactors"])
        .arg(&scene)
        .args(["--patches", "-o", "/dev/null", "-q"])
        .env_remove("LAMBERT_MEM_AVAILABLE");
    let o = output_within(cmd, Duration::from_secs(120));
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("24200 patches") && err.contains("RLIMIT_AS"), "{err}");
}

/// One glTF surface of `n` triangles in a strip (external buffer, no indices).
fn strip_gltf(dir: &Path, n: usize) -> PathBuf {
    let mut bin = Vec::with_capacity(n * 36);
    for k in 0..n {
        let x = k as f32 * 0.5;
        for v in [[x, 0.0, 0.0], [x + 1.0, 0.0, 0.0], [x, 1.0, 0.0]] {
            for c in v {
                bin.extend_from_slice(&c.to_le_bytes());
            }
        }
    }
    std::fs::write(dir.join("strip.bin"), &bin).unwrap();
    let max_x = (n - 1) as f32 * 0.5 + 1.0;
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"name":"part","mesh":0}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":{},"type":"VEC3","min":[0,0,0],"max":[{max_x},1,0]}}],
"bufferViews":[{{"buffer":0,"byteLength":{}}}],"buffers":[{{"uri":"strip.bin","byteLength":{}}}]}}"#,
        3 * n,
        bin.len(),
        bin.len()
    );
    let path = dir.join("strip.gltf");
    std::fs::write(&path, json).unwrap();
    path
}

/// A mesh surface beyond the dense limit starts with the cost estimate and what changes it
/// (refused here by the memory check right after, so nothing is computed).
#[test]
fn a_large_mesh_surface_is_warned_with_its_cost() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    strip_gltf(d, 12_001);
    std::fs::write(d.join("strip.toml"), "[[model]]\nfile = \"strip.gltf\"\ntemperature = 300.0\n").unwrap();
    let cases: [&[&str]; 2] = [
        &["viewfactors", "strip.toml", "--patches", "-m", "analytic"],
        &["solve", "strip.toml", "--exchange", "dense"],
    ];
    for args in cases {
        let o = Command::new(BIN)
            .current_dir(d)
            .args(args)
            .env("LAMBERT_MEM_AVAILABLE", "1000")
            .output()
            .unwrap();
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains("warning: surface 'part' is a mesh of 12,001 triangles")
                && err.contains("7.2e7 pairs")
                && err.contains("pairs per CPU-second"),
            "{args:?}: {err}"
        );
    }
    let o = Command::new(BIN)
        .current_dir(d)
        .args(["solve", "strip.toml", "--exchange", "dense"])
        .env("LAMBERT_MEM_AVAILABLE", "1000")
        .output()
        .unwrap();
    assert!(stderr(&o).contains("--exchange hierarchical"), "{}", stderr(&o));
    // A Monte Carlo run's cost is not in pairs: no warning.
    let o = run(d, &["viewfactors", "strip.gltf", "-m", "mc-cosine", "--samples", "16", "-o", "/dev/null"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("warning: surface"), "{}", stderr(&o));
}

/// `validate --quick` never replaces a full-suite report: refused up front with exit 2.
#[test]
fn quick_validation_keeps_a_full_report() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("validation");
    std::fs::create_dir(&out).unwrap();
    let full = "# Validation report\n\nGenerated by `lambert validate`. Mode: **full**. 39 cases.\n";
    std::fs::write(out.join("report.md"), full).unwrap();
    let o = Command::new(BIN)
        .args(["validate", "--quick", "--cases"])
        .arg(root().join("cases"))
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("holds the full suite's report") && err.contains("another --out"), "{err}");
    assert_eq!(std::fs::read_to_string(out.join("report.md")).unwrap(), full);
    // An --out that is a file is refused before any case runs.
    let o = Command::new(BIN)
        .args(["validate", "--quick", "--cases"])
        .arg(root().join("cases"))
        .arg("--out")
        .arg(out.join("report.md"))
        .output()
        .unwrap();
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("report.md: cannot create the folder") && !err.contains("checks"), "{err}");
    assert_eq!(std::fs::read_to_string(out.join("report.md")).unwrap(), full);
}

/// The scene records every file it reads: the scene file, model files and external buffers
/// (percent-escapes in a buffer URI decoded as the glTF reader decodes them).
#[test]
fn the_scene_lists_every_file_it_reads() {
    let dir = setup();
    let d = dir.path();
    let scene = lambert::scene::load(&d.join("m.toml")).unwrap();
    let want: Vec<PathBuf> = ["m.toml", "external.gltf", "external.bin"].iter().map(|f| d.join(f)).collect();
    assert_eq!(scene.inputs, want);
    let gltf = std::fs::read_to_string(d.join("external.gltf")).unwrap();
    assert!(gltf.contains("\"uri\": \"external.bin\""), "fixture changed");
    std::fs::write(
        d.join("spaced.gltf"),
        gltf.replace("\"uri\": \"external.bin\"", "\"uri\": \"my%20buffer.bin\""),
    )
    .unwrap();
    std::fs::copy(d.join("external.bin"), d.join("my buffer.bin")).unwrap();
    let scene = lambert::scene::load(&d.join("spaced.gltf")).unwrap();
    assert_eq!(scene.inputs, vec![d.join("spaced.gltf"), d.join("my buffer.bin")]);
    let o = run(d, &["viewfactors", "spaced.gltf", "-o", "my buffer.bin"]);
    refused(&o, &["-o my buffer.bin is a file that the scene spaced.gltf loads"]);
}
