//! View factors from points to surfaces: sensors, radiometers, mean radiant temperature.
//!
//! A point p with unit normal n stands for a differential element dA. Its factor to a patch is
//! Lambert's point-to-polygon formula ([`point_to_polygon`], docs/literature.md V12); where a blocker
//! cuts part of the view, the shaded part is taken off with the pair methods' own shadow
//! clipping from one viewpoint ([`ShadowGeometry::shaded`]): F = F_clear − g(p). Both steps
//! are exact (no quadrature, no sampling), so every entry has a zero standard error.
//!
//! - **Blockers** are the scene's `Blockers`, seen from the points too
//!   (`Blockers::seen_from`: a sensor outside the patches' hull keeps the blockers between
//!   it and them). Per receiver, the candidates are those whose box meets the box of the point
//!   and the receiver, clipped to the point's front half-space and to the receiver's.
//! - **A sensor on a surface** is not shadowed by it: a blocker whose plane passes within
//!   [`ON_PLANE_REL`] of the point cannot cut a sight line leaving the point.
//! - A receiver behind the point's plane, or a point behind a receiver, gives 0.
//! - **Closure**: in a closed scene the row of a point inside the enclosure sums to 1;
//!   [`Closure`] names the points that fall short (outside the enclosure, facing into a
//!   wall, or looking through a gap).
//! - Rows run in parallel (rayon), one per point, each independent of the others, and are
//!   summed to surfaces in patch order: the same numbers on any thread count.
use super::progress::{Mode, Progress};
use super::shadow::blockers::Blockers;
use super::shadow::classify::clip_front;
use super::shadow::viewpoint::{Scratch as ViewScratch, ShadowGeometry};
use super::{Entry, Level, MethodSet};
use crate::geometry::Polygon;
use crate::scene::validate::MAX_COORD;
use crate::scene::Scene;
use crate::viewfactor::exact::lambert::point_to_polygon;
use glam::DVec3;
use rayon::prelude::*;
use std::time::{Duration, Instant};

/// A point with its unit normal: the differential element a sensor stands for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewPoint {
    /// Position, m (the scene's frame).
    pub position: DVec3,
    /// Unit normal: the point sees the hemisphere it points into.
    pub normal: DVec3,
}

/// Shortest normal accepted before normalisation: below it a written normal has no direction
/// left (its digits are round-off).
pub const MIN_NORMAL_LENGTH: f64 = 1e-9;

impl ViewPoint {
    /// A checked point: finite coordinates within ±1e12 m and a non-zero finite normal (scaled
    /// to unit length). The error says what is wrong, without the location (the caller's).
    pub fn new(position: [f64; 3], normal: [f64; 3]) -> Result<Self, String> {
        for (x, axis) in position.iter().zip(["x", "y", "z"]) {
            if !x.is_finite() {
                return Err(format!("{axis} is {x}; it must be a finite number"));
            }
            if x.abs() > MAX_COORD {
                return Err(format!("{axis} is {x:e}, beyond ±{MAX_COORD:e} m"));
            }
        }
        for (x, axis) in normal.iter().zip(["nx", "ny", "nz"]) {
            if !x.is_finite() {
                return Err(format!("{axis} is {x}; it must be a finite number"));
            }
        }
        let n = DVec3::from_array(normal);
        let len = n.length();
        if !(len >= MIN_NORMAL_LENGTH) || !len.is_finite() {
            return Err(format!(
                "the normal ({}, {}, {}) has length {len:e}; give a direction (it need not be unit length)",
                normal[0], normal[1], normal[2]
            ));
        }
        Ok(Self { position: DVec3::from_array(position), normal: n / len })
    }
}

/// Distance, relative to the scene size, within which a point lies on a blocker's plane: sensor
/// positions typed to 6–7 significant digits still sit on the wall they are mounted on.
pub const ON_PLANE_REL: f64 = 1e-6;

/// Largest |row sum − 1| of a point inside a closed scene that is still round-off: the factors
/// are exact, and summing a few thousand of them loses well under 1e-12; a gap in the
/// enclosure or a point outside it loses far more.
pub const ROW_SUM_TOL: f64 = 1e-9;

/// Point-to-surface (or point-to-patch) view factors: one sparse row per point.
#[derive(Debug, Clone, PartialEq)]
pub struct PointFactors {
    /// Columns are surfaces or patches.
    pub level: Level,
    /// Column names (surfaces, or `surface#k`).
    pub names: Vec<String>,
    /// Per point, the non-zero F(point → column), sorted by column; `std_error` is 0.
    pub rows: Vec<Vec<Entry>>,
    /// Point–patch pairs evaluated.
    pub pairs: u64,
    /// Wall time.
    pub wall: Duration,
}

impl PointFactors {
    /// Σ_j F(point → j) per point.
    pub fn row_sums(&self) -> Vec<f64> {
        // `+ 0.0`: the empty sum is −0, and a point that sees nothing has a row sum of 0.
        self.rows.iter().map(|r| r.iter().map(|e| e.factor).sum::<f64>() + 0.0).collect()
    }
    /// The factors as a dense row-major array (points × columns).
    pub fn dense(&self) -> Vec<f64> {
        let m = self.names.len();
        let mut out = vec![0.0; self.rows.len() * m];
        for (i, row) in self.rows.iter().enumerate() {
            for e in row {
                out[i * m + e.to as usize] = e.factor;
            }
        }
        out
    }
    /// The closure check of a closed scene ([`ROW_SUM_TOL`]).
    pub fn closure(&self) -> Closure {
        let sums = self.row_sums();
        let (worst, at) = sums
            .iter()
            .enumerate()
            .map(|(i, s)| ((s - 1.0).abs(), i))
            .fold((0.0, 0), |a, b| if b.0 > a.0 { b } else { a });
        let off = sums.iter().copied().enumerate().filter(|(_, s)| (s - 1.0).abs() > ROW_SUM_TOL).collect();
        Closure { worst, at, off }
    }
}

/// How far the rows of a closed scene's points are from 1.
#[derive(Debug, Clone, PartialEq)]
pub struct Closure {
    /// Largest |row sum − 1|.
    pub worst: f64,
    /// The point where it occurs.
    pub at: usize,
    /// (point, row sum) of the points off by more than [`ROW_SUM_TOL`], in point order.
    pub off: Vec<(usize, f64)>,
}

/// Most points named in a closure warning.
const NAMED: usize = 5;

impl Closure {
    /// One line for stderr: the largest |row sum − 1| and where.
    pub fn summary(&self, names: &[String]) -> String {
        let at = names.get(self.at).map_or("", String::as_str);
        format!("closed scene, point rows: max |row sum - 1| = {:.3e} (point {at})", self.worst)
    }
    /// The warning for points whose rows are off, naming the worst few; `None` when all close.
    /// `obstructions`: the scene has obstructions, which take no part in the exchange.
    pub fn warning(&self, names: &[String], obstructions: bool) -> Option<String> {
        if self.off.is_empty() {
            return None;
        }
        let mut off = self.off.clone();
        off.sort_by(|a, b| (b.1 - 1.0).abs().total_cmp(&(a.1 - 1.0).abs()).then(a.0.cmp(&b.0)));
        let worst: Vec<String> = off
            .iter()
            .take(NAMED)
            .map(|&(i, s)| format!("{} (row sum {s:.6})", names.get(i).map_or("?", String::as_str)))
            .collect();
        Some(format!(
            "closed scene: {} point(s) do not see a whole hemisphere of surfaces (row sum off 1 by more than \
             {ROW_SUM_TOL:e}): a point outside the enclosure, behind a surface or facing into one{}, or a \
             gap in the enclosure; worst: {}",
            self.off.len(),
            if obstructions { ", an obstruction in view (it takes no part in the exchange)" } else { "" },
            worst.join(", ")
        ))
    }
}

/// The scene's shadowing context for points.
struct Context<'s> {
    scene: &'s Scene,
    blockers: Option<Blockers>,
    /// [`ON_PLANE_REL`] × scene size.
    on_plane: f64,
}

/// Per-thread buffers.
#[derive(Default)]
struct Scratch {
    ids: Vec<u32>,
    tmp: Vec<DVec3>,
    rings: Vec<Vec<DVec3>>,
    active: Vec<u32>,
    view: ViewScratch,
}

/// F(point → every patch or surface) for each point, with exact shadows; `progress` shows a
/// bar or log lines on stderr for long runs (counted in point–patch pairs).
pub fn compute(scene: &Scene, points: &[ViewPoint], level: Level, progress: bool) -> PointFactors {
    let start = Instant::now();
    let eyes: Vec<DVec3> = points.iter().map(|p| p.position).collect();
    let blockers = Blockers::seen_from(scene, &eyes);
    let ctx = Context {
        scene,
        blockers: (!blockers.is_empty()).then_some(blockers),
        on_plane: ON_PLANE_REL * size(scene, &eyes),
    };
    let n = scene.patches.len() as u64;
    let bar = Progress::start(n * points.len() as u64, "point-patch pairs", Mode::for_stderr(progress));
    let rows: Vec<Vec<Entry>> = points
        .par_iter()
        .with_max_len(1)
        .map_init(Scratch::default, |s, p| {
            let row = patch_row(&ctx, p, s);
            bar.add(n);
            match level {
                Level::Patch => row,
                Level::Surface => by_surface(scene, &row),
            }
        })
        .collect();
    bar.finish();
    let names = match level {
        Level::Patch => (0..scene.patches.len()).map(|p| scene.patch_name(p)).collect(),
        Level::Surface => scene.surfaces.iter().map(|s| s.name.clone()).collect(),
    };
    PointFactors { level, names, rows, pairs: n * points.len() as u64, wall: start.elapsed() }
}

/// The non-zero factors of one point to every patch, in patch order.
fn patch_row(ctx: &Context, p: &ViewPoint, s: &mut Scratch) -> Vec<Entry> {
    let mut row = Vec::new();
    for (j, patch) in ctx.scene.patches.iter().enumerate() {
        let clear = point_to_polygon(p.position, p.normal, &patch.polygon);
        if !(clear > 0.0) {
            continue;
        }
        let (factor, method) = match &ctx.blockers {
            Some(b) => shaded(ctx, b, p, &patch.polygon, clear, s),
            None => (clear, MethodSet::ANALYTIC),
        };
        if factor > 0.0 {
            row.push(Entry { to: j as u32, factor, std_error: 0.0, method });
        }
    }
    row
}

/// F(point → patch) past the blockers, from its clear value `clear`.
fn shaded(
    ctx: &Context,
    blockers: &Blockers,
    p: &ViewPoint,
    poly: &Polygon,
    clear: f64,
    s: &mut Scratch,
) -> (f64, MethodSet) {
    let snap = blockers.snap();
    let (lo, hi) = poly.vertices().iter().fold((p.position, p.position), |(l, h), &v| (l.min(v), h.max(v)));
    s.ids.clear();
    blockers.blockers_where(|blo, bhi| blo.cmple(hi).all() && bhi.cmpge(lo).all(), &mut s.ids);
    s.ids.sort_unstable();
    let (n, off) = (p.normal, p.normal.dot(p.position));
    let (nr, offr) = (poly.normal(), poly.normal().dot(poly.centroid()));
    let mut kept = 0;
    for &b in &s.ids {
        let bl = blockers.get(b as usize);
        // A blocker through the point cuts no sight line leaving it (a sensor on a wall).
        if bl.normal.dot(p.position - bl.ring[0]).abs() <= ctx.on_plane {
            continue;
        }
        clip_front(&bl.ring, n, off, snap, &mut s.tmp);
        if s.tmp.len() < 3 {
            continue;
        }
        if s.rings.len() <= kept {
            s.rings.push(Vec::new());
        }
        clip_front(&s.tmp, nr, offr, snap, &mut s.rings[kept]);
        if s.rings[kept].len() >= 3 {
            kept += 1;
        }
    }
    if kept == 0 {
        return (clear, MethodSet::ANALYTIC);
    }
    let rings: Vec<&[DVec3]> = s.rings[..kept].iter().map(Vec::as_slice).collect();
    let emitter = element(p, poly.bounding_radius());
    // No closed-body links (`set_neighbours`): the pair path skips the faces of a solid turned
    // away from a viewpoint outside it, but a sensor on a part's face is not outside it, and
    // the faces it looks out through must block.
    let Some(geo) = ShadowGeometry::new(&emitter, n, poly.vertices(), nr, &rings) else {
        return (clear, MethodSet::ANALYTIC);
    };
    s.active.clear();
    s.active.extend(0..geo.blockers().len() as u32);
    let (g, _) = geo.shaded(geo.frame().point(p.position), &s.active, &mut s.view);
    if !(g > 0.0) {
        return (clear, MethodSet::ANALYTIC);
    }
    let f = clear - g;
    (if f > SHADOW_ROUNDOFF_REL * clear { f.min(clear) } else { 0.0 }, MethodSet::SHADOWED)
}

/// What is left of a factor whose view a shadow covers, relative to its clear value, below
/// which it is round-off: the shaded and clear factors are sums of the same Lambert terms,
/// each good to about 1e-15 of the clear factor.
pub const SHADOW_ROUNDOFF_REL: f64 = 1e-12;

/// A triangle in the point's plane with its centroid at the point. [`ShadowGeometry`] takes
/// an emitter ring, but from one viewpoint it reads only the emitter's plane and centroid
/// (they set the front half-space that clips the receiver and the blockers); the ring itself
/// serves the pair methods' integration, which a point does not need.
fn element(p: &ViewPoint, r: f64) -> [DVec3; 3] {
    let (e1, e2) = p.normal.any_orthonormal_pair();
    let r = r.max(f64::MIN_POSITIVE);
    [p.position + 2.0 * r * e1, p.position - r * e1 + r * e2, p.position - r * e1 - r * e2]
}

/// A patch row summed to surfaces (patches are grouped by surface, in order).
fn by_surface(scene: &Scene, row: &[Entry]) -> Vec<Entry> {
    let mut out: Vec<Entry> = Vec::new();
    for e in row {
        let to = scene.patches[e.to as usize].surface as u32;
        match out.last_mut() {
            Some(last) if last.to == to => {
                last.factor += e.factor;
                last.method = last.method.union(e.method);
            }
            _ => out.push(Entry { to, ..*e }),
        }
    }
    out
}

/// Bounding-box diagonal of the patches, obstructions and points (1 when empty or flat).
fn size(scene: &Scene, points: &[DVec3]) -> f64 {
    let all = scene
        .patches
        .iter()
        .map(|p| &p.polygon)
        .chain(scene.obstructions.iter().flat_map(|o| o.polygons.iter()))
        .flat_map(|p| p.vertices().iter().copied())
        .chain(points.iter().copied());
    let (lo, hi) = all.fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(l, h), v| {
        (l.min(v), h.max(v))
    });
    let d = (hi - lo).length();
    if d.is_finite() && d > 0.0 {
        d
    } else {
        1.0
    }
}
