//! STL, OBJ and mesh checks end to end from the CLI: bare mesh scenes with `--unit` and
//! `--repair`, every new error path (exit 2, the file named), and leak hints that follow the
//! geometry facts (two outward bodies are never told to flip; an inward part, an open mesh
//! and an outward shell around the scene each get their own hint).
use crate::common;
use common::mesh_files::{ascii_stl, binary_stl, cube, cube_quads, flip, obj, Tri};
use lambert::geometry::DVec3;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_lambert");

fn run(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().expect("run lambert")
}

fn write(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

fn err(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Runs `viewfactors` and expects exit 2 with `what` and the file name on stderr.
fn refused(args: &[&str], file: &Path, what: &str) {
    let o = run(&[&["viewfactors"], args].concat());
    let e = err(&o);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
    let name = file.file_name().unwrap().to_str().unwrap();
    assert!(e.contains(name) && e.contains(what), "{args:?}: expected '{what}' naming {name}: {e}");
    assert!(!e.contains("panicked"), "{e}");
}

/// A glTF file with one node per triangle list (positions in an embedded buffer).
fn gltf(nodes: &[(&str, Vec<Tri>)]) -> String {
    let mut bytes = Vec::new();
    let (mut accessors, mut views, mut meshes, mut json_nodes) = (vec![], vec![], vec![], vec![]);
    for (k, (name, tris)) in nodes.iter().enumerate() {
        let start = bytes.len();
        let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
        for v in tris.iter().flatten() {
            for (c, x) in v.to_array().into_iter().enumerate() {
                bytes.extend((x as f32).to_le_bytes());
                lo[c] = lo[c].min(x as f32);
                hi[c] = hi[c].max(x as f32);
            }
        }
        views.push(format!(r#"{{"buffer":0,"byteOffset":{start},"byteLength":{}}}"#, bytes.len() - start));
        accessors.push(format!(
            r#"{{"bufferView":{k},"componentType":5126,"count":{},"type":"VEC3","min":{lo:?},"max":{hi:?}}}"#,
            3 * tris.len()
        ));
        meshes.push(format!(r#"{{"primitives":[{{"attributes":{{"POSITION":{k}}}}}]}}"#));
        json_nodes.push(format!(r#"{{"name":"{name}","mesh":{k}}}"#));
    }
    let list: Vec<String> = (0..nodes.len()).map(|k| k.to_string()).collect();
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[{}]}}],"nodes":[{}],"meshes":[{}],"accessors":[{}],"bufferViews":[{}],"buffers":[{{"byteLength":{},"uri":"data:application/octet-stream;base64,{}"}}]}}"#,
        list.join(","),
        json_nodes.join(","),
        meshes.join(","),
        accessors.join(","),
        views.join(","),
        bytes.len(),
        base64(&bytes)
    )
}

fn base64(b: &[u8]) -> String {
    const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in b.chunks(3) {
        let n = (c[0] as u32) << 16 | (*c.get(1).unwrap_or(&0) as u32) << 8 | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            s.push(if k <= c.len() { A[(n >> (18 - 6 * k) & 63) as usize] as char } else { '=' });
        }
    }
    s
}

#[test]
fn bare_mesh_scenes_take_unit_and_repair() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "box.stl", binary_stl(&cube(DVec3::ZERO, 1000.0, true)));
    let ps = p.to_str().unwrap();
    let o = run(&["solve", ps, "--unit", "mm", "--enforce", "none", "-q"]);
    // No boundary condition: refused, but after the scene loaded (the unit was accepted).
    assert!(err(&o).contains("no boundary condition"), "{}", err(&o));
    let o = run(&["viewfactors", ps, "--unit", "mm", "--patches", "-q"]);
    assert!(o.status.success(), "{}", err(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    // 12 triangles of a 1 m cube: the two halves of one face see nothing of each other.
    assert!(out.lines().count() > 100 && !out.contains("box#0,box#1,"), "{out}");
    let mut t = cube(DVec3::ZERO, 1.0, false);
    t[4] = flip(t[4]);
    let q = write(dir.path(), "part.obj", {
        let tris: Vec<Vec<DVec3>> = t.iter().map(|x| x.to_vec()).collect();
        obj(&[("", tris)], 0.0)
    });
    let o = run(&["viewfactors", q.to_str().unwrap(), "--repair", "-q"]);
    let e = err(&o);
    assert!(e.contains("part.obj: repair: flipped 1 triangles to agree with their neighbours"), "{e}");
    assert!(!e.contains("wound against"), "{e}");
    let o = run(&["viewfactors", q.to_str().unwrap(), "-q"]);
    assert!(err(&o).contains("part.obj: 1 triangles are wound against their neighbours"), "{}", err(&o));
}

#[test]
fn every_new_error_is_exit_2_and_names_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Unreadable, empty, no triangles, not STL, text after endsolid.
    let folder = d.join("folder.stl");
    std::fs::create_dir(&folder).unwrap();
    refused(&[folder.to_str().unwrap()], &folder, "cannot read the STL file");
    let p = write(d, "empty.stl", "");
    refused(&[p.to_str().unwrap()], &p, "the STL file is empty");
    let p = write(d, "none.stl", "solid x\nendsolid x\n");
    refused(&[p.to_str().unwrap()], &p, "no triangles");
    let p = write(d, "none.obj", "v 0 0 0\nv 1 0 0\n");
    refused(&[p.to_str().unwrap()], &p, "no triangles");
    let p = write(d, "junk.stl", vec![7u8; 300]);
    refused(&[p.to_str().unwrap()], &p, "not an STL file");
    let p = write(d, "tail.stl", ascii_stl(&[("a", cube(DVec3::ZERO, 1.0, true))]) + "trailing words\n");
    refused(&[p.to_str().unwrap()], &p, "unexpected text after the endsolid of solid 'a': 'trailing words'");
    let p = write(d, "trunc.stl", "solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n");
    refused(&[p.to_str().unwrap()], &p, "has no endsolid");
    // Degenerate faces only.
    let p = write(d, "flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
    refused(&[p.to_str().unwrap()], &p, "no usable triangles");
    // NaN vertices, binary STL and OBJ.
    let mut t = cube(DVec3::ZERO, 1.0, true);
    t[3][1].y = f64::NAN;
    let p = write(d, "nan.stl", binary_stl(&t));
    refused(&[p.to_str().unwrap()], &p, "triangle 3, corner 1: a vertex position is NaN");
    let p = write(d, "nan.obj", "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n");
    refused(&[p.to_str().unwrap()], &p, "a vertex position is NaN");
    // OBJ face index out of range, with its line.
    let p = write(d, "range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n");
    refused(
        &[p.to_str().unwrap()],
        &p,
        "range.obj:5: malformed OBJ: face index 9 is out of range: the file has 3 vertices",
    );
    let p = write(d, "zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
    refused(&[p.to_str().unwrap()], &p, "face index 0 is out of range");
    let p = write(d, "word.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n");
    refused(&[p.to_str().unwrap()], &p, "word.obj:4: malformed OBJ: face corner 'x' is not a vertex index");
    // Bad units and keys.
    let stl = write(d, "ok.stl", binary_stl(&cube(DVec3::ZERO, 1.0, true)));
    let o = run(&["viewfactors", stl.to_str().unwrap(), "--unit", "furlong"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(err(&o).contains("invalid value 'furlong' for '--unit <UNIT>'"), "{}", err(&o));
    assert!(err(&o).contains("[possible values: m, mm, cm, in, ft]"), "{}", err(&o));
    let bad = |name: &str, key: &str| write(d, name, format!("[[model]]\nfile = \"ok.stl\"\n{key}\n"));
    let p = bad("u.toml", "unit = \"furlong\"");
    refused(&[p.to_str().unwrap()], &p, "u.toml:3: [[model]] 'ok.stl': unknown unit 'furlong'");
    let p = bad("w.toml", "weld = -1.0");
    refused(&[p.to_str().unwrap()], &p, "weld is -1");
    let p = bad("s.toml", "split = \"bodies\"");
    refused(&[p.to_str().unwrap()], &p, "unknown split 'bodies'");
    let p = bad("k.toml", "welds = 1.0");
    refused(&[p.to_str().unwrap()], &p, "welds");
    // --unit and --repair belong to bare mesh scenes; unit and split do not apply to glTF.
    let toml = bad("t.toml", "");
    refused(&[toml.to_str().unwrap(), "--repair"], &toml, "apply to a bare");
    let g = write(d, "g.gltf", gltf(&[("box", cube(DVec3::ZERO, 1.0, true))]));
    refused(&[g.to_str().unwrap(), "--unit", "mm"], &g, "glTF coordinates are metres");
    let p = write(d, "gs.toml", "[[model]]\nfile = \"g.gltf\"\nsplit = \"component\"\n");
    refused(&[p.to_str().unwrap()], &p, "a glTF model is split by its nodes");
    // A solid name that cannot be a surface name.
    let p = write(d, "hash.stl", ascii_stl(&[("a#1", cube(DVec3::ZERO, 1.0, true))]));
    let t = write(d, "h.toml", "[[model]]\nfile = \"hash.stl\"\nsplit = \"group\"\n");
    refused(&[t.to_str().unwrap()], &p, "contains '#'");
}

#[test]
fn two_outward_bodies_are_told_the_scene_is_open_never_to_flip() {
    let dir = tempfile::tempdir().unwrap();
    let two = [("a", cube(DVec3::ZERO, 1.0, false)), ("b", cube(DVec3::X * 3.0, 1.0, false))];
    let g = write(dir.path(), "two.gltf", gltf(&two));
    for args in [vec![g.to_str().unwrap()], vec![g.to_str().unwrap(), "--enforce", "closure"]] {
        let o = run(&[&["viewfactors", "-q"], args.as_slice()].concat());
        let e = err(&o);
        assert!(
            e.contains("Nothing encloses the scene: its 2 closed meshes (of surface 'a', 'b') face outward"),
            "{e}"
        );
        assert!(e.contains("[[model]] of a TOML scene with an [ambient]"), "{e}");
        assert!(!e.contains("reverse") && !e.contains("flip"), "{e}");
    }
    // The same bodies in a TOML scene are told to add [ambient].
    write(dir.path(), "two.stl", ascii_stl(&two));
    let t = write(dir.path(), "t.toml", "[[model]]\nfile = \"two.stl\"\nsplit = \"component\"\n");
    let e = err(&run(&["viewfactors", t.to_str().unwrap(), "-q"]));
    assert!(e.contains("so the scene is open: add an [ambient]") && !e.contains("reverse"), "{e}");
}

#[test]
fn an_outward_shell_around_the_scene_is_offered_the_flip_and_an_inward_part_is_named() {
    let dir = tempfile::tempdir().unwrap();
    // A room wound outward around a correct part: the room may be a flipped enclosure.
    let room = cube(DVec3::ZERO, 3.0, false);
    let part = cube(DVec3::splat(1.0), 1.0, false);
    let p = write(dir.path(), "scene.stl", ascii_stl(&[("room", room.clone()), ("part", part.clone())]));
    let o = run(&["viewfactors", p.to_str().unwrap(), "-q"]);
    let e = err(&o);
    assert!(
        e.contains("is a closed mesh whose normals all face outward around the rest of the scene"),
        "{e}"
    );
    assert!(e.contains("if it is the enclosure, reverse its triangles' winding"), "{e}");
    // A correct room around a flipped part: the part is named, the room is not.
    let room_in: Vec<Tri> = room.iter().copied().map(flip).collect();
    let part_in: Vec<Tri> = part.iter().copied().map(flip).collect();
    write(dir.path(), "b.stl", ascii_stl(&[("room", room_in.clone()), ("part", part_in)]));
    let t = write(dir.path(), "b.toml", "[[model]]\nfile = \"b.stl\"\nsplit = \"group\"\n");
    let o = run(&["viewfactors", t.to_str().unwrap(), "-q", "--enforce", "closure"]);
    let e = err(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains("A closed mesh of surface 'b/part' (1.000e0 m³) faces inward inside the scene"),
        "{e}"
    );
    assert!(!e.contains("'b/room' is a closed mesh"), "{e}");
    // Repaired, the part faces outward and the scene closes: no leak. The room holds the part,
    // so it is an enclosure and stays as it is.
    let t = write(dir.path(), "r.toml", "[[model]]\nfile = \"b.stl\"\nsplit = \"group\"\nrepair = true\n");
    let o = run(&["viewfactors", t.to_str().unwrap(), "-q", "--enforce", "closure"]);
    assert!(o.status.success(), "{}", err(&o));
    assert!(err(&o).contains("turned 1 closed component(s) (12 triangles)"), "{}", err(&o));
}

#[test]
fn an_open_mesh_is_named_with_its_boundary_edges() {
    let dir = tempfile::tempdir().unwrap();
    let mut faces = cube_quads(DVec3::ZERO, 1.0, true);
    faces.pop();
    let p = write(dir.path(), "box.obj", obj(&[("", faces)], 0.0));
    let o = run(&["viewfactors", p.to_str().unwrap(), "-q", "--enforce", "closure"]);
    let e = err(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(e.contains("The exchanging surfaces do not close: their area vectors sum to 1.000e0 m²"), "{e}");
    assert!(e.contains("'box' is an open mesh, 4 boundary edges"), "{e}");
    assert!(!e.contains("reverse"), "{e}");
}
