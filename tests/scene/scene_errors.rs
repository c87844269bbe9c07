//! Every bad-input path of docs/SPEC.md gives `Error::Input` naming the file, the surface (when there
//! is one), the line (when known) and the problem.
//!
//! TOML cases are written to a temporary `scene.toml`; the line the error must name is marked
//! with `#<` in the text.
use lambert::error::InputError;
use lambert::scene::{self, BoundaryCondition};
use lambert::Error;
use std::path::{Path, PathBuf};

fn input_error(path: &Path) -> InputError {
    match scene::load(path) {
        Err(Error::Input(e)) => e,
        Err(other) => panic!("{}: expected an input error, got {other:?}", path.display()),
        Ok(_) => panic!("{}: loaded, but it should fail", path.display()),
    }
}

fn write(dir: &Path, text: &str) -> PathBuf {
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// Loads `text`; the error must name `surface`, the `#<` line and contain `needle`.
fn expect(text: &str, surface: Option<&str>, needle: &str) {
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), text);
    let e = input_error(&path);
    let line = text.lines().position(|l| l.contains("#<")).map(|k| k + 1);
    let shown = e.to_string();
    let ctx = format!("\n--- scene ---\n{text}\n--- error ---\n{shown}\n{e:?}");
    assert_eq!(e.file, path, "{ctx}");
    assert_eq!(e.surface.as_deref(), surface, "{ctx}");
    assert_eq!(e.line, line, "{ctx}");
    assert!(e.problem.contains(needle), "problem should contain {needle:?}{ctx}");
    assert!(shown.contains("scene.toml") && shown.contains(needle), "{ctx}");
    if let Some(s) = surface {
        assert!(shown.contains(&format!("surface '{s}'")), "{ctx}");
    }
}

const SQUARE: &str = "polygon = [[0,0,0],[1,0,0],[1,1,0],[0,1,0]]";

fn one(body: &str) -> String {
    format!("[[surface]]\nname = \"a\"\n{body}\n")
}

#[test]
fn unknown_keys_name_the_line() {
    expect(&one(&format!("{SQUARE}\nemisivity = 0.5 #<")), Some("a"), "unknown field `emisivity`");
    expect(&format!("titel = \"x\" #<\n{}", one(SQUARE)), None, "unknown field `titel`");
    expect(
        &one("rectangle = { origin = [0,0,0], u = [1,0,0], v = [0,1,0], w = 1 } #<"),
        Some("a"),
        "unknown field `w`",
    );
    expect(&format!("[defaults]\ncolour = 1 #<\n{}", one(SQUARE)), None, "unknown field `colour`");
    expect(&format!("[ambient]\ntemperature = 300\nt = 1 #<\n{}", one(SQUARE)), None, "unknown field `t`");
    expect(
        &format!("{}[[model]]\nfile = \"x.glb\"\nscale = 2 #<\n", one(SQUARE)),
        None,
        "unknown field `scale`",
    );
    // An unnamed entry is located by number.
    expect(&format!("{}[[surface]]\n{SQUARE}\nfoo = 1 #<\n", one(SQUARE)), None, "[[surface]] number 2");
}

#[test]
fn names() {
    expect(&format!("[[surface]] #<\n{SQUARE}\n"), None, "[[surface]] number 1 has no `name`");
    expect(
        &format!("{}[[surface]] #<\nname = \"a\"\n{SQUARE}\n", one(SQUARE)),
        Some("a"),
        "duplicate name: line 1",
    );
    expect(&format!("[[surface]]\nname = \"  \" #<\n{SQUARE}\n"), None, "the name is empty");
    expect(&format!("[[surface]]\nname = \"ambient\" #<\n{SQUARE}\n"), Some("ambient"), "reserved");
    expect(&format!("[[surface]]\nname = \"w#1\" #<\n{SQUARE}\n"), Some("w#1"), "may not contain '#'");
    expect(&format!("[[surface]]\nname = 3 #<\n{SQUARE}\n"), None, "expected a string");
}

#[test]
fn non_finite_numbers() {
    expect(&one("polygon = [[0,0,0],[1,0,0],[1,nan,0]] #<"), Some("a"), "polygon vertex 2 is NaN");
    expect(&one(&format!("{SQUARE}\nemissivity = inf #<")), Some("a"), "emissivity is inf");
    expect(&one(&format!("{SQUARE}\ntemperature = -inf #<")), Some("a"), "temperature is -inf");
    expect(&one(&format!("{SQUARE}\nheat_flux = nan #<")), Some("a"), "heat_flux is NaN");
    expect(
        &one("rectangle = { origin = [0,0,0], u = [inf,0,0], v = [0,1,0] } #<"),
        Some("a"),
        "rectangle u is inf",
    );
    expect(
        &one("disk = { center = [0,0,0], normal = [0,0,1], radius = nan } #<"),
        Some("a"),
        "disk radius is NaN",
    );
    expect(&one("polygon = [[0,0,0],[1e300,0,0],[1,1,0]] #<"), Some("a"), "beyond");
    expect(&format!("[ambient]\ntemperature = nan #<\n{}", one(SQUARE)), None, "ambient temperature is NaN");
}

#[test]
fn polygon_geometry() {
    expect(&one("polygon = [[0,0,0],[1,0,0]] #<"), Some("a"), "at least 3");
    expect(
        &one("polygon = [[0,0,0],[1,0,0],[1,0,0],[0,0,0]] #<"),
        Some("a"),
        "at least 3 distinct vertices, got 2",
    );
    expect(&one("polygon = [[0,0,0],[1,0,0],[2,0,0]] #<"), Some("a"), "zero area");
    expect(&one("polygon = [[0,0,0],[1,0,0],[1,1,0.1],[0,1,0]] #<"), Some("a"), "not planar");
    expect(&one("polygon = [[0,0,0],[2,2,0],[2,0,0],[0,1,0]] #<"), Some("a"), "not simple");
    expect(&one("polygon = [[0,0,0],[2,2,0],[2,0,0],[0,2,0]] #<"), Some("a"), "zero area");
    expect(&one("polygon = [[0,0,0],[1,0],[1,1,0]] #<"), Some("a"), "invalid length 2");
    expect(&one("polygon = [] #<"), Some("a"), "got 0");
}

#[test]
fn shapes() {
    expect(&format!("[[surface]] #<\nname = \"a\"\n{SQUARE}\ndisk = {{ center = [0,0,0], normal = [0,0,1], radius = 1 }}\n"), Some("a"), "polygon and disk; give exactly one shape key");
    expect("[[surface]] #<\nname = \"a\"\nemissivity = 0.5\n", Some("a"), "no shape key");
    expect(
        &one("rectangle = { origin = [0,0,0], u = [1,0,0], v = [2,0,0] } #<"),
        Some("a"),
        "parallel or zero",
    );
    expect(
        &one("rectangle = { origin = [0,0,0], u = [0,0,0], v = [0,1,0] } #<"),
        Some("a"),
        "parallel or zero",
    );
    expect(&one("rectangle = { origin = [0,0,0], u = [1,0,0] } #<"), Some("a"), "missing field `v`");
    expect(
        &one("disk = { center = [0,0,0], normal = [0,0,1], radius = 0 } #<"),
        Some("a"),
        "disk radius is 0",
    );
    expect(
        &one("disk = { center = [0,0,0], normal = [0,0,1], radius = -1 } #<"),
        Some("a"),
        "disk radius is -1",
    );
    expect(
        &one("disk = { center = [0,0,0], normal = [0,0,0], radius = 1 } #<"),
        Some("a"),
        "disk normal is zero",
    );
    expect(
        &one("disk = { center = [0,0,0], normal = [0,0,1], radius = 1, segments = 2 } #<"),
        Some("a"),
        "disk segments is 2",
    );
}

#[test]
fn properties() {
    for (e, needle) in [("0", "emissivity is 0"), ("1.5", "emissivity is 1.5"), ("-0.2", "(0, 1]")] {
        expect(&one(&format!("{SQUARE}\nemissivity = {e} #<")), Some("a"), needle);
    }
    expect(&one(&format!("{SQUARE}\nemissivity = \"high\" #<")), Some("a"), "expected a number");
    expect(&one(&format!("{SQUARE}\ntemperature = 0 #<")), Some("a"), "must be positive");
    expect(&one(&format!("{SQUARE}\ntemperature = -20 #<")), Some("a"), "temperature is -20 K");
    expect(&one(&format!("{SQUARE}\nrole = \"blocker\" #<")), Some("a"), "unknown role 'blocker'");
    expect(&format!("[ambient]\ntemperature = -1 #<\n{}", one(SQUARE)), None, "ambient temperature is -1 K");
    expect(&format!("[ambient] #<\n{}", one(SQUARE)), None, "in [ambient]: missing field `temperature`");
    expect(&format!("[defaults]\nemissivity = 2 #<\n{}", one(SQUARE)), None, "[defaults]: emissivity is 2");
    // Obstructions only block rays.
    expect(
        &format!("[[surface]] #<\nname = \"a\"\n{SQUARE}\nrole = \"obstruction\"\ntemperature = 300\n"),
        Some("a"),
        "remove temperature",
    );
}

#[test]
fn patching_options() {
    for (v, needle) in [("[0, 2]", "is 0"), ("[100000, 1]", "between 1 and 10000"), ("[-1, 2]", "is -1")] {
        expect(&one(&format!("{SQUARE}\nsubdivide = {v} #<")), Some("a"), needle);
    }
    expect(&one(&format!("{SQUARE}\nsubdivide = [2, 2.5] #<")), Some("a"), "expected an integer");
    expect(&one(&format!("{SQUARE}\nsubdivide = [2] #<")), Some("a"), "invalid length 1");
    expect(
        &format!("[[surface]] #<\nname = \"a\"\n{SQUARE}\nsubdivide = [9000, 9000]\n"),
        Some("a"),
        "limit",
    );
    for (v, needle) in
        [("0", "max_patch_size is 0"), ("-1", "must be positive"), ("nan", "max_patch_size is NaN")]
    {
        expect(&one(&format!("{SQUARE}\nmax_patch_size = {v} #<")), Some("a"), needle);
    }
    expect(&format!("[[surface]] #<\nname = \"a\"\n{SQUARE}\nmax_patch_size = 1e-6\n"), Some("a"), "limit");
    expect(&one(&format!("{SQUARE}\nmax_patch_size = 0.1\nsubdivide = [2, 2] #<")), Some("a"), "not both");
    expect(
        &one(&format!("{SQUARE}\nrole = \"obstruction\"\nsubdivide = [2, 2] #<")),
        Some("a"),
        "remove subdivide",
    );
    expect(
        "[[surface]] #<\nname = \"a\"\ndisk = { center = [0,0,0], normal = [0,0,1], radius = 1 }\nsubdivide = [3, 1]\n",
        Some("a"),
        "at least 2 sectors",
    );
}

#[test]
fn malformed_and_unreadable_files() {
    expect("[[surface] #<\nname = \"a\"\n", None, "");
    expect(&format!("{}name = \"b\" #<\n", one(SQUARE)), Some("a"), "duplicate key");
    expect("title = #<\n", None, "");
    let dir = tempfile::tempdir().unwrap();
    let e = input_error(&dir.path().join("missing.toml"));
    assert!(e.problem.contains("cannot read") && e.file.ends_with("missing.toml"), "{e}");
    let bin = dir.path().join("binary.toml");
    std::fs::write(&bin, [b'a', b'=', 0xff, 0xfe]).unwrap();
    assert!(input_error(&bin).problem.contains("not UTF-8"));
    let odd = dir.path().join("scene.ply");
    std::fs::write(&odd, "v 0 0 0").unwrap();
    assert!(input_error(&odd).problem.contains("unknown scene file type"));
    let obj = dir.path().join("scene.obj");
    std::fs::write(&obj, "v 0 0 0").unwrap();
    assert!(input_error(&obj).problem.contains("the mesh has no triangles"));
    let empty = write(dir.path(), "title = \"nothing\"\n");
    assert!(input_error(&empty).problem.contains("no exchanging surfaces"));
}

#[test]
fn models() {
    expect(&format!("{}[[model]]\nfile = \"nowhere.glb\" #<\n", one(SQUARE)), None, "does not exist");
    expect(
        &format!("{}[[model]] #<\nemissivity = 0.5\n", one(SQUARE)),
        None,
        "in [[model]] number 1: missing field `file`",
    );
    // Name clashes and overrides need a real model: reference the fixture by absolute path.
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/gltf/hierarchy.gltf");
    let m = format!("[[model]]\nfile = {:?}\n", model.to_str().unwrap());
    expect(&format!("{m}[[surface]] #<\nname = \"PanelA\"\n{SQUARE}\n"), Some("PanelA"), "same name");
    expect(
        &format!("{m}[[surface]]\nname = \"PanelA\"\nsubdivide = [2, 2] #<\n"),
        Some("PanelA"),
        "max_patch_size",
    );
    expect(
        &format!("{m}[[surface]] #<\nname = \"Panel_A\"\ntemperature = 3\n"),
        Some("Panel_A"),
        "no shape key",
    );
    expect(&format!("{m}[[surface]]\nname = \"PanelA\"\nrole = \"x\" #<\n"), Some("PanelA"), "unknown role");
}

/// A model whose format lambert does not read, a TOML scene among them, is refused at the
/// model's line, not read as glTF.
#[test]
fn model_files_of_other_formats() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("part.ply"), "ply\n").unwrap();
    std::fs::write(dir.path().join("other.toml"), "title = \"x\"\n").unwrap();
    let text = format!("{}[[model]]\nfile = \"part.ply\" #<\n", one(SQUARE));
    let e = input_error(&write(dir.path(), &text));
    assert_eq!(e.line, Some(text.lines().position(|l| l.contains("#<")).unwrap() + 1), "{e}");
    assert!(e.problem.contains("unknown model file type") && e.problem.contains(".stl"), "{e}");
    let text = format!("{}[[model]]\nfile = \"other.toml\" #<\n", one(SQUARE));
    let e = input_error(&write(dir.path(), &text));
    assert_eq!(e.line, Some(text.lines().position(|l| l.contains("#<")).unwrap() + 1), "{e}");
    assert!(e.problem.contains("unknown model file type"), "{e}");
}

/// Bad glTF files: (fixture, surface, problem).
#[test]
fn gltf_files() {
    let cases = [
        ("bad_lines.gltf", Some("Panel"), "only triangle primitives"),
        ("bad_degenerate.gltf", Some("Panel"), "no usable triangles (1 degenerate triangle(s) dropped"),
        ("bad_nan.gltf", Some("Panel"), "NaN"),
        ("bad_index.gltf", Some("Panel"), "index 9 is past the 4 vertices"),
        ("bad_duplicate.gltf", Some("Panel"), "names must be unique"),
        ("bad_cycle.gltf", None, ""),
        ("bad_extras.gltf", Some("Panel"), "node extras: emissivity is 1.5"),
        ("bad_role.gltf", Some("Panel"), "remove temperature"),
        ("bad_no_position.gltf", None, ""),
        ("bad_no_scene.gltf", None, "no scene"),
    ];
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/gltf");
    for (file, surface, needle) in cases {
        let e = input_error(&dir.join(file));
        let shown = e.to_string();
        assert!(e.file.ends_with(file) && shown.contains(file), "{file}: {shown}");
        if surface.is_some() {
            assert_eq!(e.surface.as_deref(), surface, "{file}: {shown}");
        }
        assert!(e.problem.contains(needle), "{file}: {shown}");
        assert!(!e.problem.is_empty());
    }
    // Truncated and corrupted binaries.
    let tmp = tempfile::tempdir().unwrap();
    let glb = std::fs::read(dir.join("hierarchy.glb")).unwrap();
    for (k, bytes) in
        [glb[..10].to_vec(), glb[..glb.len() / 2].to_vec(), b"glTF\x02\0\0\0\x04\0\0\0 twelve bytes".to_vec()]
            .iter()
            .enumerate()
    {
        let p = tmp.path().join(format!("cut{k}.glb"));
        std::fs::write(&p, bytes).unwrap();
        let e = input_error(&p);
        assert!(e.problem.contains("malformed") || e.problem.contains("GLB"), "{e}");
    }
    let p = tmp.path().join("broken.gltf");
    std::fs::write(&p, "{ \"asset\": ").unwrap();
    assert!(input_error(&p).problem.contains("malformed glTF"));
}

#[test]
fn boundary_conditions_are_checked_for_solve_only() {
    let dir = tempfile::tempdir().unwrap();
    let text = format!(
        "[[surface]]\nname = \"hot\"\n{SQUARE}\ntemperature = 900\n\
         [[surface]]\nname = \"both\"\npolygon = [[0,0,1],[0,1,1],[1,1,1],[1,0,1]]\ntemperature = 300\nheat_flux = 0\n\
         [[surface]]\nname = \"none\"\nrectangle = {{ origin = [0,0,0], u = [0,0,1], v = [1,0,0] }}\n"
    );
    let path = write(dir.path(), &text);
    // `viewfactors` ignores boundary conditions: the scene loads.
    let s = scene::load(&path).unwrap();
    assert_eq!(s.surfaces[0].condition, Some(BoundaryCondition::Temperature(900.0)));
    let e = match s.check_boundary_conditions() {
        Err(Error::Input(e)) => e,
        other => panic!("{other:?}"),
    };
    assert_eq!((e.surface.as_deref(), e.line), (Some("both"), Some(5)), "{e}");
    assert!(
        e.problem.contains("both temperature and heat_flux") && e.to_string().contains("scene.toml"),
        "{e}"
    );
    // Without the conflict, the missing condition is next.
    let path = write(dir.path(), &text.replace("heat_flux = 0\n", ""));
    let e = scene::load(&path).unwrap().check_boundary_conditions().unwrap_err().to_string();
    assert!(e.contains("scene.toml") && e.contains("'none'") && e.contains("no boundary condition"), "{e}");
    // [defaults] fill the gap; a surface's own heat_flux replaces a default temperature.
    let path =
        write(dir.path(), &format!("[defaults]\ntemperature = 300\n{}", text.replace("heat_flux = 0\n", "")));
    let s = scene::load(&path).unwrap();
    s.check_boundary_conditions().unwrap();
    assert_eq!(s.surfaces[2].condition, Some(BoundaryCondition::Temperature(300.0)));
    // Programmatic scenes: the message still names a file placeholder and the surface.
    let tri = lambert::geometry::Polygon::new(vec![
        lambert::geometry::DVec3::ZERO,
        lambert::geometry::DVec3::X,
        lambert::geometry::DVec3::Y,
    ])
    .unwrap();
    let s = scene::Scene::builder().surface("t", vec![tri], 1.0, None).build();
    assert!(s.check_boundary_conditions().unwrap_err().to_string().contains("<scene>: surface 't'"));
}
