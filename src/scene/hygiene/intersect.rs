//! Self-intersections: triangle pairs of one mesh that cross each other.
//!
//! Candidates come from an obvhs `Bvh2` over the triangles' boxes (padded by the contact
//! tolerance, so flat axis-aligned boxes do not degrade the tree, research/crates.md §1.3);
//! each triangle queries its box and tests the later triangles found. Pairs that share a
//! vertex are left out (neighbours meet along their shared edge or corner by construction).
//!
//! The pair test (Möller 1997, in f64) counts only proper crossings: each triangle has
//! corners strictly on both sides of the other's plane (beyond the contact tolerance) and the
//! two segments cut on the planes' common line overlap by more than the tolerance; coplanar
//! pairs facing the same way count when their interiors overlap (an edge crosses an edge, or
//! a corner lies inside the other). Touching within the tolerance, and coplanar faces turned
//! against each other (two bodies face to face), are contact, not intersection.
use super::{Finding, TriMesh};
use glam::{DVec2, DVec3, Vec3A};
use obvhs::{aabb::Aabb, bvh2::Bvh2, Boundable, BvhBuildParams};

/// Cosine above which two triangles' planes count as one plane for the pair test.
const COPLANAR_COS: f64 = 1.0 - 1e-12;

struct BoxPrim(Aabb);
impl Boundable for BoxPrim {
    fn aabb(&self) -> Aabb {
        self.0
    }
}

/// Crossing pairs of `mesh`; `tol` (m) is the contact tolerance (the weld tolerance).
pub fn self_intersections(mesh: &TriMesh, tol: f64) -> Finding {
    let mut out = Finding::default();
    let n = mesh.triangles.len();
    if n < 2 {
        return out;
    }
    let diag = bounds_diag(mesh);
    let pad = (tol.max(1e-6 * diag)) as f32;
    let boxes: Vec<Aabb> = (0..n)
        .map(|t| {
            let [a, b, c] = mesh.corners(t);
            let (lo, hi) = (a.min(b).min(c).as_vec3a(), a.max(b).max(c).as_vec3a());
            Aabb::new(lo - Vec3A::splat(pad), hi + Vec3A::splat(pad))
        })
        .collect();
    let prims: Vec<BoxPrim> = boxes.iter().map(|b| BoxPrim(*b)).collect();
    let bvh: Bvh2 =
        obvhs::bvh2::builder::build_bvh2(&prims, BvhBuildParams::fast_build(), &mut Default::default());
    let tol = tol.max(1e-12 * diag);
    for (i, bx) in boxes.iter().enumerate() {
        let ti = mesh.triangles[i];
        bvh.aabb_traverse(*bx, |bvh, node| {
            let node = &bvh.nodes[node as usize];
            for slot in node.first_index..node.first_index + node.prim_count {
                let j = bvh.primitive_indices[slot as usize] as usize;
                if j <= i || mesh.triangles[j].iter().any(|v| ti.contains(v)) {
                    continue;
                }
                if let Some(len) = crossing(mesh.corners(i), mesh.corners(j), tol) {
                    out.add(mesh.tags[i], len, Some(mesh.tags[j]));
                }
            }
            true
        });
    }
    out
}

fn bounds_diag(mesh: &TriMesh) -> f64 {
    let lo = mesh.vertices.iter().fold(DVec3::INFINITY, |a, &b| a.min(b));
    let hi = mesh.vertices.iter().fold(DVec3::NEG_INFINITY, |a, &b| a.max(b));
    (hi - lo).length()
}

/// The length of the segment along which triangles `p` and `q` cross (0 for a coplanar
/// overlap), or `None` when they only touch or are apart.
pub fn crossing(p: [DVec3; 3], q: [DVec3; 3], tol: f64) -> Option<f64> {
    let (np, nq) = (unit_normal(p)?, unit_normal(q)?);
    let dq = q.map(|v| (v - p[0]).dot(np)); // q's corners against p's plane
    let dp = p.map(|v| (v - q[0]).dot(nq));
    if np.dot(nq).abs() > COPLANAR_COS && dq.iter().all(|d| d.abs() <= tol) {
        // Facing each other: two bodies in contact (or a two-sided sheet), not an overlap.
        return (np.dot(nq) > 0.0 && coplanar_overlap(p, q, np, tol)).then_some(0.0);
    }
    let straddles = |d: &[f64; 3]| d.iter().any(|&x| x > tol) && d.iter().any(|&x| x < -tol);
    if !straddles(&dq) || !straddles(&dp) {
        return None;
    }
    let dir = np.cross(nq).normalize();
    let (a0, a1) = cut(p, dp, dir)?;
    let (b0, b1) = cut(q, dq, dir)?;
    let overlap = a1.min(b1) - a0.max(b0);
    (overlap > tol).then_some(overlap)
}

fn unit_normal(t: [DVec3; 3]) -> Option<DVec3> {
    let n = (t[1] - t[0]).cross(t[2] - t[0]);
    let len = n.length();
    (len > 0.0).then(|| n / len)
}

/// The interval (along `dir`) where triangle `t`, with signed plane distances `d`, meets the
/// other plane.
fn cut(t: [DVec3; 3], d: [f64; 3], dir: DVec3) -> Option<(f64, f64)> {
    let mut pts = Vec::with_capacity(3);
    for k in 0..3 {
        let (a, b) = (k, (k + 1) % 3);
        if d[a] == 0.0 {
            pts.push(t[a].dot(dir));
        }
        if (d[a] > 0.0 && d[b] < 0.0) || (d[a] < 0.0 && d[b] > 0.0) {
            let s = d[a] / (d[a] - d[b]);
            pts.push((t[a] + (t[b] - t[a]) * s).dot(dir));
        }
    }
    let lo = pts.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = pts.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    (lo <= hi).then_some((lo, hi))
}

/// Coplanar triangles whose interiors overlap by more than `tol`.
fn coplanar_overlap(p: [DVec3; 3], q: [DVec3; 3], n: DVec3, tol: f64) -> bool {
    let u = (p[1] - p[0]).normalize();
    let v = n.cross(u);
    let flat = |t: [DVec3; 3]| t.map(|x| DVec2::new((x - p[0]).dot(u), (x - p[0]).dot(v)));
    let (a, b) = (ccw(flat(p)), ccw(flat(q)));
    let crosses =
        (0..3).any(|i| (0..3).any(|j| proper_cross(a[i], a[(i + 1) % 3], b[j], b[(j + 1) % 3], tol)));
    crosses || a.iter().any(|&x| strictly_inside(x, b, tol)) || b.iter().any(|&x| strictly_inside(x, a, tol))
}

fn ccw(t: [DVec2; 3]) -> [DVec2; 3] {
    if (t[1] - t[0]).perp_dot(t[2] - t[0]) < 0.0 {
        [t[0], t[2], t[1]]
    } else {
        t
    }
}

/// Signed distance of `x` from the line a → b (positive on its left).
fn side(a: DVec2, b: DVec2, x: DVec2) -> f64 {
    (b - a).perp_dot(x - a) / (b - a).length()
}

fn proper_cross(a: DVec2, b: DVec2, c: DVec2, d: DVec2, tol: f64) -> bool {
    let (s1, s2) = (side(a, b, c), side(a, b, d));
    let (s3, s4) = (side(c, d, a), side(c, d, b));
    ((s1 > tol && s2 < -tol) || (s1 < -tol && s2 > tol))
        && ((s3 > tol && s4 < -tol) || (s3 < -tol && s4 > tol))
}

fn strictly_inside(x: DVec2, t: [DVec2; 3], tol: f64) -> bool {
    (0..3).all(|k| side(t[k], t[(k + 1) % 3], x) > tol)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> [DVec3; 3] {
        [DVec3::from(a), DVec3::from(b), DVec3::from(c)]
    }

    #[test]
    fn crossing_touching_and_coplanar_pairs() {
        let flat = tri([0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]);
        // A vertical triangle through the flat one: the cut runs from x = 0.25 to 0.75 at y = 0.5.
        let through = tri([0.25, 0.5, -1.0], [0.75, 0.5, -1.0], [0.5, 0.5, 1.0]);
        let len = crossing(flat, through, 1e-9).expect("crosses");
        assert!((len - 0.25).abs() < 1e-12, "{len}");
        // Resting on the plane (a corner on it) only touches.
        let resting = tri([0.25, 0.5, 0.0], [0.75, 0.5, 1.0], [0.5, 0.6, 1.0]);
        assert_eq!(crossing(flat, resting, 1e-9), None);
        // Beside the triangle: both planes are crossed but the cuts do not overlap.
        let beside = tri([3.0, 0.5, -1.0], [3.5, 0.5, -1.0], [3.2, 0.5, 1.0]);
        assert_eq!(crossing(flat, beside, 1e-9), None);
        // Coplanar: overlapping interiors count, a shared-edge neighbour does not.
        let overlap = tri([0.5, 0.5, 0.0], [3.0, 0.5, 0.0], [0.5, 3.0, 0.0]);
        assert_eq!(crossing(flat, overlap, 1e-9), Some(0.0));
        let facing = tri([0.5, 0.5, 0.0], [0.5, 3.0, 0.0], [3.0, 0.5, 0.0]);
        assert_eq!(crossing(flat, facing, 1e-9), None);
        let neighbour = tri([2.0, 0.0, 0.0], [2.0, 2.0, 0.0], [0.0, 2.0, 0.0]);
        assert_eq!(crossing(flat, neighbour, 1e-9), None);
    }
}
