//! `lambert viewfactors SCENE --points points.csv` through the real binary: the CSV it writes
//! (the library's numbers to the last digit, `--patches`, ambient rows), the closed-scene
//! check, the flags it refuses, and every bad points file (exit 2 naming file, line, column).
use lambert::report::points_csv::read_points;
use lambert::viewfactor::points::compute;
use lambert::viewfactor::Level;
use std::path::{Path, PathBuf};
use std::process::Command;

const FURNACE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/cases/cube_furnace/scene.toml");

fn lambert(args: &[&str]) -> (Option<i32>, String, String) {
    // Not -q: the summary lines are what these tests read.
    let o = Command::new(env!("CARGO_BIN_EXE_lambert")).args(args).output().expect("run lambert");
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
    )
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// (from, to, factor) rows of an output CSV, after checking its header.
fn rows(csv: &str) -> Vec<(String, String, f64)> {
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("from,to,factor,std_error,method,geometry"));
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            assert_eq!(f.len(), 6, "{l}");
            assert_eq!(f[3], "0", "exact factors: {l}");
            (f[0].to_string(), f[1].to_string(), f[2].parse().unwrap())
        })
        .collect()
}

const SENSORS: &str = "name,x,y,z,nx,ny,nz\n\
    centre up,0.5,0.5,0.5,0,0,1\n\
    on floor,0.25,0.7,0,0,0,1\n\
    tilted,0.3,0.2,0.6,1,-2,0.5\n";

#[test]
fn the_csv_holds_the_library_numbers_to_the_last_digit() {
    let dir = tempfile::tempdir().unwrap();
    let pts = write(dir.path(), "sensors.csv", SENSORS);
    let out = dir.path().join("out.csv");
    let (code, err, _) =
        lambert(&["viewfactors", FURNACE, "--points", pts.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_eq!(code, Some(0), "{err}");
    assert!(err.contains("3 points, 96 patches, 288 pairs"), "{err}");
    assert!(err.contains("closed scene, point rows: max |row sum - 1| = "), "{err}");
    assert!(!err.contains("warning"), "{err}");
    let text = std::fs::read_to_string(&out).unwrap();
    let got = rows(&text);
    // The fingerprint on the first row only.
    assert!(
        text.lines().nth(1).unwrap().ends_with(",analytic,fnv1a64:")
            || text.lines().nth(1).unwrap().contains("fnv1a64:")
    );
    let scene = lambert::scene::load(Path::new(FURNACE)).unwrap();
    let named = read_points(&pts).unwrap();
    let pf = compute(&scene, &named.points, Level::Surface, false);
    let want: Vec<(String, String, f64)> = pf
        .rows
        .iter()
        .enumerate()
        .flat_map(|(i, r)| r.iter().map(move |e| (i, e)))
        .map(|(i, e)| (named.names[i].clone(), pf.names[e.to as usize].clone(), e.factor))
        .collect();
    assert_eq!(got, want);
    for name in ["centre up", "on floor", "tilted"] {
        let sum: f64 = got.iter().filter(|r| r.0 == name).map(|r| r.2).sum();
        assert!((sum - 1.0).abs() < 1e-13, "{name}: {sum}");
    }
    assert!(
        !got.iter().any(|r| r.0 == "on floor" && r.1 == "floor"),
        "a sensor on the floor sees none of it"
    );
}

#[test]
fn patches_name_columns_and_an_open_scene_gets_ambient_rows() {
    let dir = tempfile::tempdir().unwrap();
    let pts = write(dir.path(), "p.csv", "x,y,z,nx,ny,nz\n0.5,0.5,0,0,0,1\n");
    let (code, err, out) = lambert(&["viewfactors", FURNACE, "--points", pts.to_str().unwrap(), "--patches"]);
    assert_eq!(code, Some(0), "{err}");
    let got = rows(&out);
    assert!(got.iter().all(|r| r.0 == "point#0" && r.1.contains('#')), "{out}");
    assert_eq!(got.iter().filter(|r| r.1.starts_with("ceiling#")).count(), 16);
    // Two plates, open: the rest of the hemisphere goes to the ambient.
    let scene = write(
        dir.path(),
        "open.toml",
        "[ambient]\ntemperature = 300\n[[surface]]\nname = \"plate\"\n\
         rectangle = { origin = [-1, -1, 1], u = [0, 2, 0], v = [2, 0, 0] }\n",
    );
    let (code, err, out) =
        lambert(&["viewfactors", scene.to_str().unwrap(), "--points", pts.to_str().unwrap()]);
    assert_eq!(code, Some(0), "{err}");
    let got = rows(&out);
    assert_eq!(got.len(), 2, "{out}");
    assert_eq!((got[0].1.as_str(), got[1].1.as_str()), ("plate", "ambient"));
    assert_eq!(got[0].2 + got[1].2, 1.0);
    assert!(!err.contains("closed scene"), "{err}");
}

#[test]
fn a_point_outside_a_closed_scene_is_named_in_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let pts =
        write(dir.path(), "p.csv", "name,x,y,z,nx,ny,nz\ninside,0.5,0.5,0.5,0,0,1\nbelow,0.5,0.5,-1,0,0,1\n");
    let (code, err, out) = lambert(&["viewfactors", FURNACE, "--points", pts.to_str().unwrap()]);
    assert_eq!(code, Some(0), "{err}");
    assert!(
        err.contains("warning: closed scene: 1 point(s) do not see a whole hemisphere")
            && err.contains("below (row sum 0.000000)"),
        "{err}"
    );
    assert!(!rows(&out).iter().any(|r| r.0 == "below"), "{out}");
}

#[test]
fn flags_that_points_cannot_honour_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let pts = write(dir.path(), "p.csv", "x,y,z,nx,ny,nz\n0.5,0.5,0.5,0,0,1\n");
    let p = pts.to_str().unwrap();
    let vtk = dir.path().join("o.vtu");
    for (extra, needle) in [
        (vec!["-m", "mc-cosine"], "--points: -m mc-cosine: point factors are exact"),
        (vec!["-m", "hemicube"], "--points: -m hemicube"),
        (vec!["--samples", "100"], "--points: --samples does not apply"),
        (vec!["--resolution", "128"], "--points: --resolution does not apply"),
        (vec!["--enforce", "closure"], "--points: --enforce closure: a point's row has no reciprocal entry"),
        (vec!["--vtk", vtk.to_str().unwrap()], "--points: --vtk"),
    ] {
        let mut args = vec!["viewfactors", FURNACE, "--points", p];
        args.extend(&extra);
        let (code, err, _) = lambert(&args);
        assert_eq!(code, Some(2), "{extra:?}: {err}");
        assert!(err.contains(needle), "{extra:?}: {err}");
    }
    // The points file is an input: no output may overwrite it.
    let (code, err, _) = lambert(&["viewfactors", FURNACE, "--points", p, "-o", p]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("the points file"), "{err}");
    assert_eq!(std::fs::read_to_string(&pts).unwrap(), "x,y,z,nx,ny,nz\n0.5,0.5,0.5,0,0,1\n");
    // Exact factors meet any tolerance; analytic is the same computation.
    let (code, err, a) =
        lambert(&["viewfactors", FURNACE, "--points", p, "-m", "analytic", "--tolerance", "1e-9"]);
    assert_eq!(code, Some(0), "{err}");
    let (_, _, b) = lambert(&["viewfactors", FURNACE, "--points", p, "--threads", "1", "--seed", "9"]);
    assert_eq!(a, b);
}

#[test]
fn bad_points_files_name_the_file_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let cases: &[(&str, &str, &str)] = &[
        ("empty", "", "p.csv:1: the file is empty"),
        ("header only", "x,y,z,nx,ny,nz\n", "p.csv:1: no points"),
        ("missing columns", "x,y,z,nx\n0,0,0,1\n", "p.csv:1: missing column(s) ny,nz"),
        ("unknown column", "x,y,z,nx,ny,nz,w\n0,0,0,0,0,1,2\n", "p.csv:1: unknown column 'w'"),
        ("twice", "x,y,z,nx,ny,nz,x\n0,0,0,0,0,1,0\n", "p.csv:1: column 'x' appears twice"),
        (
            "not a number",
            "x,y,z,nx,ny,nz\n0,0,0,0,0,1\n0,abc,0,0,0,1\n",
            "p.csv:3: point 'point#1', column y: 'abc' is not a number",
        ),
        (
            "empty field",
            "x,y,z,nx,ny,nz\n0,0,,0,0,1\n",
            "p.csv:2: point 'point#0', column z: '' is not a number",
        ),
        ("NaN", "name,x,y,z,nx,ny,nz\ns1,0,0,NaN,0,0,1\n", "p.csv:2: point 's1': z is NaN"),
        ("infinite normal", "name,x,y,z,nx,ny,nz\ns1,0,0,0,inf,0,1\n", "p.csv:2: point 's1': nx is inf"),
        (
            "zero normal",
            "name,x,y,z,nx,ny,nz\ns1,0.5,0.5,0.5,0,0,0\n",
            "p.csv:2: point 's1': the normal (0, 0, 0) has length 0",
        ),
        (
            "short row",
            "x,y,z,nx,ny,nz\n0,0,0,0,1\n",
            "p.csv:2: malformed row: 5 fields where the header has 6",
        ),
        (
            "same name",
            "name,x,y,z,nx,ny,nz\na,0,0,0,0,0,1\na,1,0,0,0,0,1\n",
            "p.csv:3: column name: point 'a' is already named on line 2",
        ),
        (
            "empty name",
            "name,x,y,z,nx,ny,nz\n,0,0,0,0,0,1\n",
            "p.csv:2: column name: the point's name is empty",
        ),
    ];
    for (what, text, needle) in cases {
        let pts = write(dir.path(), "p.csv", text);
        let (code, err, out) = lambert(&["viewfactors", FURNACE, "--points", pts.to_str().unwrap()]);
        assert_eq!(code, Some(2), "{what}: {err}");
        assert!(err.contains(needle), "{what}: expected '{needle}' in: {err}");
        assert!(out.is_empty(), "{what}: {out}");
    }
    let (code, err, _) =
        lambert(&["viewfactors", FURNACE, "--points", dir.path().join("none.csv").to_str().unwrap()]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("none.csv: cannot read the points file"), "{err}");
}
