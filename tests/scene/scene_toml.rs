//! Valid TOML scenes: shapes kept exactly, properties, ambient, obstructions, patch counts,
//! areas and orientation; the shipped cases load.
use lambert::geometry::subdivide::diameter;
use lambert::geometry::DVec3;
use lambert::scene::{self, BoundaryCondition, Disk, Scene, Shape};
use std::f64::consts::PI;
use std::path::Path;

/// Patch areas add up to the surface area to round-off (sums of ≤ 1e3 terms).
const AREA_TOL: f64 = 1e-12;

fn from_text(text: &str) -> Scene {
    scene::toml_scene::from_str(Path::new("inline.toml"), text).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn case(name: &str) -> Scene {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("cases").join(name).join("scene.toml");
    scene::load(&p).unwrap_or_else(|e| panic!("{e}"))
}

fn check_patches(s: &Scene) {
    for surf in &s.surfaces {
        let patches = &s.patches[surf.patches.clone()];
        let sum: f64 = patches.iter().map(|p| p.polygon.area()).sum();
        assert!((sum - surf.area).abs() <= AREA_TOL * surf.area, "{}: {sum} vs {}", surf.name, surf.area);
        assert!(patches.iter().all(|p| s.surfaces[p.surface].name == surf.name));
    }
}

#[test]
fn cube_furnace_case() {
    let s = case("cube_furnace");
    assert_eq!(s.title.as_deref(), Some("Unit cube furnace"));
    assert!(s.is_closed());
    assert_eq!(s.surfaces.len(), 6);
    assert_eq!(s.patches.len(), 96);
    check_patches(&s);
    let centre = DVec3::splat(0.5);
    for surf in &s.surfaces {
        assert!((surf.area - 1.0).abs() < AREA_TOL && surf.planar, "{}", surf.name);
        for p in &s.patches[surf.patches.clone()] {
            assert!((p.polygon.area() - 1.0 / 16.0).abs() < AREA_TOL);
            assert!((p.polygon.plane_distance(centre) - 0.5).abs() < 1e-12, "{} faces inward", surf.name);
        }
    }
    let floor = &s.surfaces[s.surface_index("floor").unwrap()];
    assert_eq!((floor.emissivity, floor.condition), (0.8, Some(BoundaryCondition::Temperature(1000.0))));
    let wall = &s.surfaces[s.surface_index("wall_x1").unwrap()];
    assert_eq!((wall.emissivity, wall.condition), (0.5, Some(BoundaryCondition::HeatFlux(0.0))));
    assert_eq!(
        wall.shape,
        Shape::Rectangle { origin: DVec3::X, u: DVec3::Z, v: DVec3::Y },
        "the exact rectangle is kept for closed forms"
    );
    s.check_boundary_conditions().unwrap();
}

#[test]
fn coaxial_disks_case() {
    let s = case("coaxial_disks");
    assert_eq!(s.ambient.map(|a| a.temperature), Some(300.0));
    let top = &s.surfaces[1];
    assert_eq!(
        top.shape,
        Shape::Disk(Disk { center: DVec3::Z, normal: -DVec3::Z, radius: 1.0, segments: 64 })
    );
    assert_eq!(top.patches.len(), 24);
    assert!((top.area - PI).abs() < AREA_TOL * PI, "the 64-gon keeps the disk's area: {}", top.area);
    check_patches(&s);
    assert!(s.patches[top.patches.clone()].iter().all(|p| p.polygon.normal().dot(-DVec3::Z) > 1.0 - 1e-14));
    // Equal-area rings: 8 sectors of π/24 each.
    assert!(s.patches[top.patches.clone()].iter().all(|p| (p.polygon.area() - PI / 24.0).abs() < 1e-12));
}

#[test]
fn shapes_properties_and_obstructions() {
    let s = from_text(
        r#"
title = "mixed"
[ambient]
temperature = 250
[defaults]
emissivity = 0.4
heat_flux = 0
max_patch_size = 0.5

[[surface]]
name = "l"
polygon = [[0,0,0],[2,0,0],[2,1,0],[1,1,0],[1,2,0],[0,2,0]]
subdivide = [2, 2]
emissivity = 0.7

[[surface]]
name = "plate"
rectangle = { origin = [0,0,1], u = [0,1,0], v = [1,0,0] }
temperature = 400

[[surface]]
name = "shade"
disk = { center = [0.5,0.5,0.5], normal = [0,0,1], radius = 0.2, segments = 12 }
role = "obstruction"

[[surface]]
name = "lid"
disk = { center = [0,0,3], normal = [0,0,-2], radius = 0.75, segments = 16 }
"#,
    );
    assert_eq!(s.title.as_deref(), Some("mixed"));
    assert_eq!(s.ambient.unwrap().temperature, 250.0);
    let names: Vec<&str> = s.surfaces.iter().map(|x| x.name.as_str()).collect();
    assert_eq!(names, ["l", "plate", "lid"]);
    check_patches(&s);
    // L: 2×2 grid of 1×1 cells over its bounding box → three square patches.
    let l = &s.surfaces[0];
    assert_eq!((l.shape.clone(), l.patches.len(), l.emissivity), (Shape::Polygon, 3, 0.7));
    assert!((l.area - 3.0).abs() < AREA_TOL);
    assert_eq!(l.condition, Some(BoundaryCondition::HeatFlux(0.0)));
    // plate: [defaults] max_patch_size 0.5 on a unit square → 3×3 cells (diagonal 0.47).
    let plate = &s.surfaces[1];
    assert_eq!(plate.patches.len(), 9);
    assert_eq!((plate.emissivity, plate.condition), (0.4, Some(BoundaryCondition::Temperature(400.0))));
    assert!(s.patches[plate.patches.clone()].iter().all(|p| p.polygon.normal().dot(-DVec3::Z) > 1.0 - 1e-14));
    // lid: normal normalised; max_patch_size 0.5 via the polygon grid.
    let lid = &s.surfaces[2];
    assert!(matches!(lid.shape, Shape::Disk(d) if d.normal == -DVec3::Z && d.segments == 16));
    assert!((lid.area - PI * 0.5625).abs() < AREA_TOL * lid.area);
    assert!(s.patches[lid.patches.clone()]
        .iter()
        .all(|p| diameter(p.polygon.vertices()) <= 0.5 * (1.0 + 1e-12)));
    // shade: an obstruction keeps its whole 12-gon.
    assert_eq!(s.obstructions.len(), 1);
    assert_eq!(s.obstructions[0].polygons[0].vertices().len(), 12);
    s.check_boundary_conditions().unwrap();
}

#[test]
fn integer_numbers_and_inline_surface_arrays_are_accepted() {
    let s = from_text(
        r#"surface = [ { name = "a", polygon = [[0,0,0],[1,0,0],[0,1,0]], temperature = 300 },
                       { name = "b", rectangle = { origin = [0,0,1], u = [1,0,0], v = [0,-1,0] }, heat_flux = -5 } ]"#,
    );
    assert_eq!(s.surfaces[0].condition, Some(BoundaryCondition::Temperature(300.0)));
    assert_eq!(s.surfaces[1].condition, Some(BoundaryCondition::HeatFlux(-5.0)));
    assert!(s.patches[1].polygon.normal().dot(-DVec3::Z) > 1.0 - 1e-15);
}
