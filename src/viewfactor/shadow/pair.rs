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
//!
//! **Behind a non-convex solid** the row's classification kept only the solid's faces that
//! patch i can cross first (`Blockers::turned_from`), so with that list patch i emits. A patch
//! j far smaller than i ([`OWN_FACES_RATIO`]; a part's triangle against a wall patch, i not on
//! the solid) emits instead with its own list ([`faces_for_emitter`]: the faces it can cross
//! first, within the pair's shaft): every viewpoint's front faces then close into the solid's
//! outline, united by one boolean ([`OWN_FACES_UNION_MIN`]), and the small emitter is cut
//! along its receiver-edge kink planes only ([`OWN_FACES_CUTS`]).
use super::adaptive::{AdaptInfo, AdaptScratch, Cuts, Integrator};
use super::blockers::Blockers;
use super::classify::clip_front;
use super::solid::SolidScratch;
use super::viewpoint::{ShadowGeometry, VIEWPOINT_WORK};
use crate::geometry::planes::Plane;
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
    /// The blockers of patch j as emitter ([`faces_for_emitter`]).
    ids: Vec<u32>,
    /// Candidates of the blocker hierarchy's query.
    candidates: Vec<u32>,
    /// A ring clipped to patch i's front.
    tmp: Vec<DVec3>,
}

/// Obstructed A_i F_ij for patches `pi`, `pj` with unobstructed exchange area `s_unobs` and the
/// partial blockers `partial` (ids into `blockers`), to the absolute tolerance `tol` (m²),
/// refining no further past `max_work` ([`Integrator::shaded_within`]; `u64::MAX` for entries).
/// `i_on_solid`: patch i is itself a face of a non-convex solid (then it emits with the row's
/// faces, whatever the sizes).
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
    i_on_solid: bool,
    s: &mut PairScratch,
) -> Shadowed {
    let own = !i_on_solid && j_emits_with_own_faces(pi, pj);
    shadowed_with(pi, pj, s_unobs, (blockers, partial), integrator, (tol, max_work), own, s)
}

/// [`shadowed`], patch j emitting with its own faces (`own`) where the pair lies behind a
/// non-convex solid, or patch i with the row's faces.
#[allow(clippy::too_many_arguments)]
fn shadowed_with(
    pi: &Polygon,
    pj: &Polygon,
    s_unobs: f64,
    (blockers, partial): (&Blockers, &[u32]),
    integrator: &Integrator,
    (tol, max_work): (f64, u64),
    own: bool,
    s: &mut PairScratch,
) -> Shadowed {
    let Kept { n, solid_faces, j_emits } = match keep(pi, pj, (blockers, partial), own, s) {
        Ok(kept) => kept,
        Err(swapped) => return Shadowed { s: s_unobs, swapped, ..Default::default() },
    };
    let snap = blockers.snap();
    let rings: Vec<&[DVec3]> = s.rings[..n].iter().map(|r| r.as_slice()).collect();
    let swapped = j_emits || (!solid_faces && !emits_first(pi, pj, &rings));
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
    if j_emits {
        geo.set_union_min(OWN_FACES_UNION_MIN);
    }
    let info = if j_emits {
        integrator.clone().with_cuts(OWN_FACES_CUTS).shaded_within(&geo, tol, max_work, &mut s.adapt)
    } else {
        integrator.shaded_within(&geo, tol, max_work, &mut s.adapt)
    };
    // The shaded part lies in [0, u]: round-off in a nearly empty shadow (−8e-27 against a
    // u of 3e-38) must not lift the obstructed value above the unobstructed one.
    let value = (s_unobs - info.shaded).clamp(0.0, s_unobs.max(0.0));
    Shadowed { s: value, error: info.error, info, swapped }
}

/// The blockers a pair's integration keeps ([`keep`]).
struct Kept {
    /// How many (their rings are `PairScratch::rings[..n]`, their ids in `kept`).
    n: usize,
    /// One of them is a face of a non-convex solid.
    solid_faces: bool,
    /// Patch j emits with its own faces.
    j_emits: bool,
}

/// The blockers of `partial` clipped to the region in front of both patches, into `s.rings`
/// and `s.kept` (sorted by blocker); where they include a non-convex solid's faces and `own`
/// is set, patch j's own list instead ([`faces_for_emitter`]). `Err(swapped)` when none is
/// left (the pair is unobstructed; `swapped` when patch j's own list was the one tried).
fn keep(
    pi: &Polygon,
    pj: &Polygon,
    (blockers, partial): (&Blockers, &[u32]),
    own: bool,
    s: &mut PairScratch,
) -> Result<Kept, bool> {
    let mut n = clip_both(pi, pj, blockers, partial.iter().copied(), s);
    if n == 0 {
        return Err(false);
    }
    let solid_faces = s.kept.iter().any(|k| {
        let b = blockers.get(k.0 as usize);
        b.closed == 1 && b.body.is_none()
    });
    // The row's classification kept only the faces of a non-convex solid that patch i can
    // cross first (`Blockers::turned_from`), and the shadows are taken from the emitter's
    // viewpoints with the faces turned towards them: with that list patch i emits. Patch j
    // emits with its own list instead (the faces j can cross first, [`faces_for_emitter`])
    // where it is the far smaller patch.
    let j_emits = solid_faces && own;
    if j_emits {
        let mut ids = std::mem::take(&mut s.ids);
        faces_for_emitter(pj, pi, blockers, partial, &mut ids, &mut s.candidates);
        n = clip_both(pi, pj, blockers, ids.iter().copied(), s);
        s.ids = ids;
        if n == 0 {
            return Err(true);
        }
    }
    Ok(Kept { n, solid_faces, j_emits })
}

/// Clips blockers `ids` to the region in front of both patches into `s.rings`, recording
/// (blocker, ring, unclipped) in `s.kept`, sorted by blocker; returns how many are kept.
fn clip_both(
    pi: &Polygon,
    pj: &Polygon,
    blockers: &Blockers,
    ids: impl Iterator<Item = u32>,
    s: &mut PairScratch,
) -> usize {
    let snap = blockers.snap();
    let mut tmp = std::mem::take(&mut s.tmp);
    let mut n = 0;
    s.kept.clear();
    for b in ids {
        let ring = &blockers.get(b as usize).ring;
        clip_front(ring, pi.normal(), pi.normal().dot(pi.centroid()), snap, &mut tmp);
        if tmp.len() < 3 {
            continue;
        }
        if s.rings.len() <= n {
            s.rings.push(Vec::new());
        }
        clip_front(&tmp, pj.normal(), pj.normal().dot(pj.centroid()), snap, &mut s.rings[n]);
        if s.rings[n].len() >= 3 {
            s.kept.push((b, n as u32, s.rings[n] == *ring));
            n += 1;
        }
    }
    s.tmp = tmp;
    s.kept.sort_unstable_by_key(|k| k.0);
    n
}

/// True when every blocker of `partial` falls away once clipped to the pair (in front of
/// both patches, and for a small patch j behind a non-convex solid its own faces): the pair
/// is unobstructed, and [`shadowed`] returns its unobstructed value without a viewpoint.
pub fn falls_away(
    pi: &Polygon,
    pj: &Polygon,
    blockers: &Blockers,
    partial: &[u32],
    i_on_solid: bool,
    s: &mut PairScratch,
) -> bool {
    let own = !i_on_solid && j_emits_with_own_faces(pi, pj);
    keep(pi, pj, (blockers, partial), own, s).is_err()
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

/// Patch j emits with its own face list when it is this many times smaller than patch i
/// (bounding radii): a part's triangle against a wall patch. On the channel's wall rows the
/// triangle then needs 3–8× fewer viewpoints than the wall (validation/cad.md).
pub const OWN_FACES_RATIO: f64 = 8.0;

/// Kink cuts of a small patch emitting with its own faces: along the receiver-edge planes
/// only, up to 32 pieces. The hundreds of faces near a part's triangle put a face plane and
/// event planes across it per face, weak kinks that tripled the viewpoints when cut; a
/// blocker edge parallel to a receiver edge kinks g along a whole line, with a strength that
/// scales with that edge and not with the emitter. Left uncut, a heat-sink fin (a fin
/// triangle emitting to a wall past the fins beside it) ended 2.5× past its goal while its
/// error estimate read 0.98 of it; cut, every entry of that heat sink in three rooms is
/// within 0.41 of its goal, at the channel's and the fingers' former cost (validation/cad.md).
pub const OWN_FACES_CUTS: Cuts = Cuts::receiver_edges(32);

/// Active blockers above which a small patch emitting with its own faces unites their
/// shadows by one boolean: its face list is the solid's whole front within the shaft, so
/// the outline closes and the boolean sees the silhouette only (the channel's wall pairs:
/// 1.5× faster than subtracting up to 64 faces one by one).
pub const OWN_FACES_UNION_MIN: usize = 8;

/// True when patch j, not i, should emit for a pair behind a non-convex solid: j is far
/// smaller than i ([`OWN_FACES_RATIO`]). Only for an i that is not on the solid itself (a
/// wall patch): between two faces of the channel the row's faces were measured cheaper.
fn j_emits_with_own_faces(pi: &Polygon, pj: &Polygon) -> bool {
    pj.bounding_radius() * OWN_FACES_RATIO <= pi.bounding_radius()
}

/// The blockers patch `e` needs as emitter towards patch `r`, into `out` (sorted), from the
/// partial blockers of row r (`partial`, classified from r, which left out the faces of a
/// non-convex solid turned away from r):
/// - the row's partial blockers, less the solid faces turned away from e (never crossed
///   first from e);
/// - the solid faces turned away from r and not from e (every segment from e that enters the
///   solid enters through a face turned towards e, which may be one r never sees), found in
///   the blocker hierarchy and kept when they reach into the shaft conv(e ∪ r) and in front
///   of both patches.
///
/// The row's classification has already cleared every other face with a point in front of r:
/// a face that no segment between the two patches crosses stays out.
pub fn faces_for_emitter(
    e: &Polygon,
    r: &Polygon,
    blockers: &Blockers,
    partial: &[u32],
    out: &mut Vec<u32>,
    candidates: &mut Vec<u32>,
) {
    let snap = blockers.snap();
    out.clear();
    out.extend(partial.iter().copied().filter(|&b| !blockers.turned_from(b as usize, e.vertices())));
    let shaft = hull_planes(e.vertices(), r.vertices(), snap);
    let front = |p: &Polygon| Plane { n: p.normal(), d: -p.normal().dot(p.centroid()) };
    let (pe, pr) = (front(e), front(r));
    let (lo, hi) = e
        .vertices()
        .iter()
        .chain(r.vertices())
        .fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(l, h), &v| {
            (l.min(v), h.max(v))
        });
    candidates.clear();
    blockers.blockers_where(
        |blo, bhi| {
            blo.cmple(hi).all()
                && bhi.cmpge(lo).all()
                && pe.box_max(blo, bhi) > snap
                && pr.box_max(blo, bhi) > snap
                && shaft.iter().all(|p| p.box_min(blo, bhi) <= snap)
        },
        candidates,
    );
    for &b in candidates.iter() {
        let ring = &blockers.get(b as usize).ring;
        if blockers.turned_from(b as usize, r.vertices())
            && !blockers.turned_from(b as usize, e.vertices())
            && !shaft.iter().any(|p| ring.iter().all(|&x| p.distance(x) > snap))
        {
            out.push(b);
        }
    }
    out.sort_unstable();
    out.dedup();
}

/// The planes of conv(a ∪ b) through an edge of one polygon and a vertex of the other, each
/// oriented with both polygons behind it (within `snap`): every segment between the two lies
/// behind every plane.
fn hull_planes(a: &[DVec3], b: &[DVec3], snap: f64) -> Vec<Plane> {
    let mut out = Vec::new();
    let all = || a.iter().chain(b).copied();
    for (p, q) in [(a, b), (b, a)] {
        for k in 0..p.len() {
            let (x, y) = (p[k], p[(k + 1) % p.len()]);
            for &v in q {
                let Some(pl) = Plane::through(x, y, v, 1e-300) else { continue };
                let (lo, hi) = all().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), z| {
                    let d = pl.distance(z);
                    (lo.min(d), hi.max(d))
                });
                if hi <= snap {
                    out.push(pl);
                } else if lo >= -snap {
                    out.push(pl.flipped());
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;
    use crate::viewfactor::exact::pair::polygon_polygon;
    use crate::viewfactor::shadow::classify::{classify_row, RowShadows, Status};
    use crate::viewfactor::shadow::policy::{AUTO_ADAPT, AUTO_CUTS};

    /// A U profile (a slot open at the top), counter-clockwise in (x, z).
    const U: &[[f64; 2]] =
        &[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.7, 1.0], [0.7, 0.4], [0.3, 0.4], [0.3, 1.0], [0.0, 1.0]];

    /// The U profile extruded over y ∈ [−1, 0] as a closed triangle mesh with outward normals.
    fn channel() -> Vec<Polygon> {
        super::super::prism::extrude(U, |q, w| DVec3::new(q.x, -w, q.y))
    }

    /// A wall at x = 3 facing −x (patch 0), the channel's triangles as patches, and the index
    /// of a slot-floor triangle whose view of the wall the slot's side cuts.
    fn wall_and_channel() -> (Scene, usize, usize) {
        let wall = Polygon::new(vec![
            DVec3::new(3.0, -4.0, -2.0),
            DVec3::new(3.0, -4.0, 6.0),
            DVec3::new(3.0, 4.0, 6.0),
            DVec3::new(3.0, 4.0, -2.0),
        ])
        .unwrap();
        let part = channel();
        let faces = part.len();
        let floor = part
            .iter()
            .position(|t| t.normal().z > 0.99 && (t.centroid().z - 0.4).abs() < 1e-12)
            .expect("a slot-floor triangle");
        // A floor below the channel, so that every face has patches on both sides.
        let ground = Polygon::new(vec![
            DVec3::new(-3.0, -4.0, -1.0),
            DVec3::new(3.0, -4.0, -1.0),
            DVec3::new(3.0, 4.0, -1.0),
            DVec3::new(-3.0, 4.0, -1.0),
        ])
        .unwrap();
        let scene = Scene::builder()
            .surface("wall", vec![wall], 0.9, None)
            .surface("part", part, 0.9, None)
            .surface("ground", vec![ground], 0.9, None)
            .build();
        (scene, 1 + floor, faces)
    }

    #[test]
    fn a_pair_whose_blockers_fall_away_is_unobstructed_without_a_viewpoint() {
        // The wall's row against every channel triangle: the partly obstructed ones whose
        // kept blockers are none once clipped (or, for the small triangle, its own faces)
        // and the others, each told apart before integrating.
        let (scene, _, faces) = wall_and_channel();
        let blockers = Blockers::new(&scene);
        let mut row = RowShadows::default();
        classify_row(&scene, &blockers, 0, 1, &mut row);
        let integrator = Integrator::new(AUTO_ADAPT).with_cuts(AUTO_CUTS);
        let mut s = PairScratch::default();
        let (mut away, mut kept) = (0, 0);
        for j in 1..=faces {
            let Status::Partial(partial) = row.status(j) else { continue };
            let partial = partial.to_vec();
            let (pi, pj) = (&scene.patches[0].polygon, &scene.patches[j].polygon);
            let u = polygon_polygon(pi, pj);
            let falls = falls_away(pi, pj, &blockers, &partial, false, &mut s);
            let r = shadowed(pi, pj, u, &blockers, &partial, &integrator, 1e-6 * u, u64::MAX, false, &mut s);
            if falls {
                away += 1;
                assert_eq!((r.s, r.info.evals), (u, 0), "pair 0-{j}");
            } else {
                kept += 1;
                assert!(r.info.evals > 0 || r.info.roots > 0 || r.s < u, "pair 0-{j}: {r:?}");
            }
        }
        assert!(away > 0 && kept > 0, "{away} pairs fall away, {kept} keep a blocker");
    }

    #[test]
    fn a_small_patch_emitting_with_its_own_faces_matches_the_large_one() {
        let (scene, j, faces) = wall_and_channel();
        let blockers = Blockers::new(&scene);
        let (pi, pj) = (&scene.patches[0].polygon, &scene.patches[j].polygon);
        assert!(pj.bounding_radius() * OWN_FACES_RATIO <= pi.bounding_radius(), "j is the small patch");
        let part: Vec<usize> = (0..blockers.len())
            .filter(|&b| matches!(blockers.get(b).source, super::super::blockers::BlockerSource::Patch(p) if (1..=faces).contains(&p)))
            .collect();
        assert!(part.iter().all(|&b| blockers.get(b).closed == 1 && blockers.get(b).body.is_none()));
        let mut row = RowShadows::default();
        classify_row(&scene, &blockers, 0, 1, &mut row);
        let Status::Partial(partial) = row.status(j) else { panic!("the slot cuts the floor's view") };
        let partial = partial.to_vec();
        // The slot's far side (x = 0.7, facing −x) is turned away from the wall: the row left
        // it out, and the triangle's own list brings it back.
        let (mut own, mut cand) = (Vec::new(), Vec::new());
        faces_for_emitter(pj, pi, &blockers, &partial, &mut own, &mut cand);
        let slot_side = |b: &u32| {
            let bl = blockers.get(*b as usize);
            bl.normal.x < -0.99 && (bl.ring[0].x - 0.7).abs() < 1e-12
        };
        assert!(!partial.iter().any(slot_side) && own.iter().any(slot_side), "{partial:?} / {own:?}");
        let u = polygon_polygon(pi, pj);
        let integrator = Integrator::new(AUTO_ADAPT).with_cuts(AUTO_CUTS);
        let mut s = PairScratch::default();
        let at = |own: bool, tol: f64, s: &mut PairScratch| {
            shadowed_with(pi, pj, u, (&blockers, &partial), &integrator, (tol, u64::MAX), own, s)
        };
        // The wall emitting with the row's faces at a 100× tighter goal is the reference.
        let goal = 1e-4 * pj.area();
        let reference = at(false, 0.01 * goal, &mut s);
        assert!(!reference.swapped && reference.s < 0.9 * u && reference.s > 0.1 * u, "{reference:?}, u {u}");
        let small = at(true, goal, &mut s);
        assert!(small.swapped, "the triangle emits");
        assert!((small.s - reference.s).abs() <= goal, "{} vs {} (goal {goal})", small.s, reference.s);
        assert!(small.error <= goal, "{small:?}");
        // The triangle with the row's faces only would miss the slot's shadow.
        let wrong =
            shadowed_with(pj, pi, u, (&blockers, &partial), &integrator, (goal, u64::MAX), false, &mut s);
        assert!(!wrong.swapped && wrong.s - reference.s > 100.0 * goal, "{} vs {}", wrong.s, reference.s);
    }
}
