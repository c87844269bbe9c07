//! STL and OBJ files written by the tests: unit cubes (whole, per face, flipped, as a soup),
//! binary and ASCII STL writers and an OBJ writer with groups.
use lambert::geometry::DVec3;

/// A triangle.
pub type Tri = [DVec3; 3];

/// The two triangles of each face of the cube [o, o + s]³, outward, faces in the order
/// z = 0, z = 1, y = 0, y = 1, x = 0, x = 1.
pub fn cube_faces(o: DVec3, s: f64) -> Vec<[Tri; 2]> {
    let p = |x: f64, y: f64, z: f64| o + s * DVec3::new(x, y, z);
    let quads = [
        [p(0., 0., 0.), p(0., 1., 0.), p(1., 1., 0.), p(1., 0., 0.)],
        [p(0., 0., 1.), p(1., 0., 1.), p(1., 1., 1.), p(0., 1., 1.)],
        [p(0., 0., 0.), p(1., 0., 0.), p(1., 0., 1.), p(0., 0., 1.)],
        [p(0., 1., 0.), p(0., 1., 1.), p(1., 1., 1.), p(1., 1., 0.)],
        [p(0., 0., 0.), p(0., 0., 1.), p(0., 1., 1.), p(0., 1., 0.)],
        [p(1., 0., 0.), p(1., 1., 0.), p(1., 1., 1.), p(1., 0., 1.)],
    ];
    quads.iter().map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect()
}

/// The 12 triangles of the cube, outward (or inward: an enclosure seen from inside).
pub fn cube(o: DVec3, s: f64, inward: bool) -> Vec<Tri> {
    let t: Vec<Tri> = cube_faces(o, s).into_iter().flatten().collect();
    if inward {
        t.into_iter().map(flip).collect()
    } else {
        t
    }
}

/// The triangle seen from its other side.
pub fn flip(t: Tri) -> Tri {
    [t[0], t[2], t[1]]
}

/// Binary STL; the header starts with "solid" as many exporters write it.
pub fn binary_stl(tris: &[Tri]) -> Vec<u8> {
    let mut b = Vec::new();
    let mut header = b"solid written as binary".to_vec();
    header.resize(80, b' ');
    b.extend(header);
    b.extend((tris.len() as u32).to_le_bytes());
    for t in tris {
        let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
        for v in std::iter::once(n).chain(t.iter().copied()) {
            for x in v.to_array() {
                b.extend((x as f32).to_le_bytes());
            }
        }
        b.extend([0u8, 0]);
    }
    b
}

/// ASCII STL with one `solid` block per (name, triangles).
pub fn ascii_stl(solids: &[(&str, Vec<Tri>)]) -> String {
    let mut s = String::new();
    for (name, tris) in solids {
        s.push_str(&format!("solid {name}\n"));
        for t in tris {
            let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
            s.push_str(&format!("  facet normal {} {} {}\n    outer loop\n", n.x, n.y, n.z));
            for v in t {
                s.push_str(&format!("      vertex {:e} {:e} {:e}\n", v.x, v.y, v.z));
            }
            s.push_str("    endloop\n  endfacet\n");
        }
        s.push_str(&format!("endsolid {name}\n"));
    }
    s
}

/// OBJ text: one `g` block per (group, polygons), every polygon with its own vertices (a
/// soup, as some exporters write it), each vertex moved by `jitter` × its index (a soup whose
/// copies differ in the last digits).
pub fn obj(groups: &[(&str, Vec<Vec<DVec3>>)], jitter: f64) -> String {
    let mut s = String::from("# written by the tests\n");
    let mut next = 1;
    for (name, polys) in groups {
        if !name.is_empty() {
            s.push_str(&format!("g {name}\n"));
        }
        for p in polys {
            let mut ix = Vec::new();
            for v in p {
                let w = *v + DVec3::splat(jitter * next as f64);
                s.push_str(&format!("v {:.17e} {:.17e} {:.17e}\n", w.x, w.y, w.z));
                ix.push(next.to_string());
                next += 1;
            }
            s.push_str(&format!("f {}\n", ix.join(" ")));
        }
    }
    s
}

/// The faces of the cube as quads (outward or inward), for [`obj`].
pub fn cube_quads(o: DVec3, s: f64, inward: bool) -> Vec<Vec<DVec3>> {
    cube_faces(o, s)
        .into_iter()
        .map(|[a, b]| {
            let q = vec![a[0], a[1], a[2], b[2]];
            if inward {
                q.into_iter().rev().collect()
            } else {
                q
            }
        })
        .collect()
}
