//! View3D `.vs3` input: the files in tests/data/vs3 (written by tests/data/make_vs3.py) against
//! closed forms and against each other (F 3 and F 3a), every refusal naming the file and line,
//! and no panic on truncated or mangled text.
use lambert::scene::{self, vs3, Scene};
use lambert::viewfactor::analytic::kernel::GAUSS_REL_TOL;
use lambert::viewfactor::{self, Level, Method, Params, ViewFactors};
use proptest::prelude::*;
use std::path::{Path, PathBuf};

/// Howell C-11: unit squares facing each other at gap 1.
const F_OPPOSITE: f64 = 0.199_824_895_698_387_5;
/// Howell C-14: unit squares sharing an edge at 90°.
const F_ADJACENT: f64 = 0.200_043_776_075_403_2;
/// Parallel unit squares 1 apart past a 0.5² plate in a corner at half height
/// (cases/o5_squares_corner_blocker, generator shadow integral to 2e-15).
const F_CORNER: f64 = 0.149_868_671_773_790_43;
/// The exact method on polygon pairs (DEVELOPERS.md: about 1e-9 relative).
const EXACT_TOL: f64 = 1e-9;
/// The L-shaped room has pairs that see each other past its inner corner: the shadowed branch
/// integrates those to the kernel's relative goal (not to round-off), row sums included, and
/// F 3 against F 3a differ by that much too (the quadrilaterals are split along other
/// diagonals, so the adaptive rule takes other paths).
const SHADOWED_TOL: f64 = GAUSS_REL_TOL;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/vs3").join(name)
}

fn exact(scene: &Scene) -> ViewFactors {
    let params = Params { method: Method::Analytic, ..Params::default() };
    viewfactor::compute(scene, &params, Level::Surface).expect("computes")
}

fn get(vf: &ViewFactors, from: &str, to: &str) -> f64 {
    let at = |n: &str| vf.names.iter().position(|x| x == n).unwrap_or_else(|| panic!("no surface {n}"));
    vf.get(at(from), at(to))
}

fn parse_err(text: &str) -> String {
    match vs3::parse(Path::new("model.vs3"), text) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn the_unit_cube_gives_the_closed_forms_and_its_controls() {
    let scene = scene::load(&data("cube.vs3")).unwrap();
    assert!(scene.is_closed(), "encl = 1 is a closed enclosure");
    assert_eq!(scene.run_defaults.tolerance, Some(1e-6));
    assert!(scene.run_defaults.closure);
    assert_eq!(scene.title.as_deref(), Some("Unit cube, closed"));
    assert!(scene.surfaces.iter().all(|s| s.emissivity == 0.8));
    let vf = exact(&scene);
    let rel = |x: f64, r: f64| (x - r).abs() / r;
    assert!(rel(get(&vf, "floor", "ceiling"), F_OPPOSITE) < EXACT_TOL);
    assert!(rel(get(&vf, "wall_x0", "wall_x1"), F_OPPOSITE) < EXACT_TOL);
    for wall in ["wall_x0", "wall_x1", "wall_y0", "wall_y1"] {
        assert!(rel(get(&vf, "floor", wall), F_ADJACENT) < EXACT_TOL, "floor -> {wall}");
    }
    for s in vf.row_sums() {
        assert!((s - 1.0).abs() < EXACT_TOL, "row sum {s}");
    }
}

#[test]
fn a_radiating_surface_also_blocks_as_in_view3d() {
    let scene = scene::load(&data("blocked_squares.vs3")).unwrap();
    assert!(!scene.is_closed(), "encl = 0 leaves the scene open");
    assert_eq!(scene.ambient.map(|a| a.temperature), Some(0.0), "open to deep space at 0 K");
    let vf = exact(&scene);
    let f = get(&vf, "bottom", "top");
    assert!((f - F_CORNER).abs() / F_CORNER < EXACT_TOL, "F(bottom -> top) = {f}");
    assert!((get(&vf, "top", "bottom") - f).abs() < EXACT_TOL * f, "reciprocity of equal areas");
}

#[test]
fn f3_and_f3a_describe_the_same_l_shaped_room() {
    let a = scene::load(&data("l_room.vs3")).unwrap();
    let b = scene::load(&data("l_room_f3a.vs3")).unwrap();
    let names: Vec<&str> = a.surfaces.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "floor",
            "ceiling",
            "wall_south",
            "wall_east",
            "notch_south",
            "notch_east",
            "wall_north",
            "wall_west_a"
        ],
        "combined surfaces are merged into the surface they name"
    );
    let area = |s: &Scene, n: &str| s.surfaces.iter().find(|x| x.name == n).unwrap().area;
    for s in [&a, &b] {
        assert!((area(s, "floor") - (4.0 * 1.5 + 2.5 * 1.5)).abs() < 1e-12);
        assert!((area(s, "wall_west_a") - 3.0 * 2.5).abs() < 1e-12);
        assert_eq!(s.surfaces.iter().find(|x| x.name == "wall_east").unwrap().emissivity, 0.7);
    }
    let (fa, fb) = (exact(&a), exact(&b));
    assert_eq!(fa.names, fb.names);
    for i in 0..fa.names.len() {
        assert!((fa.row_sums()[i] - 1.0).abs() < SHADOWED_TOL, "closed room, row {}", fa.names[i]);
        for j in 0..fa.names.len() {
            let (x, y) = (fa.get(i, j), fb.get(i, j));
            assert!(
                (x - y).abs() <= SHADOWED_TOL * x.max(y),
                "{} -> {}: F 3 {x} vs F 3a {y}",
                fa.names[i],
                fa.names[j]
            );
        }
    }
}

#[test]
fn blast_shapes_place_rectangles_triangles_and_quads() {
    // A 2 × 1 rectangle facing east (azimuth 90°, tilt 90°: a wall whose local x runs north)
    // and the same as a quad.
    let text = "F 3a\nS 1 R 0 0 0.5 r\n 1 2 3  90 90  2 1\nS 2 Q 0 0 0.5 q\n 1 2 3 90 90 0 0 2 0 2 1 0 1\n\
                S 3 T 0 0 0.5 t\n 0 0 0 180 0  0 0 1 0 0 1\nE\n";
    let v = vs3::parse(Path::new("blast.vs3"), text).unwrap();
    let ring = |k: usize| -> Vec<[f64; 3]> {
        v.model.surfaces[k].triangles.iter().flat_map(|t| t.vertices().iter().map(|q| q.to_array())).collect()
    };
    // Every corner is some vertex and every vertex some corner (to round-off of the rotation).
    let close = |a: &[[f64; 3]], b: &[[f64; 3]]| {
        let near = |x: &[f64; 3], y: &[f64; 3]| (0..3).all(|k| (x[k] - y[k]).abs() < 1e-12);
        a.iter().all(|x| b.iter().any(|y| near(x, y))) && b.iter().all(|y| a.iter().any(|x| near(x, y)))
    };
    let wall = [[1.0, 2.0, 3.0], [1.0, 2.0, 4.0], [1.0, 4.0, 3.0], [1.0, 4.0, 4.0]];
    assert!(close(&ring(0), &wall), "R: {:?}", ring(0));
    assert!(close(&ring(1), &wall), "Q: {:?}", ring(1));
    // A rectangle or quadrilateral is one polygon (one patch), never split on a diagonal.
    for k in [0, 1] {
        let polys = &v.model.surfaces[k].triangles;
        assert_eq!((polys.len(), polys[0].vertices().len()), (1, 4), "surface {k}");
    }
    let n = v.model.surfaces[0].triangles[0].normal();
    assert!((n.x - 1.0).abs() < 1e-12, "azimuth 90°, tilt 90° faces east (+x): {n:?}");
    let floor = [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]];
    assert!(close(&ring(2), &floor), "T: {:?}", ring(2));
    assert!(v.model.surfaces[2].triangles[0].normal().z > 0.999, "tilt 0 faces up");
}

#[test]
fn controls_are_read_warned_or_refused() {
    let body = "F 3\nV 1 0 0 0\nV 2 1 0 0\nV 3 0 1 0\nS 1 1 2 3 0 0 0 0.5 a\n";
    let v =
        vs3::parse(Path::new("c.vs3"), &format!("C encl=1 emit=1 eps=1e-5 maxu=8 list=2\n{body}")).unwrap();
    assert_eq!(v.controls, vs3::Controls { enclosure: true, emittances: true, eps: Some(1e-5) });
    assert!(v.warnings.iter().any(|w| w.contains("maxu=8") && w.contains("c.vs3: line 1")));
    let v = vs3::parse(Path::new("c.vs3"), &format!("C frob=2\n{body}")).unwrap();
    assert!(v.warnings.iter().any(|w| w.contains("unknown control word `frob`")));
    assert!(parse_err(&format!("C eps=2\n{body}")).contains("model.vs3:1: control eps=2 must be in (0, 1)"));
    assert!(parse_err(&format!("C encl=yes\n{body}")).contains("`encl=yes` is not a number"));
}

#[test]
fn emittances_names_and_combined_surfaces() {
    let v = vs3::parse(
        Path::new("e.vs3"),
        "F 3\nV 1 0 0 0\nV 2 1 0 0\nV 3 1 1 0\nV 4 0 1 0\n\
         S 1 1 2 3 0 0 0 0.0 ambient\nS 2 1 3 4 0 0 0 0.9 ambient\nS 3 1 3 4 0 0 1 0.5 part\nO 4 1 2 3 0\n",
    )
    .unwrap();
    let s = &v.model.surfaces;
    assert_eq!(s.len(), 3, "part merges into surface 1; the obstruction stays");
    // Two triangle records, combined: one polygon each.
    let corners: Vec<usize> = s[0].triangles.iter().map(|p| p.vertices().len()).collect();
    assert_eq!((s[0].name.as_str(), corners), ("ambient_1", vec![3, 3]));
    assert_eq!(s[1].name, "ambient_2");
    assert_eq!(s[0].extras.emissivity, Some(0.001), "View3D's lower clamp");
    assert_eq!(s[2].extras.role, Some(lambert::scene::props::Role::Obstruction));
    let joined = v.warnings.join("\n");
    assert!(joined.contains("clamped to 0.001"), "{joined}");
    assert!(joined.contains("renamed 'ambient_1'"), "{joined}");
    assert!(joined.contains("combines into 1 (ambient) with 0"), "{joined}");
}

/// Every refusal: the message names the file, the line and the problem.
#[test]
fn refusals_name_the_file_the_line_and_the_problem() {
    let v = "V 1 0 0 0\nV 2 1 0 0\nV 3 1 1 0\nV 4 0 1 0\n";
    let cases: Vec<(String, &str)> = vec![
        ("T no geometry\n".into(), "model.vs3: no `F 3` or `F 3a` record"),
        ("F 2\n".into(), "model.vs3:1: geometry format 'F 2' is not supported"),
        (format!("F 3\n{v}M 1 1 2 3 4\n"), "model.vs3:6: mask (M) surfaces are not supported"),
        (format!("F 3\n{v}N 1 1 2 3 4\n"), "model.vs3:6: null (N) surfaces are not supported"),
        (
            format!("F 3\n{v}S 1 1 2 3 4 0 0 0.5 a\nS 2 1 2 3 0 1 0 0.5 b\n"),
            "model.vs3:7: surface 2 is a subsurface of surface 1",
        ),
        (format!("F 3\n{v}Z 1\n"), "model.vs3:6: unknown record 'Z'"),
        (
            format!("F 3\n{v}S 1 1 2 3 4 0 0\n"),
            "model.vs3:6: the record is truncated: the emittance is missing",
        ),
        (format!("F 3\n{v}S 1 1 2 3 4 0 0 x a\n"), "model.vs3:6: the emittance 'x' is not a finite number"),
        (
            format!("F 3\n{v}S 1 1 2 9 4 0 0 0.5 a\n"),
            "model.vs3:6: surface 'a': surface 1: vertex 9 is missing (the file defines 4)",
        ),
        (format!("F 3\n{v}S 2 1 2 3 4 0 0 0.5 a\n"), "model.vs3:6: surface 2 is out of sequence: expected 1"),
        ("F 3\nV 2 0 0 0\n".into(), "model.vs3:2: vertex 2 is out of sequence: expected 1"),
        ("F 3\nV 1 0 0 nan\n".into(), "model.vs3:2: z 'nan' is not a finite number"),
        (v.to_string(), "model.vs3: no `F 3` or `F 3a` record"),
        ("S 1 1 2 3 4 0 0 0.5 a\n".into(), "model.vs3:1: a surface record before the `F 3` or `F 3a` record"),
        ("F 3a\nV 1 0 0 0\n".into(), "model.vs3:2: a V (vertex) record in an F 3a file"),
        ("F 3a\nS 1 X 0 0 0.5 a\n 0 0 0 0 0 1 1\n".into(), "model.vs3:2: shape 'X' is not R, Q or T"),
        (
            "F 3a\nS 1 R 0 0 0.5 a\n 0 0 0 0 0\n".into(),
            "model.vs3:2: the record is truncated: the width is missing",
        ),
        (
            format!("F 3\n{v}O 1 1 2 3 4\nS 2 1 2 3 4 0 0 0.5 a\n"),
            "model.vs3:7: surface 2: radiating surfaces must come before obstructions (O)",
        ),
        (
            format!("F 3\n{v}S 1 1 2 3 4 0 2 0.5 a\nS 2 1 2 3 4 0 0 0.5 b\n"),
            "model.vs3:6: surface 'a': surface 1 combines into 2, which is not an earlier radiating surface",
        ),
        (
            format!("F 3\n{v}S 1 1 2 3 4 0 0 0.5 a\nS 2 1 2 3 4 0 1 0.5 b\nS 3 1 2 3 4 0 2 0.5 c\n"),
            "model.vs3:8: surface 'c': surface 3 combines into 2, which is itself combined",
        ),
        // A repeated corner is dropped as in any polygon (`1 2 2 4` is a triangle); two left is none.
        (format!("F 3\n{v}S 1 1 2 2 2 0 0 0.5 a\n"), "model.vs3:6: surface 'a': surface 1:"),
        (
            "F 3\nV 1 0 0 0\nV 2 1 0 0\nV 3 1 1 0\nV 4 0 1 1\nS 1 1 2 3 4 0 0 0.5 warped\n".into(),
            "model.vs3:6: surface 'warped': surface 1:",
        ),
    ];
    for (text, want) in cases {
        let got = parse_err(&text);
        assert!(got.contains(want), "for:\n{text}\nwanted: {want}\ngot:    {got}");
    }
}

#[test]
fn comments_continuations_and_end_of_data() {
    let v = vs3::parse(
        Path::new("c.vs3"),
        "! a comment line\nT  Title words  here ! trailing comment\nF 3\nV 1 0 0 0 ! origin\nV 2\n 1 0 0\nV 3 1 1 0\n\
         S 1 1 2 3 0\n 0 0 0.5 tri extra words ignored\nEnd of data\nthis is never read\n",
    )
    .unwrap();
    assert_eq!(v.title.as_deref(), Some("Title words  here"), "the title as written, comment cut");
    assert_eq!(v.model.surfaces.len(), 1);
    assert_eq!(v.model.surfaces[0].name, "tri");
}

#[test]
fn a_toml_scene_can_take_a_view3d_model_and_its_controls_are_set_aside() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(data("cube.vs3"), dir.path().join("cube.vs3")).unwrap();
    let toml = dir.path().join("scene.toml");
    std::fs::write(
        &toml,
        "[[model]]\nfile = \"cube.vs3\"\n\n[[surface]]\nname = \"floor\"\ntemperature = 1000.0\n",
    )
    .unwrap();
    let scene = scene::load(&toml).unwrap();
    assert_eq!(scene.surfaces.len(), 6);
    assert!(scene
        .warnings
        .iter()
        .any(|w| w.contains("control values (encl, emit, eps) of a [[model]] are ignored")));
    assert_eq!(scene.run_defaults, scene::RunDefaults::default());
    let vf = exact(&scene);
    assert!((get(&vf, "floor", "ceiling") - F_OPPOSITE).abs() < EXACT_TOL * F_OPPOSITE);
}

#[test]
fn a_missing_file_is_named() {
    let e = scene::load(&data("no_such.vs3")).unwrap_err().to_string();
    assert!(e.contains("no_such.vs3") && e.contains("cannot read"), "{e}");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// Any prefix of a valid file, or the file with one byte changed, parses or is refused:
    /// never a panic.
    #[test]
    fn truncated_or_mangled_files_never_panic(cut in 0usize..2000, at in 0usize..2000, byte in 0u8..128) {
        for name in ["l_room.vs3", "l_room_f3a.vs3", "blocked_squares.vs3"] {
            let text = std::fs::read_to_string(data(name)).unwrap();
            let cut = cut.min(text.len());
            let _ = vs3::parse(Path::new(name), &text[..cut]);
            let mut bytes = text.into_bytes();
            let at = at.min(bytes.len() - 1);
            bytes[at] = byte;
            let _ = vs3::parse(Path::new(name), &String::from_utf8_lossy(&bytes));
        }
    }
}
