//! Test meshes: a planar profile extruded into a closed triangle mesh.
use crate::geometry::convex::ear_indices;
use crate::geometry::Polygon;
use glam::{DVec2, DVec3};

/// The counter-clockwise `profile` swept from w = 0 to w = 1 as a closed triangle mesh: two
/// triangles per side, the end caps by ear clipping; `at(q, w)` places a profile point. The
/// normals face out when `at` keeps the profile's turn (as x, −y, z from u, w, v does).
pub(crate) fn extrude(profile: &[[f64; 2]], at: impl Fn(DVec2, f64) -> DVec3) -> Vec<Polygon> {
    let p: Vec<DVec2> = profile.iter().map(|&[u, v]| DVec2::new(u, v)).collect();
    let tri = |a, b, c| Polygon::new(vec![a, b, c]).unwrap();
    let m = p.len();
    let mut out = Vec::new();
    for k in 0..m {
        let (a, b) = (p[k], p[(k + 1) % m]);
        out.push(tri(at(a, 0.0), at(b, 0.0), at(b, 1.0)));
        out.push(tri(at(a, 0.0), at(b, 1.0), at(a, 1.0)));
    }
    for [i, j, k] in ear_indices(&p) {
        out.push(tri(at(p[i], 1.0), at(p[j], 1.0), at(p[k], 1.0)));
        out.push(tri(at(p[k], 0.0), at(p[j], 0.0), at(p[i], 0.0)));
    }
    out
}
