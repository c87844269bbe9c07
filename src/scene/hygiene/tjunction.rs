//! T-junctions: faces triangulated apart (an irregularly meshed box, CAD faces meshed one by
//! one) meet along edges whose vertices differ, so each edge is "used by one triangle" though
//! no radiation can pass. A boundary edge whose whole length is covered, within the contact
//! tolerance, by collinear boundary edges of other triangles is such a seam, not an opening.
//! Each overlapping pair becomes a link between the two triangles (with whether they run the
//! seam the same way), so components and winding follow the seam as they follow shared edges.
use super::TriMesh;
use crate::scene::mesh::Edge;
use glam::{DVec3, Vec3A};
use obvhs::{aabb::Aabb, bvh2::Bvh2, Boundable, BvhBuildParams};

/// A link across a seam: two triangles and whether they run it the same way (disagree).
pub type Link = (u32, u32, bool);

struct BoxPrim(Aabb);
impl Boundable for BoxPrim {
    fn aabb(&self) -> Aabb {
        self.0
    }
}

/// Which boundary edges (indices into `edges`) are covered seams, and the seam links.
pub fn seams(mesh: &TriMesh, edges: &[Edge], tol: f64) -> (Vec<bool>, Vec<Link>) {
    let boundary: Vec<usize> = (0..edges.len()).filter(|&k| edges[k].is_boundary()).collect();
    let mut covered = vec![false; edges.len()];
    let mut links = Vec::new();
    if boundary.len() < 2 {
        return (covered, links);
    }
    // Endpoints in the direction the edge's triangle runs it.
    let ends = |k: usize| {
        let e = &edges[k];
        let (a, b) = (mesh.vertices[e.a as usize], mesh.vertices[e.b as usize]);
        if e.uses[0].1 {
            (a, b)
        } else {
            (b, a)
        }
    };
    let pad = tol as f32 + f32::EPSILON;
    let boxes: Vec<Aabb> = boundary
        .iter()
        .map(|&k| {
            let (a, b) = ends(k);
            Aabb::new(a.min(b).as_vec3a() - Vec3A::splat(pad), a.max(b).as_vec3a() + Vec3A::splat(pad))
        })
        .collect();
    let prims: Vec<BoxPrim> = boxes.iter().map(|b| BoxPrim(*b)).collect();
    let bvh: Bvh2 =
        obvhs::bvh2::builder::build_bvh2(&prims, BvhBuildParams::fast_build(), &mut Default::default());
    let mut spans: Vec<(f64, f64)> = Vec::new();
    for (slot, &k) in boundary.iter().enumerate() {
        let (a, b) = ends(k);
        let len = a.distance(b);
        if len <= tol {
            continue;
        }
        let dir = (b - a) / len;
        let tri = edges[k].uses[0].0;
        spans.clear();
        bvh.aabb_traverse(boxes[slot], |bvh, node| {
            let node = &bvh.nodes[node as usize];
            for s in node.first_index..node.first_index + node.prim_count {
                let other = boundary[bvh.primitive_indices[s as usize] as usize];
                let t2 = edges[other].uses[0].0;
                if other == k || t2 == tri {
                    continue;
                }
                let (c, d) = ends(other);
                if off_line(c, a, dir) > tol || off_line(d, a, dir) > tol {
                    continue;
                }
                let (s0, s1) = ((c - a).dot(dir), (d - a).dot(dir));
                let (lo, hi) = (s0.min(s1).max(0.0), s0.max(s1).min(len));
                if hi - lo > tol {
                    spans.push((lo, hi));
                    if tri < t2 {
                        links.push((tri, t2, (d - c).dot(dir) > 0.0));
                    }
                }
            }
            true
        });
        spans.sort_by(|x, y| x.0.total_cmp(&y.0));
        let mut reach = 0.0;
        for &(lo, hi) in &spans {
            if lo > reach + tol {
                break;
            }
            reach = f64::max(reach, hi);
        }
        covered[k] = reach >= len - tol;
    }
    links.sort_unstable_by_key(|l| (l.0, l.1));
    links.dedup_by_key(|l| (l.0, l.1));
    (covered, links)
}

/// Distance of `p` from the line through `a` along unit `dir`.
fn off_line(p: DVec3, a: DVec3, dir: DVec3) -> f64 {
    let v = p - a;
    (v - dir * v.dot(dir)).length()
}
