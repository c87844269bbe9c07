//! Hints checked against the facts before they are printed (issue 19): a view-factor file
//! written for another geometry is refused as such (its fingerprint), not blamed on a leak;
//! a leak next to obstructions names them; a panel of an open scene facing away from the
//! rest of the scene is named.
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_lambert");

fn run(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().expect("run lambert")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn furnace() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/cube_furnace/scene.toml"))
        .unwrap()
}

/// `viewfactors SCENE -o OUT`, returning OUT's text.
fn viewfactors(scene: &Path, out: &Path) -> String {
    let o = run(&["viewfactors", scene.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::read_to_string(out).unwrap()
}

#[test]
fn view_factors_carry_the_geometry_and_another_scenes_file_is_refused_as_such() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = write(d, "furnace.toml", &furnace());
    // The same names in another scene: the ceiling lifted to 2 m, open to the surroundings.
    let lifted = furnace().replace("origin = [0, 0, 1], u = [0, 1, 0]", "origin = [0, 0, 2], u = [0, 1, 0]")
        + "\n[ambient]\ntemperature = 300.0\n";
    let other = write(d, "lifted.toml", &lifted);
    let ours = viewfactors(&scene, &d.join("ours.csv"));
    let theirs = viewfactors(&other, &d.join("theirs.csv"));
    let stamp = |text: &str| text.lines().nth(1).unwrap().rsplit(',').next().unwrap().to_string();
    assert!(ours.starts_with("from,to,factor,std_error,method,geometry\n"), "{ours}");
    assert!(stamp(&ours).starts_with("fnv1a64:") && stamp(&ours) != stamp(&theirs));
    assert!(ours.lines().skip(2).all(|l| l.ends_with(',')), "the fingerprint is on the first row only");

    // Its own file: solved as before.
    let o = run(&["solve", scene.to_str().unwrap(), "--viewfactors", d.join("ours.csv").to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    // Another geometry's file: exit 2 saying so, on the line of the fingerprint.
    let o = run(&["solve", scene.to_str().unwrap(), "--viewfactors", d.join("theirs.csv").to_str().unwrap()]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("theirs.csv:2:") && err.contains("computed for another geometry"), "{err}");
    assert!(err.contains("Compute the view factors again for this scene"), "{err}");
    assert!(!err.contains("leaks") && !err.contains("gap"), "{err}");

    // The same file without its fingerprint (an older lambert) loads on its names; its rows
    // leak in this scene, and the refusal says the file may belong to another scene.
    let unstamped = theirs.replacen(&stamp(&theirs), "", 1);
    let old = write(d, "old.csv", &unstamped);
    let o = run(&["solve", scene.to_str().unwrap(), "--viewfactors", old.to_str().unwrap()]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("leaks") && err.contains("carries no geometry fingerprint"), "{err}");

    // Rows of two geometries in one file.
    let mixed = format!("{ours}{}", theirs.lines().nth(1).unwrap());
    let mixed = write(d, "mixed.csv", &mixed);
    let o = run(&["solve", scene.to_str().unwrap(), "--viewfactors", mixed.to_str().unwrap()]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("two geometry fingerprints"), "{err}");
}

/// The View3D unit cube (closed, `encl = 1`) with an obstruction plate; `z` its height.
fn cube_with_plate(z: f64) -> String {
    format!(
        "C encl=1\nF 3\nV 1 0 0 0\nV 2 1 0 0\nV 3 1 1 0\nV 4 0 1 0\nV 5 0 0 1\nV 6 0 1 1\nV 7 1 1 1\nV 8 1 0 1\n\
         V 9 0.3 0.3 {z}\nV 10 0.7 0.3 {z}\nV 11 0.7 0.7 {z}\nV 12 0.3 0.7 {z}\n\
         S 1 1 2 3 4 0 0 0.8 floor\nS 2 5 6 7 8 0 0 0.8 ceiling\nS 3 1 5 8 2 0 0 0.8 wall_y0\n\
         S 4 4 3 7 6 0 0 0.8 wall_y1\nS 5 1 4 6 5 0 0 0.8 wall_x0\nS 6 2 8 7 3 0 0 0.8 wall_x1\n\
         O 7 9 10 11 12\nEnd of data\n"
    )
}

#[test]
fn a_leak_beside_an_obstruction_names_the_obstruction() {
    let dir = tempfile::tempdir().unwrap();
    let inside = write(dir.path(), "inside.vs3", &cube_with_plate(0.5));
    // viewfactors enforces closure for encl = 1: refused, and the note names the plate.
    let o = run(&["viewfactors", inside.to_str().unwrap(), "-o", "-"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("leaks") && err.contains("obstruction_7") && err.contains("`S` record"), "{err}");
    // Raw factors: the leak warning carries the same note.
    let o = run(&["viewfactors", inside.to_str().unwrap(), "--enforce", "none", "-o", "-"]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("closed scene leaks") && err.contains("in front of 'floor' (obstruction_7)"),
        "{err}"
    );

    // The plate below the floor blocks nothing of the cube: no leak and no note.
    let outside = write(dir.path(), "outside.vs3", &cube_with_plate(-0.5));
    let o = run(&["viewfactors", outside.to_str().unwrap(), "-o", "-"]);
    let err = stderr(&o);
    assert!(o.status.success() && !err.contains("obstruction"), "{err}");
}

/// A hot floor and a 1 m² panel 1 m above it, open to 300 K; `flip` turns the panel away.
fn panel(flip: bool) -> String {
    let (u, v) = if flip { ("[1, 0, 0]", "[0, 1, 0]") } else { ("[0, 1, 0]", "[1, 0, 0]") };
    format!(
        "[ambient]\ntemperature = 300.0\n\n[defaults]\nemissivity = 0.9\n\n[[surface]]\nname = \"floor\"\n\
         rectangle = {{ origin = [0, 0, 0], u = [1, 0, 0], v = [0, 1, 0] }}\ntemperature = 1000.0\n\n\
         [[surface]]\nname = \"panel\"\nrectangle = {{ origin = [0, 0, 1], u = {u}, v = {v} }}\ntemperature = 300.0\n"
    )
}

#[test]
fn a_panel_facing_away_from_the_scene_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let flipped = write(dir.path(), "flipped.toml", &panel(true));
    for cmd in ["viewfactors", "solve"] {
        let o = run(&[cmd, flipped.to_str().unwrap(), "-o", "-"]);
        let err = stderr(&o);
        assert!(o.status.success(), "{err}");
        assert!(
            err.contains("warning: surface 'panel' faces away from every other surface")
                && err.contains("'floor' lies behind it"),
            "{cmd}: {err}"
        );
        assert!(
            !err.contains("surface 'floor' faces away"),
            "{cmd}: the floor faces the panel's back: {err}"
        );
    }
    let facing = write(dir.path(), "facing.toml", &panel(false));
    let o = run(&["solve", facing.to_str().unwrap(), "-o", "-"]);
    assert!(o.status.success() && !stderr(&o).contains("faces away"), "{}", stderr(&o));
}
