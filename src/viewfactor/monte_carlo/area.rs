//! `mc-area`: random point pairs, x uniform on patch i and y on a receiver j chosen with
//! probability A_j/A_R among the receivers R that face i; visibility by an occlusion ray.
//!
//! s_ij = A_i F_ij = ∫_i ∫_j k(x, y) V(x, y) dy dx with k = cosθ_i cosθ_j/(π r²). Uniform y
//! alone (weight k·A_j) has infinite variance where patches share an edge (k ~ 1/r², tail
//! P(w > t) ~ t^(−3/2)): estimates then fall low most of the time, and the sample variance
//! does not show it. So y is drawn by one-sample multiple importance sampling (balance
//! heuristic, Veach 1997) from two techniques, each with probability ½:
//! - uniform on j: area density 1/A_j;
//! - the point where a cosine-weighted ray from x meets j's plane (if inside j): its area
//!   density is exactly k(x, y).
//!
//! The weight k·V/p(j, y) = k·V·A_R/(½ + ½·A_j·k) is bounded by 2A_R/A_j: finite variance
//! everywhere. Each sample lands on one receiver (multinomial, like hit counting). A pair with
//! no blocker candidates in the BVH (`Visibility::candidates_between`) needs no ray.
use super::super::accuracy::MethodInfo;
use super::super::engine::{Row, RowKernel};
use super::super::MethodSet;
use super::tally::{IdHasher, TallyPool};
use super::{replicate_len, stream_key, Common, Points};
use crate::geometry::Polygon;
use crate::geometry::{
    frame::Frame,
    sampling::{sample_cosine_hemisphere, PolygonSampler},
};
use crate::Result;
use glam::DVec2;
use std::collections::HashMap;
use std::f64::consts::FRAC_1_PI;
use std::hash::BuildHasherDefault;

/// The `mc-area` row of the method registry (error: a few standard errors).
pub const INFO: MethodInfo = super::info(crate::palette::VERMILLION, false);

/// Probability of the uniform-area technique in the two-technique mixture.
const UNIFORM_SHARE: f64 = 0.5;

/// A receiver faces the emitter when some vertex is this fraction of the pair's size in front
/// of the other's plane (coplanar neighbours sit at round-off distance, ~1e-16 relative).
const FACING_TOL: f64 = 1e-9;

/// The `mc-area` row kernel.
pub(crate) struct AreaKernel<'a> {
    c: Common<'a>,
    samplers: Vec<PolygonSampler>,
    pool: TallyPool<'a>,
}

impl<'a> AreaKernel<'a> {
    pub fn new(c: Common<'a>) -> Self {
        let samplers = c.scene.patches.iter().map(|p| PolygonSampler::new(&p.polygon)).collect();
        Self { c, samplers, pool: TallyPool::new(c.cell_of) }
    }
}

/// True when part of `b` lies strictly in front of `a`'s plane.
fn in_front(a: &Polygon, b: &Polygon, size: f64) -> bool {
    b.vertices().iter().any(|&v| a.plane_distance(v) > FACING_TOL * size)
}

impl RowKernel for AreaKernel<'_> {
    fn symmetric(&self) -> bool {
        false
    }

    fn tree_hash(&self) -> u64 {
        self.c.vis.tree_hash()
    }

    fn row(&self, i: usize, out: &mut Row) -> Result<()> {
        let c = &self.c;
        let vis = c.vis;
        let pi = &c.scene.patches[i].polygon;
        let (ni, area_i) = (pi.normal(), pi.area());
        // Receivers that face i and that i faces, with their cumulative areas.
        let mut receivers = Vec::new();
        let mut cdf = Vec::new();
        let mut total = 0.0;
        for (j, pj) in c.scene.patches.iter().enumerate() {
            let pj = &pj.polygon;
            let size = pi.bounding_radius() + pj.bounding_radius();
            if j != i && in_front(pi, pj, size) && in_front(pj, pi, size) {
                total += pj.area();
                receivers.push(j);
                cdf.push(total);
            }
        }
        out.pairs = c.samples as u64;
        if receivers.is_empty() {
            return Ok(());
        }
        let (kind, reps) = c.plan();
        let frame = Frame::from_normal(ni);
        let mut blocked: HashMap<usize, bool, BuildHasherDefault<IdHasher>> = HashMap::default();
        let mut scratch = Vec::new();
        let mut tally = self.pool.tally(reps);
        for r in 0..reps {
            let n = replicate_len(c.samples, reps, r);
            let mut points = Points::new(kind, stream_key(c.seed, 1, i, r));
            for _ in 0..n {
                let u = points.next();
                // u₄ picks the receiver by area, then (rescaled) the technique.
                let k = cdf.partition_point(|&a| a <= u[4] * total).min(receivers.len() - 1);
                let j = receivers[k];
                let lo = if k == 0 { 0.0 } else { cdf[k - 1] };
                let pick = (u[4] * total - lo) / (cdf[k] - lo);
                let pj = &c.scene.patches[j].polygon;
                let nj = pj.normal();
                let x = self.samplers[i].sample(DVec2::new(u[0], u[1]));
                let y = if pick < UNIFORM_SHARE {
                    self.samplers[j].sample(DVec2::new(u[2], u[3]))
                } else {
                    // Cosine ray from x to j's plane; outside j it scores nothing.
                    let d = frame.to_world(sample_cosine_hemisphere(DVec2::new(u[2], u[3])));
                    let dn = d.dot(nj);
                    let t = (pj.centroid() - x).dot(nj) / dn;
                    if !(dn < 0.0 && t > 0.0) {
                        continue;
                    }
                    let y = x + d * t;
                    if !self.samplers[j].contains(y) {
                        continue;
                    }
                    y
                };
                let d = y - x;
                let r2 = d.length_squared();
                let (cos_i, cos_j) = (ni.dot(d), -nj.dot(d));
                if cos_i <= 0.0 || cos_j <= 0.0 || r2 == 0.0 {
                    continue;
                }
                // k = cosθ_i cosθ_j/(π r²) with both cosines from the unnormalised d.
                let kernel = cos_i * cos_j / (r2 * r2) * FRAC_1_PI;
                let may_block = *blocked.entry(j).or_insert_with(|| {
                    vis.candidates_between(i, j, &mut scratch);
                    !scratch.is_empty()
                });
                if may_block && vis.occluded(x, y, i, j) {
                    continue;
                }
                let density = UNIFORM_SHARE + (1.0 - UNIFORM_SHARE) * pj.area() * kernel;
                tally.add(j as u32, kernel * total / density);
            }
            tally.end_replicate(n, area_i);
        }
        tally.finish(MethodSet::MC_AREA, c.samples, area_i, out);
        Ok(())
    }
}
