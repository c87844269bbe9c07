//! glTF loading: node hierarchy transforms against hand-computed world positions, the three
//! containers (embedded .gltf, external .bin, .glb), names, extras, winding under mirroring,
//! strips, dropped degenerate triangles, `[[model]]` defaults and overrides.
//! Fixtures: tests/data/make_gltf.py.
use lambert::geometry::subdivide::diameter;
use lambert::geometry::DVec3;
use lambert::scene::{self, BoundaryCondition, Scene, Shape};
use std::path::{Path, PathBuf};

/// f32 positions and an f32 quaternion renormalised in f64: world positions match hand values
/// to f32 round-off of the inputs (all inputs here are exact in f32 but the quaternion).
const POS_TOL: f64 = 1e-6;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

fn load(name: &str) -> Scene {
    scene::load(&data(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn close(a: DVec3, b: DVec3) -> bool {
    (a - b).length() < POS_TOL
}

fn surface<'a>(s: &'a Scene, name: &str) -> &'a lambert::scene::Surface {
    &s.surfaces[s.surface_index(name).unwrap_or_else(|| panic!("no surface {name}"))]
}

fn first_triangle(s: &Scene, name: &str) -> Vec<DVec3> {
    s.patches[surface(s, name).patches.start].polygon.vertices().to_vec()
}

#[test]
fn hierarchy_world_positions_match_hand_computation() {
    let s = load("gltf/hierarchy.gltf");
    let names: Vec<&str> = s.surfaces.iter().map(|x| x.name.as_str()).collect();
    assert_eq!(
        names,
        ["PanelA", "PanelB", "node3", "Mirror", "StripPanel"],
        "Ghost is in scene 1, not the default"
    );
    // PanelA = T(10,0,5)·S(2) on the unit quad.
    let a = first_triangle(&s, "PanelA");
    let want = [DVec3::new(10.0, 0.0, 5.0), DVec3::new(12.0, 0.0, 5.0), DVec3::new(12.0, 2.0, 5.0)];
    assert!(a.iter().zip(want).all(|(x, y)| close(*x, y)), "{a:?}");
    assert!((surface(&s, "PanelA").area - 4.0).abs() < POS_TOL);
    // PanelB = T(10,0,5)·T(1,0,0)·Rx(90°): (1,1,0) → (12,0,6), normal +z → −y.
    let b = first_triangle(&s, "PanelB");
    let want = [DVec3::new(11.0, 0.0, 5.0), DVec3::new(12.0, 0.0, 5.0), DVec3::new(12.0, 0.0, 6.0)];
    assert!(b.iter().zip(want).all(|(x, y)| close(*x, y)), "{b:?}");
    let pb = &s.patches[surface(&s, "PanelB").patches.start].polygon;
    assert!(close(pb.normal(), -DVec3::Y), "{:?}", pb.normal());
    // Unnamed node with an unnamed mesh: "node3"; its degenerate triangle is dropped.
    let n3 = surface(&s, "node3");
    assert_eq!(n3.patches.len(), 1);
    assert!(s.warnings.iter().any(|w| w.contains("node3") && w.contains("dropped 1")), "{:?}", s.warnings);
    assert!(close(s.patches[n3.patches.start].polygon.normal(), -DVec3::Y));
    // Mirror = T(10,0,5)·T(0,3,0)·S(−1,1,1): winding reversed, so the front stays +z.
    let m = first_triangle(&s, "Mirror");
    let want = [DVec3::new(10.0, 3.0, 5.0), DVec3::new(9.0, 4.0, 5.0), DVec3::new(9.0, 3.0, 5.0)];
    assert!(m.iter().zip(want).all(|(x, y)| close(*x, y)), "{m:?}");
    for p in surface(&s, "Mirror").patches.clone() {
        assert!(close(s.patches[p].polygon.normal(), DVec3::Z));
    }
    // Triangle strip: two triangles, both +z, at z = −2.
    let strip = surface(&s, "StripPanel");
    assert_eq!(strip.patches.len(), 2);
    for p in strip.patches.clone() {
        let poly = &s.patches[p].polygon;
        assert!(close(poly.normal(), DVec3::Z) && poly.vertices().iter().all(|v| v.z == -2.0));
    }
    assert!((strip.area - 1.0).abs() < POS_TOL);
    // Shield is an obstruction (extras role) with its two triangles.
    assert_eq!(s.obstructions.len(), 1);
    assert_eq!(s.obstructions[0].name, "Shield");
    assert_eq!(s.obstructions[0].polygons.len(), 2);
    assert!(s.surfaces.iter().all(|x| x.shape == Shape::Mesh && x.planar));
}

#[test]
fn bare_gltf_uses_default_properties_and_extras() {
    let s = load("gltf/hierarchy.gltf");
    let a = surface(&s, "PanelA");
    assert_eq!((a.emissivity, a.condition), (0.7, Some(BoundaryCondition::Temperature(350.0))));
    assert_eq!(surface(&s, "PanelB").condition, Some(BoundaryCondition::HeatFlux(0.0)));
    let n3 = surface(&s, "node3");
    assert_eq!((n3.emissivity, n3.condition), (1.0, None));
    assert!(s.is_closed(), "a bare glTF scene has no ambient");
    let err = s.check_boundary_conditions().unwrap_err().to_string();
    assert!(
        err.contains("hierarchy.gltf") && err.contains("'node3'") && err.contains("no boundary condition"),
        "{err}"
    );
}

#[test]
fn embedded_external_and_binary_containers_agree() {
    let a = load("gltf/hierarchy.gltf");
    for other in ["gltf/external.gltf", "gltf/hierarchy.glb"] {
        let b = load(other);
        assert_eq!(a.surfaces, b.surfaces, "{other}");
        assert_eq!(a.patches, b.patches, "{other}");
        assert_eq!(a.obstructions, b.obstructions, "{other}");
    }
}

#[test]
fn model_defaults_and_overrides_resolve_by_priority() {
    let s = load("model_scene.toml");
    let names: Vec<&str> = s.surfaces.iter().map(|x| x.name.as_str()).collect();
    assert_eq!(names, ["floor", "PanelA", "PanelB", "node3", "Mirror", "StripPanel"]);
    assert_eq!(s.title.as_deref(), Some("Model with overrides"));
    let check = |name: &str, e: f64, c: Option<BoundaryCondition>| {
        let x = surface(&s, name);
        assert_eq!((x.emissivity, x.condition), (e, c), "{name}");
    };
    check("floor", 0.9, Some(BoundaryCondition::Temperature(300.0))); // [defaults]
    check("PanelA", 0.7, Some(BoundaryCondition::Temperature(350.0))); // node extras
    check("PanelB", 0.8, Some(BoundaryCondition::Temperature(500.0))); // override beats extras
    check("node3", 0.8, Some(BoundaryCondition::Temperature(290.0))); // [[model]]
                                                                      // max_patch_size on a mesh: each unit right triangle (longest edge √2) → n = ⌈√2/0.5⌉ = 3.
    let strip = surface(&s, "StripPanel");
    assert_eq!(strip.patches.len(), 18);
    assert!(s.patches[strip.patches.clone()].iter().all(|p| diameter(p.polygon.vertices()) <= 0.5));
    assert!((strip.area - 1.0).abs() < 1e-12);
    assert!(s.patches[strip.patches.clone()].iter().all(|p| p.polygon.normal().dot(DVec3::Z) > 1.0 - 1e-12));
    // The model's Shield stays an obstruction (node extras).
    let obs: Vec<&str> = s.obstructions.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(obs, ["Shield"]);
    s.check_boundary_conditions().unwrap();
}

#[test]
fn box_interior_case_faces_inward() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/box_interior/scene.toml");
    let s = scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let bx = surface(&s, "box");
    assert_eq!(bx.patches.len(), 12);
    assert!(!bx.planar, "the box interior sees itself");
    assert!((bx.area - 6.0).abs() < 1e-12);
    let centre = DVec3::splat(0.5);
    for p in &s.patches {
        let poly = &p.polygon;
        assert!(poly.plane_distance(centre) > 0.49, "every face looks at the centre: {poly:?}");
    }
}

#[test]
fn instanced_unnamed_nodes_get_stable_unique_names() {
    let s = load("gltf/instanced.gltf");
    let names: Vec<&str> = s.surfaces.iter().map(|x| x.name.as_str()).collect();
    assert_eq!(names, ["M_node0", "M_node1"]);
    assert!(s.patches[s.surfaces[1].patches.start].polygon.vertices().iter().all(|v| v.z == 1.0));
}

#[test]
fn model_role_and_name_clashes_between_models() {
    let dir = tempfile::tempdir().unwrap();
    let model = data("gltf/hierarchy.gltf");
    let m = format!("[[model]]\nfile = {:?}\n", model.to_str().unwrap());
    let floor = "[[surface]]\nname = \"floor\"\npolygon = [[0,0,0],[1,0,0],[0,1,0]]\n";
    // A model-wide role: every surface of the model only blocks rays.
    let path = dir.path().join("role.toml");
    std::fs::write(&path, format!("{floor}{m}role = \"obstruction\"\n")).unwrap();
    let s = scene::load(&path).unwrap();
    assert_eq!(s.surfaces.len(), 1);
    assert_eq!(s.obstructions.len(), 6);
    // The same model twice: its names clash.
    let path = dir.path().join("twice.toml");
    std::fs::write(&path, format!("{m}{m}")).unwrap();
    let e = scene::load(&path).unwrap_err().to_string();
    assert!(e.contains("hierarchy.gltf: surface 'PanelA'") && e.contains("names must be unique"), "{e}");
}
