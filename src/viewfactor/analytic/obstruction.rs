//! Which pairs of a row are obstructed, and by what (exact and conservative).
//!
//! For row i:
//! 1. the blockers with a point strictly in front of patch i come from the blocker hierarchy;
//! 2. each is clipped to i's front half-space (the rest meets no segment leaving i) and its
//!    penumbra and umbra from i are built ([`super::penumbra`]);
//! 3. the penumbra prunes the patch hierarchy to the receivers it may shadow; each of those is
//!    classified exactly: clear, fully blocked (inside the umbra) or partial.
//!
//! A receiver absent from the result is unobstructed. The cost is proportional to the receivers
//! each blocker's penumbra reaches, not to N × blockers.
use super::blockers::Blockers;
use super::penumbra::{Build, Class, ShadowVolume};
use crate::scene::Scene;
use glam::DVec3;

/// The obstruction status of one pair (i, j) of a row.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PairStatus {
    /// Receiver patch.
    pub j: u32,
    /// Some single blocker intercepts every segment between i and j: F = 0.
    pub blocked: bool,
    /// Partial blockers: `RowShadows::blockers[start..start + len]`.
    pub start: u32,
    /// Their number.
    pub len: u32,
}

/// The obstructed pairs of one row, sorted by receiver.
#[derive(Debug, Clone, Default)]
pub struct RowShadows {
    /// One status per obstructed receiver.
    pub pairs: Vec<PairStatus>,
    /// Partial blocker ids (indices into [`Blockers`]), grouped per pair.
    pub blockers: Vec<u32>,
    /// Scratch: (j, blocker, class) triples before grouping.
    hits: Vec<(u32, u32, Class)>,
    row_blockers: Vec<u32>,
    receivers: Vec<u32>,
    ring: Vec<DVec3>,
    volume: ShadowVolume,
}

impl RowShadows {
    /// The partial blockers of `p`.
    pub fn partial(&self, p: &PairStatus) -> &[u32] {
        &self.blockers[p.start as usize..(p.start + p.len) as usize]
    }
    /// Status of receiver j, if obstructed.
    pub fn get(&self, j: usize) -> Option<&PairStatus> {
        self.pairs.binary_search_by_key(&(j as u32), |p| p.j).ok().map(|k| &self.pairs[k])
    }
}

/// Fills `out` with the obstructed receivers j ≥ `first` of row `i`.
pub fn classify_row(scene: &Scene, blockers: &Blockers, i: usize, first: usize, out: &mut RowShadows) {
    out.pairs.clear();
    out.blockers.clear();
    out.hits.clear();
    if blockers.is_empty() {
        return;
    }
    let snap = blockers.snap();
    let pi = &scene.patches[i].polygon;
    let (ni, off) = (pi.normal(), pi.normal().dot(pi.centroid()));
    let in_front =
        |lo: DVec3, hi: DVec3| ni.dot(0.5 * (lo + hi)) + ni.abs().dot(0.5 * (hi - lo)) - off > snap;
    out.row_blockers.clear();
    blockers.blockers_where(in_front, &mut out.row_blockers);
    out.row_blockers.sort_unstable();
    for k in 0..out.row_blockers.len() {
        let b = out.row_blockers[k];
        let blocker = blockers.get(b as usize);
        clip_front(&blocker.ring, ni, off, snap, &mut out.ring);
        if out.ring.len() < 3 {
            continue;
        }
        if out.volume.build(pi.vertices(), &out.ring, snap) == Build::Never {
            continue;
        }
        out.receivers.clear();
        let volume = &out.volume;
        blockers.patches_where(|lo, hi| in_front(lo, hi) && !volume.box_clear(lo, hi), &mut out.receivers);
        for &j in &out.receivers {
            if (j as usize) < first || j as usize == i {
                continue;
            }
            match volume.classify(scene.patches[j as usize].polygon.vertices()) {
                Class::Clear => {}
                class => out.hits.push((j, b, class)),
            }
        }
    }
    // Group by receiver: blocked when any blocker covers it, else the list of partial ones.
    out.hits.sort_unstable_by_key(|&(j, b, _)| (j, b));
    let mut k = 0;
    while k < out.hits.len() {
        let j = out.hits[k].0;
        let end = k + out.hits[k..].iter().take_while(|h| h.0 == j).count();
        let blocked = out.hits[k..end].iter().any(|h| h.2 == Class::Full);
        let start = out.blockers.len() as u32;
        if !blocked {
            out.blockers.extend(out.hits[k..end].iter().map(|h| h.1));
        }
        out.pairs.push(PairStatus { j, blocked, start, len: out.blockers.len() as u32 - start });
        k = end;
    }
}

/// The part of a convex ring with n·x − off ≥ 0 (snapping within `snap`), into `out`.
pub fn clip_front(ring: &[DVec3], n: DVec3, off: f64, snap: f64, out: &mut Vec<DVec3>) {
    out.clear();
    let m = ring.len();
    let side = |x: DVec3| {
        let d = n.dot(x) - off;
        if d.abs() <= snap {
            0.0
        } else {
            d
        }
    };
    let mut a = ring[m - 1];
    let mut da = side(a);
    for &b in ring {
        let db = side(b);
        if (da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0) {
            out.push(a + (b - a) * (da / (da - db)));
        }
        if db >= 0.0 {
            out.push(b);
        }
        a = b;
        da = db;
    }
    if out.len() < 3 || !out.iter().any(|&x| side(x) > 0.0) {
        out.clear();
    }
}
