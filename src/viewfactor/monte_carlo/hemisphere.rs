//! `mc-uniform` and `mc-cosine`: rays from area-uniform points of patch i into its front
//! hemisphere, closest hit by the BVH.
//!
//! F_ij = (1/A_i)∫_{A_i}∫_Ω (cosθ/π)·[ray hits the front of j] dω dA, estimated with
//! - uniform directions (pdf 1/2π): weight 2cosθ;
//! - cosine directions (pdf cosθ/π, Malley): weight 1, a binomial count.
//!
//! A ray that ends on a back side or on an obstruction is absorbed and counts for no patch; a
//! ray that leaves the scene goes to the ambient (open scenes) or shows as a row-sum deficit.
use super::super::accuracy::MethodInfo;
use super::super::engine::{Row, RowKernel};
use super::super::MethodSet;
use super::tally::TallyPool;
use super::{replicate_len, stream_key, Common, Points};
use crate::geometry::{
    frame::Frame,
    sampling::{sample_cosine_hemisphere, sample_uniform_hemisphere, PolygonSampler},
};
use crate::Result;
use glam::DVec2;

/// The `mc-uniform` row of the method registry (error: a few standard errors; hit counts).
pub const UNIFORM_INFO: MethodInfo = super::info(crate::palette::ORANGE, true);

/// The `mc-cosine` row of the method registry (error: a few standard errors; hit counts).
pub const COSINE_INFO: MethodInfo = super::info(crate::palette::BLUISH_GREEN, true);

/// Direction distribution.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Warp {
    /// Uniform over the hemisphere, weight 2cosθ.
    Uniform,
    /// Cosine-weighted (Malley), weight 1.
    Cosine,
}

/// The row kernel of both hemisphere estimators.
pub(crate) struct HemisphereKernel<'a> {
    c: Common<'a>,
    warp: Warp,
    pool: TallyPool<'a>,
}

impl<'a> HemisphereKernel<'a> {
    pub fn new(c: Common<'a>, warp: Warp) -> Self {
        Self { c, warp, pool: TallyPool::new(c.cell_of) }
    }
    fn method(&self) -> MethodSet {
        match self.warp {
            Warp::Uniform => MethodSet::MC_UNIFORM,
            Warp::Cosine => MethodSet::MC_COSINE,
        }
    }
}

impl RowKernel for HemisphereKernel<'_> {
    fn symmetric(&self) -> bool {
        false
    }

    fn tree_hash(&self) -> u64 {
        self.c.vis.tree_hash()
    }

    fn row(&self, i: usize, out: &mut Row) -> Result<()> {
        let c = &self.c;
        let vis = c.vis;
        let poly = &c.scene.patches[i].polygon;
        let area = poly.area();
        let sampler = PolygonSampler::new(poly);
        let frame = Frame::from_normal(poly.normal());
        let (kind, reps) = c.plan();
        let salt = match self.warp {
            Warp::Uniform => 2,
            Warp::Cosine => 3,
        };
        let skip = i as u32;
        // Rays as long as the scene is wide: every surface in reach, no infinite interval.
        let reach = vis.ray_length();
        let mut tally = self.pool.tally(reps);
        for r in 0..reps {
            let n = replicate_len(c.samples, reps, r);
            let mut points = Points::new(kind, stream_key(c.seed, salt, i, r));
            for _ in 0..n {
                let u = points.next4();
                let x = sampler.sample(DVec2::new(u[0], u[1]));
                let uv = DVec2::new(u[2], u[3]);
                let local = match self.warp {
                    Warp::Uniform => sample_uniform_hemisphere(uv),
                    Warp::Cosine => sample_cosine_hemisphere(uv),
                };
                if local.z <= 0.0 {
                    continue; // a grazing direction of measure zero: weight 0
                }
                let d = frame.to_world(local).normalize();
                let o = vis.to_frame(x).as_vec3a();
                if let Some((slot, hit)) = vis.first_hit_frame(o, d.as_vec3a(), reach, skip) {
                    let j = vis.owner[slot];
                    if hit.front && (j as usize) < c.scene.patches.len() {
                        let w = match self.warp {
                            Warp::Uniform => 2.0 * local.z,
                            Warp::Cosine => 1.0,
                        };
                        tally.add(j, w);
                    }
                }
            }
            tally.end_replicate(n, area);
        }
        tally.finish(self.method(), c.samples, area, out);
        out.pairs = c.samples as u64;
        Ok(())
    }
}
