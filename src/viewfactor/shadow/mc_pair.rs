//! Monte Carlo for one partly obstructed pair, as a ratio to the exact unobstructed value:
//! A_i F_ij = (A_i F_ij)_unobstructed · Σ_k K_k V_k / Σ_k K_k,
//! with point pairs (x_k on i, y_k on j) from scrambled Sobol points, K = cosθ_i cosθ_j/(π r²)
//! and V the visibility of the segment.
//!
//! - **Exact visibility from the candidates.** The segment is tested against the pair's
//!   partial blockers only (clipped convex polygons, a plane and edge test each): the
//!   obstruction classification guarantees nothing else can cut it, so no ray is traced through
//!   the scene's BVH. Beyond [`LEAF`] blockers (a pair behind a meshed body) they are
//!   walked in a per-pair box tree ([`super::segtree`]) instead of scanned; either way a
//!   sample costs tens of nanoseconds, and the tests made are counted ([`McPair::tests`]).
//! - **Ratio, not difference.** A pair entirely visible or entirely hidden gets the exact value
//!   whatever the sample count; only the penumbra's variation costs samples.
//! - **Standard error.** The ratio estimator's delta-method variance
//!   Σ K_k² (V_k − R)² / (Σ K_k)², computed as for independent samples (an overestimate for
//!   scrambled Sobol), with a floor from a half-count prior R̃ = (R·n_eff + ½)/(n_eff + 1),
//!   n_eff = (ΣK)²/ΣK², so that a sample in which every point agreed never claims zero error,
//!   and at least Agresti–Coull's R̂(1 − R̂)/(n_eff + Z²), R̂ = (R·n_eff + Z²/2)/(n_eff + Z²)
//!   at Z = `MC_SIGMAS`: a sample that saw one blocked point or none, stopped because its
//!   plug-in variance looked small, does not claim a tighter error than the binomial interval
//!   (a boards wall pair at 5.8 standard errors from `analytic` before, validation/cad.md);
//!   a sample in which no point pair faced each other (ΣK = 0) reports the ratio ½ ± ½.
//! - **Replicates.** A sample of 512 points or more is drawn as 16 independently scrambled
//!   Sobol sequences ([`replicated`]); its error is their spread at its upper 95 % bound, which
//!   sees the stratification the binomial count ignores (a shadow edge sampled by a net errs
//!   far less than n^−1/2), while fewer than 64 point pairs on the minority side keep the
//!   binomial error above.
//! - **Budget.** The sample doubles until the standard error meets the goal; `auto` starts it
//!   at a sixteenth of the worst case (`policy::MC_PILOT_SHARE`).
//! - **Streams.** Seeded from (seed, i, j): the same numbers on any thread count.

use super::policy::MC_SIGMAS;
use super::segtree::{SegmentBlocker, SegmentTree, LEAF};
use crate::geometry::sampling::{sample_triangle, PolygonSampler};
use crate::geometry::tolerance::PARALLELOGRAM_REL;
use crate::geometry::Polygon;
use crate::viewfactor::monte_carlo::{mix64, stream_key, SobolBlock};
use glam::{DVec2, DVec3};
use std::f64::consts::FRAC_1_PI;

/// Salt of the auto pair streams (distinct from the Monte Carlo methods' salts).
const SALT: u64 = 0x6175_746F;
/// The ratio reported when no sampled point pair faced each other: the middle of [0, 1],
/// with the half-width as its standard error.
const NO_SIGHT_RATIO: f64 = 0.5;

/// Uniform points on a patch: the bilinear map for a parallelogram (keeps the Sobol
/// stratification), the triangle map for a triangle, else the triangle-table sampler.
#[derive(Debug, Clone)]
pub enum PatchSampler {
    /// o + s·u + t·v.
    Para {
        /// Corner.
        o: DVec3,
        /// First edge.
        u: DVec3,
        /// Second edge.
        v: DVec3,
    },
    /// One triangle: the same points as its one-entry table, without the table look-up.
    Tri([DVec3; 3]),
    /// Any planar polygon.
    Poly(PolygonSampler),
}

impl PatchSampler {
    /// The sampler of `p`.
    pub fn new(p: &Polygon) -> Self {
        let v = p.vertices();
        if v.len() == 4 {
            let scale = (v[2] - v[0]).length() + (v[3] - v[1]).length();
            if ((v[0] + v[2]) - (v[1] + v[3])).length() <= PARALLELOGRAM_REL * scale {
                return PatchSampler::Para { o: v[0], u: v[1] - v[0], v: v[3] - v[0] };
            }
        }
        let table = PolygonSampler::new(p);
        match table.triangle(0) {
            Some(t) if table.triangles() == 1 => PatchSampler::Tri(t),
            _ => PatchSampler::Poly(table),
        }
    }
    /// Area-uniform point for u ∈ [0, 1)².
    #[inline]
    pub fn sample(&self, s: f64, t: f64) -> DVec3 {
        match self {
            PatchSampler::Para { o, u, v } => *o + s * *u + t * *v,
            // The table's rescaling of s for its one triangle (cumulative fractions [1]).
            PatchSampler::Tri([a, b, c]) => {
                sample_triangle(*a, *b, *c, DVec2::new(s.clamp(0.0, 1.0 - f64::EPSILON), t))
            }
            PatchSampler::Poly(p) => p.sample(DVec2::new(s, t)),
        }
    }
}

/// The estimate for one pair.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct McPair {
    /// A_i F_ij, m².
    pub s: f64,
    /// Its variance, m⁴.
    pub var: f64,
    /// Samples used.
    pub samples: u32,
    /// Box and blocker tests made.
    pub tests: u64,
}

/// How many point pairs to draw.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Budget {
    /// Points drawn first.
    pub first: u32,
    /// Never more than this (at most 2¹⁶, one Sobol block).
    pub max: u32,
    /// Standard error to reach, m²; the sample doubles until it does.
    pub sigma: f64,
}

/// Ratio estimate of the obstructed A_i F_ij, sampling until the standard error meets the
/// budget: the kernel weights make the effective sample (ΣK)²/ΣK² smaller than the count, so
/// the first guess can fall short.
#[allow(clippy::too_many_arguments)]
pub fn estimate(
    si: &PatchSampler,
    ni: DVec3,
    sj: &PatchSampler,
    nj: DVec3,
    s_unobs: f64,
    (all, ids): (&[SegmentBlocker], &[u32]),
    budget: Budget,
    seed: u64,
    (i, j): (usize, usize),
    tree: &mut SegmentTree,
) -> McPair {
    let key = mix64(stream_key(seed, SALT, i, 0) ^ (j as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    let max = budget.max.clamp(1, 1 << 16);
    let use_tree = ids.len() > LEAF;
    if use_tree {
        tree.build(all, ids);
    }
    let mut tests = 0u64;
    // Point pair k of the scrambled sequence `sobol`: (kernel, visible), or None when the
    // two points do not face each other.
    let mut draw = |k: u32, sobol: &SobolBlock, tests: &mut u64| {
        let [a, b, c, d] = sobol.sample_4d(k);
        let x = si.sample(a as f64, b as f64);
        let y = sj.sample(c as f64, d as f64);
        let dv = y - x;
        let r2 = dv.length_squared();
        let (ci, cj) = (ni.dot(dv), -nj.dot(dv));
        if ci <= 0.0 || cj <= 0.0 || r2 == 0.0 {
            return None;
        }
        let kern = ci * cj / (r2 * r2) * FRAC_1_PI;
        let visible = if use_tree {
            !tree.blocked(all, x, y, tests)
        } else {
            !ids.iter().any(|&b| {
                *tests += 1;
                all[b as usize].cuts(x, y)
            })
        };
        Some((kern, visible))
    };
    if budget.first >= REPLICATES * REPLICATE_MIN && max >= 2 * REPLICATES * REPLICATE_MIN {
        return replicated(s_unobs, budget, max, key, &mut draw, tests);
    }
    let sobol = SobolBlock::from_seed(mix64(key) as u32);
    let mut sums = Sums::default();
    let (mut k, mut end) = (0, budget.first.clamp(1, max));
    loop {
        while k < end {
            if let Some((kern, visible)) = draw(k, &sobol, &mut tests) {
                sums.add(kern, visible);
            }
            k += 1;
        }
        let (s, var) = sums.ratio(s_unobs);
        if var.sqrt() <= budget.sigma || end >= max {
            return McPair { s, var, samples: end, tests };
        }
        end = end.saturating_mul(2).min(max);
    }
}

/// Independent scramblings a large sample is split into ([`replicated`]).
const REPLICATES: u32 = 16;
/// Fewest points per replicate: a sample of fewer than `REPLICATES` × this many points stays one
/// sequence with the binomial error.
const REPLICATE_MIN: u32 = 32;
/// Upper 95 % confidence factor of a variance estimated with `REPLICATES` − 1 degrees of
/// freedom: 15/χ²(0.05; 15) = 15/7.261.
const REPLICATE_VAR_UPPER: f64 = 2.066;
/// Fewest point pairs on the minority side (seen or hidden) before the replicates' spread is
/// trusted; below it a few hits could all fall in one replicate, and the binomial floor holds.
const MINORITY_MIN: u32 = 64;

/// Kernel sums of a sample.
#[derive(Debug, Clone, Copy, Default)]
struct Sums {
    sk: f64,
    skv: f64,
    sk2: f64,
    sk2v: f64,
    /// Point pairs that faced each other, and those of them that saw each other.
    faced: u32,
    seen: u32,
}

impl Sums {
    #[inline]
    fn add(&mut self, kern: f64, visible: bool) {
        self.sk += kern;
        self.sk2 += kern * kern;
        self.faced += 1;
        if visible {
            self.skv += kern;
            self.sk2v += kern * kern;
            self.seen += 1;
        }
    }
    fn merge(&mut self, o: &Sums) {
        self.sk += o.sk;
        self.skv += o.skv;
        self.sk2 += o.sk2;
        self.sk2v += o.sk2v;
        self.faced += o.faced;
        self.seen += o.seen;
    }
    fn ratio(&self, s_unobs: f64) -> (f64, f64) {
        ratio(s_unobs, self.sk, self.skv, self.sk2, self.sk2v)
    }
}

/// A large sample as [`REPLICATES`] independently scrambled Sobol sequences (randomized
/// quasi-Monte Carlo), each doubling together: the estimate pools them, and its variance is
/// the replicates' spread about the pooled ratio (delta method),
/// Σ_k (A_k − R·B_k)² / (K(K − 1)·B̄²) with A_k = Σ K·V and B_k = Σ K of replicate k, raised to
/// its upper 95 % confidence bound ([`REPLICATE_VAR_UPPER`]). A stratified sample of a shadow
/// edge errs far less than the binomial count says (about n^−3/4 against n^−1/2 across a
/// smooth edge), and the spread measures that without assuming it. While the minority side
/// holds fewer than [`MINORITY_MIN`] point pairs the binomial error of [`ratio`] is kept.
fn replicated(
    s_unobs: f64,
    budget: Budget,
    max: u32,
    key: u64,
    draw: &mut impl FnMut(u32, &SobolBlock, &mut u64) -> Option<(f64, bool)>,
    mut tests: u64,
) -> McPair {
    let scrambles: [SobolBlock; REPLICATES as usize] = std::array::from_fn(|r| {
        SobolBlock::from_seed(mix64(key ^ (r as u64 + 1).wrapping_mul(0xD1B5_4A32_D192_ED03)) as u32)
    });
    let mut sums = [Sums::default(); REPLICATES as usize];
    let per_max = max / REPLICATES;
    let (mut k, mut end) = (0, (budget.first / REPLICATES).next_power_of_two().clamp(REPLICATE_MIN, per_max));
    loop {
        for (r, sobol) in scrambles.iter().enumerate() {
            for m in k..end {
                if let Some((kern, visible)) = draw(m, sobol, &mut tests) {
                    sums[r].add(kern, visible);
                }
            }
        }
        k = end;
        let all = sums.iter().fold(Sums::default(), |mut all, r| {
            all.merge(r);
            all
        });
        let (s, binomial) = all.ratio(s_unobs);
        let minority = all.seen.min(all.faced - all.seen);
        let var = if minority < MINORITY_MIN || !(all.sk > 0.0) {
            binomial
        } else {
            let pooled = all.skv / all.sk;
            let reps = f64::from(REPLICATES);
            let mean_b = all.sk / reps;
            let spread: f64 = sums.iter().map(|r| (r.skv - pooled * r.sk).powi(2)).sum();
            s_unobs * s_unobs * spread / (reps * (reps - 1.0) * mean_b * mean_b) * REPLICATE_VAR_UPPER
        };
        if var.sqrt() <= budget.sigma || end >= per_max {
            return McPair { s, var, samples: end * REPLICATES, tests };
        }
        end = (end * 2).min(per_max);
    }
}

/// The ratio estimate and its variance from the kernel sums (see the module notes).
fn ratio(s_unobs: f64, sk: f64, skv: f64, sk2: f64, sk2v: f64) -> (f64, f64) {
    if !(sk > 0.0) {
        // No point pair saw the other patch (the facing part of the pair is smaller than
        // the sample resolves): the ratio is anywhere in [0, 1], so the estimate is the
        // middle and its error the half-width, never zero.
        return (s_unobs * NO_SIGHT_RATIO, (s_unobs * NO_SIGHT_RATIO).powi(2));
    }
    let r = skv / sk;
    // Σ K²(V − R)² with V ∈ {0, 1}: Σ_{V=1} K²·(1 − 2R) + R²·Σ K².
    let spread = ((1.0 - 2.0 * r) * sk2v + r * r * sk2).max(0.0) / (sk * sk);
    let n_eff = sk * sk / sk2;
    let prior = (r * n_eff + 0.5) / (n_eff + 1.0);
    let z2 = MC_SIGMAS * MC_SIGMAS;
    let wide = (r * n_eff + 0.5 * z2) / (n_eff + z2);
    let floor = (prior * (1.0 - prior) / n_eff).max(wide * (1.0 - wide) / (n_eff + z2));
    (s_unobs * r, s_unobs * s_unobs * spread.max(floor))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sq(z: f64, x0: f64, y0: f64, s: f64, up: bool) -> Polygon {
        Polygon::new(crate::geometry::fixtures::square(z, x0, y0, s, up)).unwrap()
    }

    #[test]
    fn a_triangle_samples_the_points_of_its_table() {
        let t = Polygon::new(vec![
            DVec3::new(0.1, 0.2, 0.3),
            DVec3::new(1.3, -0.4, 0.5),
            DVec3::new(0.2, 0.9, -0.7),
        ])
        .unwrap();
        let (fast, table) = (PatchSampler::new(&t), PolygonSampler::new(&t));
        assert!(matches!(fast, PatchSampler::Tri(_)));
        for k in 0..=64 {
            let (s, u) = (k as f64 / 64.0, (k * 37 % 65) as f64 / 64.0);
            assert_eq!(fast.sample(s, u), table.sample(DVec2::new(s, u)), "({s}, {u})");
        }
    }

    #[test]
    fn segment_test_hits_the_interior_only() {
        let b = SegmentBlocker::new(sq(0.5, 0.25, 0.25, 0.5, true).vertices(), 0.0);
        assert!(b.cuts(DVec3::new(0.5, 0.5, 0.0), DVec3::new(0.5, 0.5, 1.0)));
        assert!(!b.cuts(DVec3::new(0.1, 0.1, 0.0), DVec3::new(0.1, 0.1, 1.0)));
        assert!(!b.cuts(DVec3::new(0.5, 0.5, 0.0), DVec3::new(0.5, 0.5, 0.4)));
    }

    #[test]
    fn a_small_shadow_few_samples_hit_is_within_three_standard_errors() {
        // Unit squares at gap 1, a small plate midway: a few per cent of the exchange is
        // blocked, and a goal of u/9 (an entry of `auto` at 1e-4 with F ≈ 9e-4) stops the
        // sample after tens of points, often when it has seen one blocked point or none. The
        // plug-in variance of such a sample claims a tight error around a ratio near 1 (the
        // doubling stops on it); the floor must not.
        let (e, r) = (sq(0.0, 0.0, 0.0, 1.0, true), sq(1.0, 0.0, 0.0, 1.0, false));
        let unobs = 0.199_824_895_698;
        let (se, sr) = (PatchSampler::new(&e), PatchSampler::new(&r));
        let mut far = 0;
        // Perpendicular squares along a shared edge too (the kernel peaks at the edge, so the
        // effective sample is far below the count).
        let wall = Polygon::new(vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 1.0),
            DVec3::new(0.0, 0.0, 1.0),
        ])
        .unwrap();
        assert!(wall.normal().x > 0.0);
        let perpendicular = crate::viewfactor::exact::pair::polygon_polygon(&e, &wall);
        let swall = PatchSampler::new(&wall);
        for (side, corner, z, upright) in
            [(0.1, 0.45, 0.5, false), (0.12, 0.2, 0.5, false), (0.08, 0.7, 0.5, false), (0.1, 0.3, 0.2, true)]
        {
            let (r, sr, unobs) = if upright { (&wall, &swall, perpendicular) } else { (&r, &sr, unobs) };
            let ring = if upright {
                vec![
                    DVec3::new(corner, corner, z),
                    DVec3::new(corner + side, corner, z),
                    DVec3::new(corner + side, corner + side, z),
                    DVec3::new(corner, corner + side, z),
                ]
            } else {
                sq(z, corner, corner, side, true).vertices().to_vec()
            };
            let plate = [SegmentBlocker::new(&ring, 0.0)];
            let blockers = (&plate[..], &[0u32][..]);
            let run = |budget, seed| {
                let tree = &mut SegmentTree::default();
                estimate(&se, e.normal(), sr, r.normal(), unobs, blockers, budget, seed, (0, 1), tree)
            };
            let reference = run(Budget { first: 1 << 16, max: 1 << 16, sigma: 0.0 }, 99);
            let blocked = 1.0 - reference.s / unobs;
            assert!(blocked > 0.005 && blocked < 0.05, "blocked share {blocked}");
            for seed in 0..400 {
                let m = run(Budget { first: 8, max: 1 << 16, sigma: unobs / 18.0 }, seed);
                far += usize::from((m.s - reference.s).abs() > 3.0 * m.var.sqrt());
            }
        }
        // Honest standard errors put under 1 % of samples beyond three (normal: 0.27 %).
        assert!(far <= 16, "{far} of 1,600 samples beyond 3 standard errors");
    }

    #[test]
    fn a_large_sample_in_replicates_reports_an_honest_error_from_fewer_points() {
        // Two unit squares at gap 1 with a centred 0.5² blocker midway: F = 0.0995062946, the
        // blocked share ½, where the binomial count is largest.
        let (e, r) = (sq(0.0, 0.0, 0.0, 1.0, true), sq(1.0, 0.0, 0.0, 1.0, false));
        let blockers = [SegmentBlocker::new(sq(0.5, 0.25, 0.25, 0.5, true).vertices(), 0.0)];
        let (se, sr) = (PatchSampler::new(&e), PatchSampler::new(&r));
        let (unobs, exact): (f64, f64) = (0.199_824_895_698, 0.099_506_294_6);
        let sigma = unobs / 300.0;
        // The binomial error u·√(R(1 − R)/n) meets σ at 22,500 points.
        let binomial_n = (0.25 * (unobs / sigma).powi(2)) as u64;
        let (mut far, mut drawn) = (0, 0u64);
        for seed in 0..300 {
            let tree = &mut SegmentTree::default();
            let budget = Budget { first: 1024, max: 1 << 16, sigma };
            let m = estimate(
                &se,
                e.normal(),
                &sr,
                r.normal(),
                unobs,
                (&blockers, &[0]),
                budget,
                seed,
                (0, 1),
                tree,
            );
            assert!(m.var.sqrt() <= sigma, "seed {seed}: {m:?}");
            assert_eq!(m.samples % (REPLICATES * REPLICATE_MIN), 0, "whole replicates: {m:?}");
            far += usize::from((m.s - exact).abs() > 3.0 * m.var.sqrt());
            drawn += u64::from(m.samples);
        }
        // Honest: about 0.3 % beyond three standard errors (at most 1 % allowed) …
        assert!(far <= 3, "{far} of 300 estimates beyond 3 standard errors");
        // … from a fraction of the points the binomial error would ask.
        assert!(drawn / 300 <= binomial_n / 2, "{} points on average against {binomial_n}", drawn / 300);
    }

    #[test]
    fn centred_blocker_within_four_standard_errors() {
        // Two unit squares at gap 1 with a centred 0.5² blocker midway: F = 0.0995062946.
        let (e, r) = (sq(0.0, 0.0, 0.0, 1.0, true), sq(1.0, 0.0, 0.0, 1.0, false));
        let blockers = [SegmentBlocker::new(sq(0.5, 0.25, 0.25, 0.5, true).vertices(), 0.0)];
        let blockers = (&blockers[..], &[0u32][..]);
        let (se, sr) = (PatchSampler::new(&e), PatchSampler::new(&r));
        let unobs = 0.199_824_895_698;
        let run = |blockers, budget, seed| {
            let tree = &mut SegmentTree::default();
            estimate(&se, e.normal(), &sr, r.normal(), unobs, blockers, budget, seed, (0, 1), tree)
        };
        let mut z2 = 0.0;
        for seed in 0..20 {
            let m = run(blockers, Budget { first: 4096, max: 4096, sigma: 0.0 }, seed);
            let z = (m.s - 0.099_506_294_6) / m.var.sqrt();
            assert!(z.abs() < 4.0, "seed {seed}: {} ± {}", m.s, m.var.sqrt());
            z2 += z * z;
        }
        // The reported error is an upper bound for scrambled Sobol: rms z well below 1.
        assert!((z2 / 20.0f64).sqrt() < 1.0, "rms z {}", (z2 / 20.0f64).sqrt());
        // The sample grows until the error meets the budget.
        let m = run(blockers, Budget { first: 8, max: 1 << 16, sigma: 1e-3 }, 3);
        assert!(m.var.sqrt() <= 1e-3 && m.samples > 8, "{m:?}");
        // A receiver almost entirely behind the emitter's plane: the few samples drawn all
        // miss its facing sliver, and the estimate must say it knows nothing (before, it
        // claimed the unobstructed value with zero error).
        let tilted = Polygon::new(vec![
            DVec3::new(0.0, 0.0, -1.0),
            DVec3::new(0.0, 0.0, 0.001),
            DVec3::new(1.0, 0.0, 0.001),
            DVec3::new(1.0, 0.0, -1.0),
        ])
        .unwrap();
        let st = PatchSampler::new(&tilted);
        assert!(tilted.normal().y > 0.0, "the receiver faces the emitter");
        let tree = &mut SegmentTree::default();
        let unobs_tilted = 1e-6;
        let budget = Budget { first: 4, max: 4, sigma: 0.0 };
        let m =
            estimate(&se, e.normal(), &st, tilted.normal(), unobs_tilted, blockers, budget, 1, (0, 1), tree);
        assert!(m.var.sqrt() >= 0.5 * unobs_tilted * 0.999, "no sight claimed {m:?}");
        // No blocker: exact whatever the sample count.
        let m = run((&[], &[]), Budget { first: 4, max: 4, sigma: 0.0 }, 1);
        assert_eq!(m.s, unobs);
    }
}
