//! STL and OBJ input and the mesh checks, through the library: binary and ASCII STL, OBJ groups
//! and objects, units, welding, split modes, every hygiene finding with its count and worst
//! example, and repair. Every file is written here (tests/common/mesh_files.rs).
use crate::common;
use common::mesh_files::{ascii_stl, binary_stl, cube, cube_faces, cube_quads, flip, obj, Tri};
use common::{F_PARALLEL, F_PERPENDICULAR};
use lambert::geometry::DVec3;
use lambert::scene::{self, Scene};
use lambert::viewfactor::{self, Level, Method, Params};
use std::path::{Path, PathBuf};

fn write(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

fn load(p: &Path) -> Scene {
    scene::load(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn names(s: &Scene) -> Vec<&str> {
    s.surfaces.iter().map(|x| x.name.as_str()).collect()
}

fn warning<'a>(s: &'a Scene, what: &str) -> &'a str {
    s.warnings.iter().find(|w| w.contains(what)).unwrap_or_else(|| panic!("no '{what}' in {:#?}", s.warnings))
}

fn analytic(s: &Scene) -> lambert::viewfactor::ViewFactors {
    let p = Params { method: Method::Analytic, progress: false, ..Params::default() };
    viewfactor::compute(s, &p, Level::Surface).unwrap()
}

/// An inward cube whose faces are ASCII STL solids `f0`..`f5`, in `unit`-scaled coordinates.
fn face_solids(side: f64) -> String {
    let faces: Vec<(String, Vec<Tri>)> = cube_faces(DVec3::ZERO, side)
        .into_iter()
        .enumerate()
        .map(|(k, f)| (format!("f{k}"), f.into_iter().map(flip).collect()))
        .collect();
    let solids: Vec<(&str, Vec<Tri>)> = faces.iter().map(|(n, t)| (n.as_str(), t.clone())).collect();
    ascii_stl(&solids)
}

/// Faces k and k ^ 1 of [`cube_faces`] are opposite.
fn check_cube_factors(s: &Scene, vf: &lambert::viewfactor::ViewFactors, what: &str) {
    for i in 0..6 {
        for j in 0..6 {
            let f = vf.get(i, j);
            let expect = if i == j {
                0.0
            } else if i ^ 1 == j {
                F_PARALLEL
            } else {
                F_PERPENDICULAR
            };
            assert!(
                (f - expect).abs() < 1e-9 * expect.max(1e-9),
                "{what}: F({}, {}) = {f}",
                s.surfaces[i].name,
                s.surfaces[j].name
            );
        }
    }
}

#[test]
fn binary_and_ascii_stl_give_the_same_triangles() {
    let dir = tempfile::tempdir().unwrap();
    let tris = cube(DVec3::ZERO, 1.0, true);
    let b = load(&write(dir.path(), "box_b.stl", binary_stl(&tris)));
    let a = load(&write(dir.path(), "box_a.stl", ascii_stl(&[("box", tris.clone())])));
    assert_eq!((names(&b), names(&a)), (vec!["box_b"], vec!["box_a"]));
    assert_eq!(b.patches.len(), 12);
    for (p, q) in b.patches.iter().zip(&a.patches) {
        assert_eq!(p.polygon.vertices(), q.polygon.vertices());
    }
    // An inward cube alone encloses the scene: an enclosure, no warning.
    assert!(b.warnings.is_empty() && a.warnings.is_empty(), "{:?} {:?}", b.warnings, a.warnings);
    let r = &b.meshes[0];
    assert_eq!((r.components.len(), r.weld.before, r.weld.after), (1, 36, 8));
    assert!(r.components[0].is_inward() && (r.components[0].volume + 1.0).abs() < 1e-12);
}

#[test]
fn a_1000_mm_cube_has_the_unit_cube_factors_of_the_toml_cube() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "box.stl", face_solids(1000.0));
    let p = write(dir.path(), "s.toml", "[[model]]\nfile = \"box.stl\"\nunit = \"mm\"\nsplit = \"group\"\n");
    let s = load(&p);
    assert_eq!(names(&s), ["box/f0", "box/f1", "box/f2", "box/f3", "box/f4", "box/f5"]);
    assert!((s.surfaces.iter().map(|x| x.area).sum::<f64>() - 6.0).abs() < 1e-12);
    let vf = analytic(&s);
    check_cube_factors(&s, &vf, "STL in mm");
    // The TOML cube (one rectangle per face) has the same rows, face for face.
    let toml = common::cube_interior(1);
    let tv = analytic(&toml);
    let sorted = |v: Vec<f64>| {
        let mut v = v;
        v.sort_by(f64::total_cmp);
        v
    };
    for i in 0..6 {
        let a = sorted((0..6).map(|j| vf.get(i, j)).collect());
        let b = sorted((0..6).map(|j| tv.get(i, j)).collect());
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() < 1e-12, "row {i}: {a:?} vs {b:?}");
        }
    }
    // Inches scale too.
    let p = write(dir.path(), "in.toml", "[[model]]\nfile = \"box.stl\"\nunit = \"in\"\n");
    assert!((load(&p).surfaces[0].area - 6.0 * (1000.0 * 0.0254f64).powi(2)).abs() < 1e-9);
}

#[test]
fn welding_closes_a_soup_whose_copies_differ_in_the_last_digits() {
    let dir = tempfile::tempdir().unwrap();
    let groups: Vec<(String, Vec<Vec<DVec3>>)> = cube_quads(DVec3::ZERO, 1.0, true)
        .into_iter()
        .enumerate()
        .map(|(k, q)| (format!("face{k}"), vec![q]))
        .collect();
    let g: Vec<(&str, Vec<Vec<DVec3>>)> = groups.iter().map(|(n, q)| (n.as_str(), q.clone())).collect();
    // Every corner is written once per face, moved by up to 24 × 1e-12 m.
    write(dir.path(), "soup.obj", obj(&g, 1e-12));
    let welded = load(&write(dir.path(), "w.toml", "[[model]]\nfile = \"soup.obj\"\n"));
    let r = &welded.meshes[0];
    assert_eq!((r.weld.before, r.weld.after), (36, 8));
    assert!(r.weld.moved > 0 && r.weld.max_move < 1e-10, "{:?}", r.weld);
    assert_eq!(r.boundary.count, 0);
    assert!(r.components.len() == 1 && r.components[0].is_inward());
    check_cube_factors(&welded, &analytic(&welded), "welded OBJ soup");
    // Without welding the same file is 6 open pieces: 24 boundary edges, said in the warnings.
    let raw = load(&write(dir.path(), "r.toml", "[[model]]\nfile = \"soup.obj\"\nweld = 0\n"));
    let r = &raw.meshes[0];
    assert_eq!((r.weld.after, r.boundary.count, r.components.len()), (24, 24, 6));
    let w = warning(&raw, "open mesh");
    assert!(w.contains("24 boundary edges") && w.contains("on 6 surface(s)"), "{w}");
}

#[test]
fn obj_groups_objects_and_polygons() {
    let dir = tempfile::tempdir().unwrap();
    let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\nv 1 2 0\nv 2 1 0\n\
                f 1 2 3\n\
                o part\ng top\nf 1 2 3 4\n\
                g lshape\nf 1 5 9 3 8 7\n\
                g top\nf 3 9 6 -2/1/1\n";
    let s = load(&write(dir.path(), "m.obj", text));
    // Faces before any group, then groups; `top` continues where it came back.
    assert_eq!(names(&s), ["m/group0", "m/top", "m/lshape"]);
    let area = |n: &str| s.surfaces[s.surface_index(n).unwrap()].area;
    assert!((area("m/top") - 2.0).abs() < 1e-15);
    // The non-convex L (a 2×2 square less its top-right unit square) is ear-clipped: area 3.
    assert!((area("m/lshape") - 3.0).abs() < 1e-15, "{}", area("m/lshape"));
    assert_eq!(s.patches[s.surfaces[2].patches.clone()].len(), 4);
    // split = "file" and "component".
    let one = load(&write(dir.path(), "f.toml", "[[model]]\nfile = \"m.obj\"\nsplit = \"file\"\n"));
    assert_eq!(names(&one), ["m"]);
    assert!((one.surfaces[0].area - 5.5).abs() < 1e-15);
    let two = load(&write(
        dir.path(),
        "c.obj",
        obj(
            &[("a", cube_quads(DVec3::ZERO, 1.0, false)), ("b", cube_quads(DVec3::X * 3.0, 1.0, false))],
            0.0,
        ),
    ));
    assert_eq!(names(&two), ["c/a", "c/b"]);
    let p = write(
        dir.path(),
        "comp.toml",
        "[ambient]\ntemperature = 0\n[[model]]\nfile = \"c.obj\"\nsplit = \"component\"\n",
    );
    let comp = load(&p);
    assert_eq!(names(&comp), ["c/0", "c/1"]);
    assert!(comp.meshes[0].components.iter().all(|c| c.is_outward_body()));
}

#[test]
fn each_finding_is_one_line_with_its_count_and_worst_example() {
    let dir = tempfile::tempdir().unwrap();
    // An outward part inside an inward room; the part carries one defect of each kind.
    let mut part = cube(DVec3::splat(1.0), 1.0, false);
    part[5] = flip(part[5]); // wound against its neighbours
    part.push(part[8]); // a duplicate face
    part.push(part[9]);
    let [a, b, c] = part[0];
    let m = 0.5 * (a + c) + DVec3::new(1e-6, -1e-6, 0.0); // a sliver beside a split triangle
    part[0] = [a, b, m];
    part.push([b, c, m]);
    part.push([a, m, c]);
    // A crossing plate (its own group, so its open edges are its own).
    let plate = vec![[DVec3::new(1.2, 1.5, 0.9), DVec3::new(1.8, 1.5, 0.9), DVec3::new(1.5, 1.5, 1.6)]];
    let stl = ascii_stl(&[("room", cube(DVec3::ZERO, 3.0, true)), ("part", part), ("plate", plate)]);
    write(dir.path(), "w.stl", stl);
    let s = load(&write(dir.path(), "s.toml", "[[model]]\nfile = \"w.stl\"\nsplit = \"group\"\n"));
    let r = &s.meshes[0];
    assert_eq!(r.against.count, 1);
    assert_eq!((r.against.worst.unwrap().at.index, r.name(r.against.worst.unwrap().at)), (5, "w/part"));
    assert!(
        warning(&s, "1 triangles are wound against their neighbours").contains("surface 'w/part' triangle 5")
    );
    assert_eq!(r.duplicates.count, 2);
    assert!(warning(&s, "2 duplicate faces").contains("repeats surface 'w/part' triangle"));
    // Aspect √3·L²/(4A) = √3·2/(4e-6) = 8.7e5 in f64; the STL's f32 corners move m by up to
    // 6e-8 of its 1.4e-6 offset.
    assert_eq!(r.slivers.count, 1);
    let q = r.slivers.worst.unwrap().value;
    assert!((8e5..1e6).contains(&q), "{q}");
    let w = warning(&s, "1 sliver triangles");
    assert!(w.contains("surface 'w/part' triangle 15") && w.contains(&format!("aspect {q:.3e}")), "{w}");
    assert_eq!(r.boundary.count, 3);
    assert!(
        warning(&s, "open mesh").contains("3 boundary edges")
            && warning(&s, "open mesh").contains("'w/plate'")
    );
    assert!(r.intersections.count >= 2, "{:?}", r.intersections);
    let w = warning(&s, "pairs of triangles cross");
    assert!(w.contains("surface 'w/part' triangle") && w.contains("surface 'w/plate' triangle 0"), "{w}");
    // The copied pair of one face puts 3 triangles on their 4 outer edges and 4 on the diagonal.
    assert_eq!(r.nonmanifold.count, 5);
    assert!(warning(&s, "5 non-manifold edges").contains("triangle 8, on an edge of 4 triangles"));
    // The room encloses the scene: an enclosure, not flagged as an inward body.
    assert!(!s.warnings.iter().any(|w| w.contains("face inward")), "{:#?}", s.warnings);
}

#[test]
fn an_inward_part_inside_a_room_is_flagged_and_repair_turns_it() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "part.stl", binary_stl(&cube(DVec3::splat(1.0), 1.0, true)));
    let room = "[[surface]]\nname = \"room\"\npolygon = [[0,0,0],[0,3,0],[3,3,0],[3,0,0]]\n";
    let p = write(dir.path(), "s.toml", format!("{room}[[model]]\nfile = \"part.stl\"\n"));
    let s = load(&p);
    let w = warning(&s, "face inward");
    assert!(
        w.contains("1 closed component(s)") && w.contains("surface 'part'") && w.contains("-1.000e0 m³"),
        "{w}"
    );
    let p = write(dir.path(), "r.toml", format!("{room}[[model]]\nfile = \"part.stl\"\nrepair = true\n"));
    let s = load(&p);
    assert!(warning(&s, "repair:").contains("turned 1 closed component(s) (12 triangles)"));
    assert!(s.meshes[0].components[0].is_outward_body());
    assert!(!s.warnings.iter().any(|w| w.contains("face inward")));
    // Every triangle now faces away from the part's centre.
    for p in &s.patches[s.surfaces[1].patches.clone()] {
        assert!(p.polygon.normal().dot(p.polygon.centroid() - DVec3::splat(1.5)) > 0.0);
    }
}

#[test]
fn repair_flips_a_wrong_triangle_and_drops_duplicates() {
    let dir = tempfile::tempdir().unwrap();
    let mut t = cube(DVec3::ZERO, 1.0, false);
    t[3] = flip(t[3]);
    t.push(t[7]);
    write(dir.path(), "p.stl", binary_stl(&t));
    let amb = "[ambient]\ntemperature = 0\n";
    let s = load(&write(dir.path(), "a.toml", format!("{amb}[[model]]\nfile = \"p.stl\"\n")));
    assert_eq!((s.patches.len(), s.meshes[0].against.count, s.meshes[0].duplicates.count), (13, 1, 1));
    let s = load(&write(dir.path(), "b.toml", format!("{amb}[[model]]\nfile = \"p.stl\"\nrepair = true\n")));
    let w = warning(&s, "repair:");
    assert!(w.contains("dropped 1 duplicate faces") && w.contains("flipped 1 triangles"), "{w}");
    assert_eq!(s.patches.len(), 12);
    let r = &s.meshes[0];
    assert_eq!((r.against.count, r.duplicates.count, r.nonmanifold.count), (0, 0, 0));
    assert!(r.components[0].is_outward_body());
    assert!(r.repair.is_some_and(|l| l.flipped == 1 && l.duplicates == 1));
}

#[test]
fn an_irregularly_meshed_box_is_closed_across_its_seams() {
    // Each face of the validation box is triangulated on its own: 168 edges end in T-junctions.
    let s = load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/o7_irregular_box_block/scene.toml"));
    let r = &s.meshes[0];
    assert_eq!((r.boundary.count, r.seams), (0, 168), "{:?}", r.boundary);
    assert!(r.components.iter().any(|c| c.closed && c.consistent && c.volume < 0.0), "{:?}", r.components);
    assert!(s.warnings.is_empty(), "{:#?}", s.warnings);
}

#[test]
fn gltf_models_are_checked_too() {
    let glb = Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/box_interior/box.glb");
    let s = load(&glb);
    assert_eq!(s.meshes.len(), 1);
    assert!(s.meshes[0].components.iter().all(|c| c.closed && c.consistent && c.volume < 0.0));
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
}
