//! Pairs whose every partial blocker is a face of one convex solid (a closed, convex mesh with
//! outward normals: a facetted sphere, a block): the blocked exchange as a sum over the faces.
//!
//! Every sight line from the emitter E to the receiver R that the solid blocks enters it
//! through exactly one face f turned towards its start point p. With E_f = E ∩ front(R) ∩
//! front(f) (the points that can enter through f) and K the exchange kernel,
//!
//! S_f = ∫_{E_f} ∫_f K(p, x) [the ray p → x goes on to R] dA_x dA_p,   A·F = u − Σ_f S_f,
//!
//! since each blocked sight line is counted once, at its entry point, and K(p, y) dA_y =
//! K(p, x) dA_x along a ray (the same solid angle). Per face:
//! - **exact**: when every ray from E_f through f lands on R (checked on the |E_f|·|f| vertex
//!   rays; R convex, so their hull bounds all of them), S_f = A·F(E_f → f), the contour
//!   integral;
//! - **integrated**: else, K being symmetric, S_f = ∫_f F(dA_x → E_f ∩ π_x(R)) dA_x, π_x the
//!   central projection through x onto E's plane (R lies beyond x). The face is small, and it
//!   is first cut along the planes where the polygon E_f ∩ π_x(R) changes its vertices (x in
//!   the plane of an R vertex and an E_f edge, or of an R edge and an E_f vertex), so the
//!   integrand is smooth on every piece and a piece on which it is 0 at one point is 0
//!   throughout: no contribution can hide between the rule points.
//!
//! A facetted curved body seen whole makes g, the shaded integrand of
//! [`super::viewpoint`], kink wherever a face plane crosses the emitter (its silhouette
//! changes): hundreds of kinks over one emitter for a 1,280-facet sphere, each needing its own
//! cells. Here each face carries only its own few events.
use super::adaptive::{cut_along, emitter_cells, segment_meets_ring, Integrator};
use super::viewpoint::lambert;
use crate::geometry::clip::clip_homogeneous;
use crate::geometry::convex::{clip_convex, convex_contains, convex_hull, is_convex, twice_area, HalfPlane};
use crate::geometry::frame::Frame;
use crate::geometry::planes::{plane_of, Plane};
use crate::viewfactor::exact::pair::ring_ring;
use glam::{DVec2, DVec3};

/// Most pieces one face is cut into along its events (beyond, the adaptivity takes the rest).
const MAX_FACE_PIECES: usize = 256;

/// What the facet sum did for one pair.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SolidInfo {
    /// Σ_f S_f: the blocked exchange area, m².
    pub blocked: f64,
    /// Error estimate of `blocked` (the integrated faces' estimates and the exact faces'
    /// round-off bounds), m².
    pub error: f64,
    /// Faces summed exactly by the contour integral.
    pub exact: u32,
    /// Faces integrated.
    pub integrated: u32,
    /// Viewpoints evaluated on the integrated faces.
    pub evals: u64,
    /// Cells accepted.
    pub cells: u32,
    /// Cells accepted at the depth limit.
    pub at_max_depth: u32,
    /// Root cells (face pieces after the event cuts).
    pub roots: u32,
}

/// Reusable buffers.
#[derive(Debug, Clone, Default)]
pub struct SolidScratch {
    ring: Vec<DVec2>,
    tmp: Vec<DVec2>,
    hom: Vec<DVec3>,
    hom2: Vec<DVec3>,
    poly: Vec<DVec2>,
    rays: Vec<DVec2>,
    /// Per face to integrate: (face index, E_f in 2-D).
    todo: Vec<(usize, Vec<DVec2>)>,
}

/// The blocked exchange area Σ_f S_f between emitter ring `e` (normal `n_e`) and receiver ring
/// `r` (normal `n_r`) behind `faces`, the partial faces of one convex solid with outward normals
/// (clipped to the slab in front of both patches), to the absolute tolerance `tol` (m²).
/// `None` when E or R is not convex (the caller integrates the shadow instead).
pub fn blocked(
    (e, n_e): (&[DVec3], DVec3),
    (r, n_r): (&[DVec3], DVec3),
    faces: &[&[DVec3]],
    snap: f64,
    tol: f64,
    integrator: &Integrator,
    s: &mut SolidScratch,
) -> Option<SolidInfo> {
    let mut info = SolidInfo::default();
    // Emitter frame: E in z = 0 facing +z.
    let fe = Frame::new(e.iter().copied().sum::<DVec3>() / e.len() as f64, n_e);
    let e2: Vec<DVec2> = e.iter().map(|&x| fe.point(x).truncate()).collect();
    // Receiver frame, for the rays' landing points.
    let fr = Frame::new(r.iter().copied().sum::<DVec3>() / r.len() as f64, n_r);
    let r2: Vec<DVec2> = r.iter().map(|&x| fr.point(x).truncate()).collect();
    if !is_convex(&e2) || !is_convex(&r2) {
        return None;
    }
    let r_in_e: Vec<DVec3> = r.iter().map(|&x| fe.point(x)).collect();
    // E ∩ front(R).
    let mut e_front = e2.clone();
    if !clip_plane(&mut e_front, fe.vector(n_r), fe.point(r[0]), snap, &mut s.tmp) {
        return Some(info);
    }
    s.todo.clear();
    for (k, f) in faces.iter().enumerate() {
        let Some(pf) = plane_of(f) else { continue };
        // E_f = E ∩ front(R) ∩ front(f).
        s.ring.clone_from(&e_front);
        if !clip_plane(&mut s.ring, fe.vector(pf.n), fe.point(f[0]), snap, &mut s.tmp) {
            continue;
        }
        if twice_area(&s.ring) <= snap * snap {
            continue;
        }
        let e_f: Vec<DVec3> = s.ring.iter().map(|q| fe.point_to_world(q.extend(0.0))).collect();
        if lands_inside(&e_f, f, &fr, &r2, snap, &mut s.rays) {
            let x = ring_ring(&e_f, n_e, f, pf.n);
            info.blocked += x.value;
            info.error += x.round_off;
            info.exact += 1;
        } else {
            s.todo.push((k, s.ring.clone()));
        }
    }
    if s.todo.is_empty() {
        return Some(info);
    }
    let share = tol / s.todo.len() as f64;
    let todo = std::mem::take(&mut s.todo);
    for (k, e_f) in &todo {
        let f_loc: Vec<DVec3> = faces[*k].iter().map(|&x| fe.point(x)).collect();
        let Some(pf) = plane_of(&f_loc) else { continue };
        let e3: Vec<DVec3> = e_f.iter().map(|q| q.extend(0.0)).collect();
        let Some(support) = support(&f_loc, pf, &e3, &r_in_e, snap) else { continue };
        let edges: Vec<HalfPlane> =
            (0..e_f.len()).filter_map(|m| HalfPlane::left_of(e_f[m], e_f[(m + 1) % e_f.len()])).collect();
        let planes = events(&support, &e3, &r_in_e, snap);
        let mut roots = Vec::new();
        for piece in cut_along(&support, &planes, snap, MAX_FACE_PIECES) {
            roots.extend(emitter_cells(&piece, pf.n));
        }
        info.roots += roots.len() as u32;
        let (hom, hom2, poly) = (&mut s.hom, &mut s.hom2, &mut s.poly);
        let q = integrator.integrate_smooth(&roots, share, |x| {
            through_window(x, pf.n, &r_in_e, &edges, snap, (hom, hom2, poly))
        });
        info.blocked += q.value;
        info.error += q.error;
        info.evals += q.evals;
        info.cells += q.cells;
        info.at_max_depth += q.at_max_depth;
        info.integrated += 1;
    }
    s.todo = todo;
    Some(info)
}

/// Clips the 2-D ring (in a frame's z = 0) to the front of the plane through `point` with
/// normal `n` (frame coordinates); false when nothing is left.
fn clip_plane(ring: &mut Vec<DVec2>, n: DVec3, point: DVec3, snap: f64, tmp: &mut Vec<DVec2>) -> bool {
    match HalfPlane::from_normal(n.truncate(), -n.dot(point)) {
        Some(h) => {
            clip_convex(ring, h, snap, tmp);
            std::mem::swap(ring, tmp);
            ring.len() >= 3
        }
        // The plane is parallel to z = 0: all in front or all behind.
        None => -n.dot(point) > snap,
    }
}

/// True when every ray from a vertex of `e_f` through a vertex of `f` (world) reaches the
/// receiver's plane beyond the face and lands inside R (`r2`, frame `fr`) by `snap`.
fn lands_inside(
    e_f: &[DVec3],
    f: &[DVec3],
    fr: &Frame,
    r2: &[DVec2],
    snap: f64,
    rays: &mut Vec<DVec2>,
) -> bool {
    rays.clear();
    for &p in e_f {
        let p = fr.point(p);
        for &v in f {
            let v = fr.point(v);
            if !(p.z - v.z > snap) {
                return false;
            }
            rays.push((p + (v - p) * (p.z / (p.z - v.z))).truncate());
        }
    }
    convex_contains(r2, rays, snap)
}

/// The part of face `f` (plane `pf`) that lies on some segment from E_f to R, the only part
/// where the integrand is not 0: f ∩ conv(E_f ∪ R), that hull cut by f's plane. `None` when
/// empty.
fn support(f: &[DVec3], pf: Plane, e: &[DVec3], r: &[DVec3], snap: f64) -> Option<Vec<DVec3>> {
    let (a1, _) = pf.n.any_orthonormal_pair();
    let a2 = pf.n.cross(a1);
    let flat = |x: DVec3| DVec2::new(x.dot(a1), x.dot(a2));
    let pts: Vec<DVec3> = e.iter().chain(r).copied().collect();
    let mut cut: Vec<DVec2> = Vec::new();
    for (k, &a) in pts.iter().enumerate() {
        let da = pf.distance(a);
        if da.abs() <= snap {
            cut.push(flat(a));
        }
        for &b in &pts[k + 1..] {
            let db = pf.distance(b);
            if (da > snap && db < -snap) || (da < -snap && db > snap) {
                cut.push(flat(a + (b - a) * (da / (da - db))));
            }
        }
    }
    let mut hull = Vec::new();
    convex_hull(&mut cut, &mut hull);
    if hull.len() < 3 {
        return None;
    }
    let mut ring: Vec<DVec2> = f.iter().map(|&x| flat(x)).collect();
    if twice_area(&ring) < 0.0 {
        ring.reverse();
    }
    let mut tmp = Vec::new();
    for m in 0..hull.len() {
        let Some(h) = HalfPlane::left_of(hull[m], hull[(m + 1) % hull.len()]) else { continue };
        clip_convex(&ring, h, snap, &mut tmp);
        std::mem::swap(&mut ring, &mut tmp);
        if ring.len() < 3 {
            return None;
        }
    }
    if !(twice_area(&ring) > snap * snap) {
        return None;
    }
    // Back to 3-D on f's plane, in f's orientation.
    let mut out: Vec<DVec3> = ring.iter().map(|q| q.x * a1 + q.y * a2 - pf.d * pf.n).collect();
    if plane_of(&out).is_some_and(|p| p.n.dot(pf.n) < 0.0) {
        out.reverse();
    }
    Some(out)
}

/// Planes (emitter frame) where E_f ∩ π_x(R) changes its vertices as x crosses the support
/// `face`: an R vertex v and an E_f edge [a, b] (π_x(v) crosses the edge: x in the triangle
/// v, a, b), an R edge [p, q] and an E_f vertex a (x in the triangle a, p, q). Parallel edges
/// are included (that plane holds both). Only planes whose triangle meets the face count.
fn events(face: &[DVec3], e: &[DVec3], r: &[DVec3], snap: f64) -> Vec<Plane> {
    let mut planes = Vec::new();
    let mut push = |t: [DVec3; 3]| {
        let Some(p) = Plane::through(t[0], t[1], t[2], snap * (t[2] - t[1]).length()) else { return };
        // The chord of the face in the plane, against the triangle, in the plane's axes.
        let (a1, _) = p.n.any_orthonormal_pair();
        let a2 = p.n.cross(a1);
        let flat = |x: DVec3| DVec2::new(x.dot(a1), x.dot(a2));
        let m = face.len();
        let mut chord = [DVec2::ZERO; 2];
        let mut count = 0;
        for k in 0..m {
            let (x, y) = (face[k], face[(k + 1) % m]);
            let (dx, dy) = (p.distance(x), p.distance(y));
            if (dx > 0.0) != (dy > 0.0) && count < 2 {
                chord[count] = flat(x + (y - x) * (dx / (dx - dy)));
                count += 1;
            }
        }
        let mut tri = t.map(flat).to_vec();
        if twice_area(&tri) < 0.0 {
            tri.reverse();
        }
        if count == 2 && segment_meets_ring(chord[0], chord[1], &tri) {
            planes.push(p);
        }
    };
    let (me, mr) = (e.len(), r.len());
    for a in 0..me {
        for &v in r {
            push([v, e[a], e[(a + 1) % me]]);
        }
    }
    for b in 0..mr {
        for &a in e {
            push([a, r[b], r[(b + 1) % mr]]);
        }
    }
    planes
}

/// F(dA_x → E_f ∩ π_x(R)) for x in the emitter frame (x.z > 0) with normal `n`: R (frame
/// coordinates, beyond x) projected through x onto z = 0 in homogeneous coordinates
/// (X, Y, W) = (q_z·x_x − h·q_x, q_z·x_y − h·q_y, q_z − h), h = x_z, clipped to E_f's edges
/// before the division (E_f bounded, so what is left has W > 0: only R beyond x).
fn through_window(
    x: DVec3,
    n: DVec3,
    r: &[DVec3],
    edges: &[HalfPlane],
    snap: f64,
    (hom, hom2, poly): (&mut Vec<DVec3>, &mut Vec<DVec3>, &mut Vec<DVec2>),
) -> f64 {
    let h = x.z;
    if !(h > snap) {
        return 0.0;
    }
    hom.clear();
    hom.extend(r.iter().map(|q| DVec3::new(q.z * x.x - h * q.x, q.z * x.y - h * q.y, q.z - h)));
    for e in edges {
        clip_homogeneous(hom, DVec3::new(e.n.x, e.n.y, e.c), hom2);
        std::mem::swap(hom, hom2);
        if hom.len() < 3 {
            return 0.0;
        }
    }
    let w_min = 1e-12 * h;
    poly.clear();
    poly.extend(hom.iter().map(|v| {
        let w = v.z.max(w_min);
        DVec2::new(v.x / w, v.y / w)
    }));
    let a2 = twice_area(poly);
    if !(a2.abs() > snap * snap) {
        return 0.0;
    }
    if a2 < 0.0 {
        poly.reverse();
    }
    lambert(x, n, poly).max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::fixtures::square as sq;
    use crate::viewfactor::shadow::adaptive::{AdaptParams, AdaptScratch};
    use crate::viewfactor::shadow::viewpoint::ShadowGeometry;

    /// Both methods integrate to tolerances this small; they must agree within a few of them.
    const AGREE: f64 = 10.0;

    /// The 12 outward triangles of the box [lo, hi].
    fn cuboid(lo: DVec3, hi: DVec3) -> Vec<Vec<DVec3>> {
        let c = |i: usize| DVec3::new([lo.x, hi.x][i & 1], [lo.y, hi.y][i >> 1 & 1], [lo.z, hi.z][i >> 2]);
        let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        quads
            .iter()
            .flat_map(|q| [vec![c(q[0]), c(q[1]), c(q[2])], vec![c(q[0]), c(q[2]), c(q[3])]])
            .collect()
    }

    /// (facet sum, shadow integration) of emitter `e` and receiver `r` past `faces`, both to `tol`.
    fn both(e: &[DVec3], r: &[DVec3], faces: &[Vec<DVec3>], tol: f64) -> (SolidInfo, f64) {
        let refs: Vec<&[DVec3]> = faces.iter().map(|f| f.as_slice()).collect();
        let (ne, nr) = (plane_of(e).unwrap().n, plane_of(r).unwrap().n);
        let it = Integrator::new(AdaptParams { low: 4, high: 5, min_depth: 0, max_depth: 12 });
        let geo = ShadowGeometry::new(e, ne, r, nr, &refs).unwrap();
        let shadow = it.shaded(&geo, tol, &mut AdaptScratch::default()).shaded;
        let sum = blocked((e, ne), (r, nr), &refs, 1e-12, tol, &it, &mut SolidScratch::default()).unwrap();
        (sum, shadow)
    }

    #[test]
    fn the_facet_sum_matches_the_shadow_integration_past_a_block() {
        let d = DVec3::new;
        let (e, r) = (sq(0.0, 0.0, 0.0, 1.0, true), sq(1.0, 0.0, 0.0, 1.0, false));
        // A receiver at right angles (x = 1.2, facing −x) and a triangular emitter.
        let rp = vec![d(1.2, 0.0, 0.0), d(1.2, 0.0, 1.0), d(1.2, 1.0, 1.0), d(1.2, 1.0, 0.0)];
        let et = vec![d(0.0, 0.0, 0.0), d(1.0, 0.2, 0.0), d(0.3, 0.9, 0.0)];
        for (e, r, lo, hi) in [
            (&e, &r, d(0.3, 0.3, 0.4), d(0.7, 0.7, 0.6)),
            (&e, &r, d(0.6, 0.1, 0.3), d(1.3, 0.5, 0.45)),
            (&e, &rp, d(0.6, 0.1, 0.3), d(0.9, 0.5, 0.45)),
            (&et, &rp, d(0.6, 0.1, 0.3), d(0.9, 0.5, 0.45)),
        ] {
            let tol = 1e-13;
            let (sum, shadow) = both(e, r, &cuboid(lo, hi), tol);
            assert!(shadow > 1e-3, "the block shades {shadow}");
            assert!((sum.blocked - shadow).abs() <= AGREE * tol, "{sum:?} vs {shadow}");
            assert!(sum.integrated > 0 && sum.error <= tol, "{sum:?}");
        }
    }

    #[test]
    fn a_large_face_is_integrated_only_where_segments_cross_it() {
        // A floor and a wall triangle of box_500_block and two faces of its block: the face
        // x = 0.65 is 25 times the patches' size; only the beam between them is integrated.
        let d = DVec3::new;
        let e = vec![
            d(1.0, 0.299_040_883_779_525_76, 0.0),
            d(1.0, 0.460_379_600_524_902_34, 0.157_914_265_990_257_26),
            d(1.0, 0.421_249_479_055_404_66, 0.0),
        ];
        let r = vec![
            d(0.139_549_598_097_801_2, 1.133_693_695_068_359_4, 0.7),
            d(0.169_573_992_490_768_43, 1.3, 0.7),
            d(0.269_690_722_227_096_56, 1.3, 0.7),
        ];
        let faces = vec![
            vec![d(0.35, 0.85, 0.5), d(0.65, 0.85, 0.5), d(0.65, 0.85, 0.2)],
            vec![d(0.65, 0.45, 0.2), d(0.65, 0.85, 0.2), d(0.65, 0.85, 0.5)],
        ];
        let tol = 1e-18;
        let (sum, shadow) = both(&e, &r, &faces, tol);
        assert!((sum.blocked - shadow).abs() <= AGREE * tol, "{sum:?} vs {shadow}");
        // Only the face towards the emitter is an entry face.
        assert_eq!(sum.integrated, 1, "{sum:?}");
        assert!(sum.evals < 20_000, "{sum:?}");
    }

    #[test]
    fn faces_whose_rays_all_land_on_the_receiver_are_exact() {
        // A small cube just below the receiver's middle: every ray from the emitter through
        // it lands on the receiver, so each entry face is one contour integral.
        let d = DVec3::new;
        let (e, r) = (sq(0.0, 0.0, 0.0, 1.0, true), sq(1.0, 0.0, 0.0, 1.0, false));
        let faces = cuboid(d(0.45, 0.45, 0.9), d(0.55, 0.55, 0.95));
        let tol = 1e-14;
        let (sum, shadow) = both(&e, &r, &faces, tol);
        assert!(sum.exact >= 2 && sum.integrated == 0 && sum.evals == 0, "{sum:?}");
        assert!((sum.blocked - shadow).abs() <= AGREE * tol, "{sum:?} vs {shadow}");
    }

    #[test]
    fn a_non_convex_patch_is_left_to_the_shadow_integration() {
        let d = DVec3::new;
        let l_shape = vec![
            d(0.0, 0.0, 0.0),
            d(1.0, 0.0, 0.0),
            d(1.0, 0.5, 0.0),
            d(0.5, 0.5, 0.0),
            d(0.5, 1.0, 0.0),
            d(0.0, 1.0, 0.0),
        ];
        let r = sq(1.0, 0.0, 0.0, 1.0, false);
        let faces = cuboid(d(0.3, 0.3, 0.4), d(0.7, 0.7, 0.6));
        let refs: Vec<&[DVec3]> = faces.iter().map(|f| f.as_slice()).collect();
        let it = Integrator::new(AdaptParams { low: 4, high: 5, min_depth: 0, max_depth: 12 });
        let none = blocked(
            (&l_shape, DVec3::Z),
            (&r, -DVec3::Z),
            &refs,
            1e-12,
            1e-10,
            &it,
            &mut SolidScratch::default(),
        );
        assert!(none.is_none());
    }
}
