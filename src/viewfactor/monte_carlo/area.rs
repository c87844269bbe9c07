//! `mc-area`: random point pairs, x uniform on patch i and y uniform on a receiver j chosen
//! with probability A_j/A_R among the receivers R that face i, so
//! s_ij = A_i F_ij = A_i·E[ cosθ_i cosθ_j/(π r²) · V(x, y) · A_R · [y ∈ j] ],
//! with V the occlusion ray. Each sample lands on one receiver (multinomial, like hit counting).
//!
//! A pair with no blocker candidates in the BVH (`Visibility::candidates_between`) needs no
//! ray at all. The kernel is singular (1/r²) where patches share an edge: the estimator stays
//! unbiased but its variance is infinite there, so near-field standard errors are optimistic
//! (validation/rays.md quantifies it); the analytic methods are the right tool for such pairs.
use super::super::engine::{Row, RowKernel};
use super::super::MethodSet;
use super::tally::{IdHasher, Tally};
use super::{replicate_len, stream_key, Common, Points};
use crate::geometry::sampling::PolygonSampler;
use crate::geometry::Polygon;
use crate::Result;
use glam::DVec2;
use std::collections::HashMap;
use std::f64::consts::FRAC_1_PI;
use std::hash::BuildHasherDefault;

/// A receiver faces the emitter when some vertex is this fraction of the pair's size in front
/// of the other's plane (coplanar neighbours sit at round-off distance, ~1e-16 relative).
const FACING_TOL: f64 = 1e-9;

/// The `mc-area` row kernel.
pub(crate) struct AreaKernel<'a> {
    c: Common<'a>,
    samplers: Vec<PolygonSampler>,
}

impl<'a> AreaKernel<'a> {
    pub fn new(c: Common<'a>) -> Self {
        let samplers = c.scene.patches.iter().map(|p| PolygonSampler::new(&p.polygon)).collect();
        Self { c, samplers }
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
        let mut blocked: HashMap<usize, bool, BuildHasherDefault<IdHasher>> = HashMap::default();
        let mut scratch = Vec::new();
        let mut tally = Tally::new(reps);
        for r in 0..reps {
            let n = replicate_len(c.samples, reps, r);
            let mut points = Points::new(kind, stream_key(c.seed, 1, i, r));
            for _ in 0..n {
                let u = points.next();
                let k = cdf.partition_point(|&a| a <= u[4] * total).min(receivers.len() - 1);
                let j = receivers[k];
                let pj = &c.scene.patches[j].polygon;
                let x = self.samplers[i].sample(DVec2::new(u[0], u[1]));
                let y = self.samplers[j].sample(DVec2::new(u[2], u[3]));
                let d = y - x;
                let r2 = d.length_squared();
                let cos_i = ni.dot(d);
                let cos_j = -pj.normal().dot(d);
                if cos_i <= 0.0 || cos_j <= 0.0 || r2 == 0.0 {
                    continue;
                }
                let may_block = *blocked.entry(j).or_insert_with(|| {
                    vis.candidates_between(i, j, &mut scratch);
                    !scratch.is_empty()
                });
                if may_block && vis.occluded(x, y, i, j) {
                    continue;
                }
                // cosθ_i cosθ_j/(π r²) with both cosines from the unnormalised d.
                tally.add(j as u32, cos_i * cos_j / (r2 * r2) * FRAC_1_PI * total);
            }
            tally.end_replicate(n, area_i);
        }
        tally.finish(MethodSet::MC_AREA, c.samples, area_i, out);
        Ok(())
    }
}
