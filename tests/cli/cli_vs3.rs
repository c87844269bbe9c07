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

/// A unit-cube room as View3D quadrilaterals; `rotate` starts every quadrilateral at its
/// second corner, which moves the diagonal a two-triangle split would take.
fn quad_room(rotate: bool) -> String {
    let faces = [
        ("floor", [1, 2, 3, 4]),
        ("ceiling", [5, 6, 7, 8]),
        ("wall_y0", [1, 5, 8, 2]),
        ("wall_y1", [4, 3, 7, 6]),
        ("wall_x0", [1, 4, 6, 5]),
        ("wall_x1", [2, 8, 7, 3]),
    ];
    let mut text = String::from(
        "F 3\nV 1 0 0 0\nV 2 1 0 0\nV 3 1 1 0\nV 4 0 1 0\nV 5 0 0 1\nV 6 0 1 1\nV 7 1 1 1\nV 8 1 0 1\n",
    );
    for (k, (name, mut v)) in faces.into_iter().enumerate() {
        if rotate {
            v.rotate_left(1);
        }
        text += &format!("S {} {} {} {} {} 0 0 0.8 {name}\n", k + 1, v[0], v[1], v[2], v[3]);
    }
    text
}

#[test]
fn a_quadrilateral_is_one_surface_whatever_its_diagonal() {
    // Hot floor, cold ceiling, adiabatic walls: by symmetry all four walls settle at one
    // temperature, and the room gives the same heat rates as the TOML polygons.
    let dir = tempfile::tempdir().unwrap();
    let conditions = "[defaults]\nheat_flux = 0.0\n\n[[surface]]\nname = \"floor\"\ntemperature = 1000.0\n\n\
                      [[surface]]\nname = \"ceiling\"\ntemperature = 300.0\n";
    let solve = |vs3: &str, name: &str| -> Vec<(String, f64, f64)> {
        std::fs::write(dir.path().join(format!("{name}.vs3")), vs3).unwrap();
        let scene = dir.path().join(format!("{name}.toml"));
        std::fs::write(&scene, format!("[[model]]\nfile = \"{name}.vs3\"\n\n{conditions}")).unwrap();
        let o = run(&["solve", scene.to_str().unwrap(), "--patches"]);
        assert!(o.status.success(), "{}", text(&o.stderr));
        text(&o.stdout)
            .lines()
            .skip(1)
            .map(|l| {
                let f: Vec<&str> = l.split(',').collect();
                (f[0].to_string(), f[3].parse().unwrap(), f[5].parse().unwrap())
            })
            .collect()
    };
    let a = solve(&quad_room(false), "a");
    let b = solve(&quad_room(true), "b");
    assert_eq!(a.len(), 6, "one patch per quadrilateral: {a:?}");
    let floor_q = a[0].2;
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(x.0, y.0);
        assert!((x.1 - y.1).abs() < 1e-9 * x.1, "{}: {} K vs {} K with the other diagonal", x.0, x.1, y.1);
        assert!((x.2 - y.2).abs() < 1e-9 * floor_q, "{}: {} W vs {} W", x.0, x.2, y.2);
    }
    for w in &a[2..] {
        assert!((w.1 - a[2].1).abs() < 1e-9 * a[2].1, "symmetric walls: {a:?}");
    }
    // The same room as TOML polygons.
    let mut toml = String::from("[defaults]\nemissivity = 0.8\n");
    let corner = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [0, 1, 1], [1, 1, 1], [1, 0, 1]];
    for line in quad_room(false).lines().filter(|l| l.starts_with('S')) {
        let f: Vec<&str> = line.split_whitespace().collect();
        let pts: Vec<String> =
            f[2..6].iter().map(|v| format!("{:?}", corner[v.parse::<usize>().unwrap() - 1])).collect();
        let condition = match f[9] {
            "floor" => "temperature = 1000.0",
            "ceiling" => "temperature = 300.0",
            _ => "heat_flux = 0.0",
        };
        toml += &format!("\n[[surface]]\nname = \"{}\"\npolygon = [{}]\n{condition}\n", f[9], pts.join(", "));
    }
    let path = dir.path().join("polygons.toml");
    std::fs::write(&path, &toml).unwrap();
    let o = run(&["solve", path.to_str().unwrap()]);
    assert!(o.status.success(), "{toml}\n{}", text(&o.stderr));
    let rows: Vec<Vec<String>> =
        text(&o.stdout).lines().skip(1).map(|l| l.split(',').map(String::from).collect()).collect();
    for (x, r) in a.iter().zip(&rows) {
        assert_eq!(x.0.split('#').next(), Some(r[0].as_str()));
        let (t, q): (f64, f64) = (r[3].parse().unwrap(), r[5].parse().unwrap());
        assert!((x.1 - t).abs() < 1e-9 * t && (x.2 - q).abs() < 1e-9 * floor_q, "{}: {x:?} vs {r:?}", r[0]);
    }
}
