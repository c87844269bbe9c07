//! One partly obstructed pair end to end: choice of emitter and receiver, shadow geometry,
//! adaptive integration, and the obstructed exchange area
//! A_i F_ij = (A_i F_ij)_unobstructed − ∫_E g dA.
//!
//! **Which patch emits.** Only the emitter side is integrated numerically; the receiver side is
//! exact. The integrand g varies as shadows move across the receiver while the viewpoint moves
//! across the emitter: a blocker at height d_e above the emitter and d_r above the receiver
//! shifts its shadow by (d_r/d_e)·Δ for a viewpoint step Δ. Relative to the receiver's size
//! the shadow sweeps (L_e·d_r)/(d_e·L_r) over the whole emitter, so the emitter is the patch
//! with the smaller L/d (its size over its distance to the nearest blocker): the receiver is
//! the patch nearer to the blockers relative to its size. View3D picks the surface nearer to
//! the obstructions (research/view3d.md §2); this also weighs the sizes, so a large patch next
//! to a blocker is not chosen as emitter because a small one is slightly farther.
use super::adaptive::{AdaptInfo, AdaptScratch, Integrator};
use super::blockers::Blockers;
use super::classify::clip_front;
use super::solid::SolidScratch;
use super::viewpoint::{ShadowGeometry, VIEWPOINT_WORK};
use crate::geometry::Polygon;
use glam::DVec3;

/// Work units of one face of the facet sum besides its viewpoints (clips, a contour integral
/// or the event cuts), in viewpoint-projection units.
const SOLID_FACE_WORK: u64 = 16;

/// Result of one obstructed pair.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Shadowed {
    /// Obstructed exchange area A_i F_ij, m² (never above the unobstructed one).
    pub s: f64,
    /// Error estimate of `s`, m².
    pub error: f64,
    /// Integration statistics.
    pub info: AdaptInfo,
    /// True when patch j was the emitter.
    pub swapped: bool,
}

/// Reusable buffers.
#[derive(Debug, Clone, Default)]
pub struct PairScratch {
    /// Integrator buffers.
    pub adapt: AdaptScratch,
    rings: Vec<Vec<DVec3>>,
    /// Buffers of the facet sum.
    pub solid: SolidScratch,
    /// (blocker, ring index, ring unclipped) of the pair's kept blockers.
    kept: Vec<(u32, u32, bool)>,
}

/// Obstructed A_i F_ij for patches `pi`, `pj` with unobstructed exchange area `s_unobs` and the
/// partial blockers `partial` (ids into `blockers`), to the absolute tolerance `tol` (m²),
/// refining no further past `max_work` ([`Integrator::shaded_within`]; `u64::MAX` for entries).
#[allow(clippy::too_many_arguments)]
pub fn shadowed(
    pi: &Polygon,
    pj: &Polygon,
    s_unobs: f64,
    blockers: &Blockers,
    partial: &[u32],
    integrator: &Integrator,
    tol: f64,
    max_work: u64,
    s: &mut PairScratch,
) -> Shadowed {
    let snap = blockers.snap();
    // Blockers clipped to the region in front of both patches.
    s.rings.resize_with(partial.len(), Vec::new);
    let mut tmp = Vec::new();
    let mut n = 0;
    s.kept.clear();
    for &b in partial {
        let ring = &blockers.get(b as usize).ring;
        clip_front(ring, pi.normal(), pi.normal().dot(pi.centroid()), snap, &mut tmp);
        if tmp.len() < 3 {
            continue;
        }
        clip_front(&tmp, pj.normal(), pj.normal().dot(pj.centroid()), snap, &mut s.rings[n]);
        if s.rings[n].len() >= 3 {
            s.kept.push((b, n as u32, s.rings[n] == *ring));
            n += 1;
        }
    }
    if n == 0 {
        return Shadowed { s: s_unobs, ..Default::default() };
    }
    s.kept.sort_unstable_by_key(|k| k.0);
    let rings: Vec<&[DVec3]> = s.rings[..n].iter().map(|r| r.as_slice()).collect();
    let solid_faces = s.kept.iter().any(|k| {
        let b = blockers.get(k.0 as usize);
        b.closed == 1 && b.body.is_none()
    });
    // The row's classification kept only the faces of a non-convex solid that patch i can
    // cross first (`Blockers::turned_from`), and the shadows are taken from the emitter's
    // viewpoints with the faces turned towards them: patch i then emits, whatever the sizes.
    let swapped = !solid_faces && !emits_first(pi, pj, &rings);
    let (e, r) = if swapped { (pj, pi) } else { (pi, pj) };
    let closed: Vec<(i8, Option<u32>)> = s.kept.iter().fold(vec![(0, None); n], |mut c, &(b, k, _)| {
        let bl = blockers.get(b as usize);
        c[k as usize] = (bl.closed, bl.body);
        c
    });
    if let Some(min) = integrator.solid_min() {
        // One convex solid with outward normals, of at least `min` faces: the facet sum.
        let body = closed[0].1;
        let faces = s.kept.first().map_or(0, |k| blockers.get(k.0 as usize).body_faces as usize);
        if faces >= min && body.is_some() && closed.iter().all(|&c| c == (1, body)) {
            if let Some(q) = super::solid::blocked(
                (e.vertices(), e.normal()),
                (r.vertices(), r.normal()),
                &rings,
                snap,
                tol,
                integrator,
                &mut s.solid,
            ) {
                let info = AdaptInfo {
                    shaded: q.blocked,
                    error: q.error,
                    evals: q.evals,
                    work: q.evals * VIEWPOINT_WORK + u64::from(q.exact + q.integrated) * SOLID_FACE_WORK,
                    cells: q.cells,
                    at_max_depth: q.at_max_depth,
                    roots: q.roots,
                    stalled: false,
                    capped: false,
                };
                let value = (s_unobs - q.blocked).max(0.0);
                return Shadowed { s: value, error: q.error, info, swapped };
            }
        }
    }
    // Shared edges between kept, unclipped blockers, as ring indices (the shadow integration
    // only; `kept` is sorted by blocker above).
    let neighbours: Vec<Vec<Option<u32>>> = {
        let mut out = vec![Vec::new(); n];
        for &(b, k, whole) in &s.kept {
            if whole {
                out[k as usize] = blockers
                    .get(b as usize)
                    .across
                    .iter()
                    .map(|c| {
                        let c = (*c)?;
                        let at = s.kept.binary_search_by_key(&c, |k| k.0).ok()?;
                        s.kept[at].2.then_some(s.kept[at].1)
                    })
                    .collect();
            }
        }
        out
    };
    let Some(mut geo) = ShadowGeometry::new(e.vertices(), e.normal(), r.vertices(), r.normal(), &rings)
    else {
        return Shadowed { s: 0.0, swapped, ..Default::default() };
    };
    geo.set_neighbours(&neighbours, &closed);
    let info = integrator.shaded_within(&geo, tol, max_work, &mut s.adapt);
    // The shaded part lies in [0, u]: round-off in a nearly empty shadow (−8e-27 against a
    // u of 3e-38) must not lift the obstructed value above the unobstructed one.
    let value = (s_unobs - info.shaded).clamp(0.0, s_unobs.max(0.0));
    Shadowed { s: value, error: info.error, info, swapped }
}

/// True when `a` should be the emitter: its size over its distance to the nearest blocker
/// point is the smaller (see the module notes).
fn emits_first(a: &Polygon, b: &Polygon, blockers: &[&[DVec3]]) -> bool {
    let dist = |p: &Polygon| {
        blockers
            .iter()
            .flat_map(|r| r.iter())
            .map(|&v| p.plane_distance(v))
            .fold(f64::INFINITY, f64::min)
            .max(0.0)
    };
    let (da, db) = (dist(a), dist(b));
    // L_a/d_a ≤ L_b/d_b, written without divisions (either distance may be 0).
    a.bounding_radius() * db <= b.bounding_radius() * da
}
