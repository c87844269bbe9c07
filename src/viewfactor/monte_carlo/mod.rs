//! Monte Carlo view factors: `mc-area`, `mc-uniform`, `mc-cosine` .
//!
//! - this file: options, the dispatch used by `viewfactor::compute`, the sample streams;
//! - `hemisphere`: `mc-uniform` (weight 2cosθ) and `mc-cosine` (Malley, equal weights),
//!   closest-hit ray casting from patch i;
//! - `area`: `mc-area`, random point pairs with an occlusion ray;
//! - `tally`: per-row receiver sums and their standard errors.
//!
//! **Budget.** `--samples N` is the number of rays (point pairs for `mc-area`) cast from each
//! patch. `mc-area` spends them on receivers chosen by area among the patches facing i, so the
//! cost is N per patch for every method, as for the ray methods.
//!
//! **Streams.** Every patch row draws from its own stream keyed by (seed, method, patch,
//! replicate): results are identical on any thread count.
//!
//! **Samplers and standard errors** (measured in validation/rays.md):
//! - [`Sampler::Sobol`] (default): Owen-scrambled Sobol points (sobol_burley), split into
//!   [`SOBOL_REPLICATES`] independently scrambled replicates. The standard error of an entry is
//!   the spread of the replicate estimates (randomised QMC); the binomial formula would
//!   overstate it. The spread is taken per output cell (see `tally`), so surface sums get
//!   their true replicate variance, covariances included (`shared_samples = 0`).
//! - [`Sampler::Random`]: independent PCG draws; the error of an entry is the sample second
//!   moment rule, which is the binomial √(F(1−F)/N) for `mc-cosine`, and
//!   `shared_samples = N` lets the sink apply the exact multinomial rule to surface sums.
use super::engine::{self, RowKernel};
use super::{Level, Method, Params, ViewFactors};
use crate::scene::Scene;
use crate::visibility::Visibility;
use crate::{Error, Result};
use rand::Rng;
use rand_pcg::Pcg64Mcg;

pub(crate) mod area;
pub(crate) mod hemisphere;
pub(crate) mod tally;

/// Independently scrambled Sobol replicates per row; 16 gives a standard error good to about
/// ±18 % (χ² with 15 degrees of freedom) for a (16/1)^0.3 ≈ 2.3× variance cost at RQMC rates.
pub const SOBOL_REPLICATES: u32 = 16;
/// Fewest samples per patch: the sample variance behind every standard error needs two.
pub const MIN_SAMPLES: usize = 2;
/// Fewest samples per replicate for Sobol; below this a row falls back to random sampling.
const MIN_PER_REPLICATE: usize = 4;
/// sobol_burley sequences hold 2¹⁶ points per seed; longer replicates chain new seeds.
const SOBOL_BLOCK_BITS: u32 = 16;

/// Half the f32 grid step of sobol_burley's output (24-bit mantissa on [0, 1)).
const SOBOL_HALF_CELL: f64 = 0.5 / (1u32 << 24) as f64;

/// Point generator behind the estimators.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Sampler {
    /// Owen-scrambled Sobol points in replicates (randomised QMC).
    #[default]
    Sobol,
    /// Independent uniform points (PCG64).
    Random,
}

/// Monte Carlo options beyond [`Params`] (benchmarks and studies set them).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct McOptions {
    /// Point generator.
    pub sampler: Sampler,
}

/// Runs a Monte Carlo method with the default options.
pub fn compute(scene: &Scene, params: &Params, level: Level) -> Result<ViewFactors> {
    compute_with(scene, params, level, McOptions::default())
}

/// Runs a Monte Carlo method with explicit options.
pub fn compute_with(scene: &Scene, params: &Params, level: Level, options: McOptions) -> Result<ViewFactors> {
    if params.samples < MIN_SAMPLES {
        return Err(Error::Usage(format!(
            "Monte Carlo needs at least {MIN_SAMPLES} samples per patch ({} {}): a standard error \
             from fewer is undefined",
            crate::error::opt("samples"),
            params.samples
        )));
    }
    let samples = u32::try_from(params.samples).map_err(|_| {
        Error::Usage(format!(
            "{} {} exceeds 2^32 - 1 per patch",
            crate::error::opt("samples"),
            params.samples
        ))
    })?;
    let vis = Visibility::new(scene);
    let cell_of: Vec<u32> = match level {
        Level::Surface => scene.patches.iter().map(|p| p.surface as u32).collect(),
        Level::Patch => (0..scene.patches.len() as u32).collect(),
    };
    let common =
        Common { scene, vis: &vis, cell_of: &cell_of, samples, seed: params.seed, sampler: options.sampler };
    let kernel: Box<dyn RowKernel + '_> = match params.method {
        Method::McArea => Box::new(area::AreaKernel::new(common)),
        Method::McUniform => Box::new(hemisphere::HemisphereKernel::new(common, hemisphere::Warp::Uniform)),
        Method::McCosine => Box::new(hemisphere::HemisphereKernel::new(common, hemisphere::Warp::Cosine)),
        m => return Err(Error::Usage(format!("'{m}' is not a Monte Carlo method"))),
    };
    engine::run(scene, kernel.as_ref(), params, level)
}

/// A Monte Carlo method's registry row: samples as the knob, a few standard errors as the
/// error model, its own sampler (no row kernel); `counts_hits` for the hit-counting estimators.
const fn info(colour: (u8, u8, u8), counts_hits: bool) -> super::MethodInfo {
    use super::accuracy::{mc_error_bound, no_own_leak_tol, Knob};
    super::MethodInfo {
        knob: Knob::Samples,
        symmetric: false,
        monte_carlo: true,
        counts_hits,
        exact_shadows: false,
        kernel: |_, _| Ok(None),
        error_bound: mc_error_bound,
        own_leak_tol: no_own_leak_tol,
        colour: (colour, false),
    }
}

/// What every estimator needs.
#[derive(Clone, Copy)]
pub(crate) struct Common<'a> {
    pub scene: &'a Scene,
    pub vis: &'a Visibility,
    /// Output cell (surface or patch) of each patch, for replicate variances.
    pub cell_of: &'a [u32],
    pub samples: u32,
    pub seed: u64,
    pub sampler: Sampler,
}

impl Common<'_> {
    /// Replicate plan for a row: (sampler actually used, replicate count).
    pub fn plan(&self) -> (Sampler, u32) {
        match self.sampler {
            Sampler::Sobol if self.samples as usize >= MIN_PER_REPLICATE * SOBOL_REPLICATES as usize => {
                (Sampler::Sobol, SOBOL_REPLICATES)
            }
            _ => (Sampler::Random, 1),
        }
    }
}

/// Samples of replicate `r` out of `reps` when `n` are shared out evenly.
pub(crate) fn replicate_len(n: u32, reps: u32, r: u32) -> u32 {
    n / reps + u32::from(r < n % reps)
}

/// SplitMix64 finaliser: a bijective 64-bit mix.
pub(crate) fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Key of one stream: (seed, method salt, patch, replicate) hashed to 64 bits.
pub(crate) fn stream_key(seed: u64, salt: u64, patch: usize, replicate: u32) -> u64 {
    let mut h = mix64(seed ^ 0x6C61_6D62_6572_7400);
    for x in [salt, patch as u64, replicate as u64] {
        h = mix64(h ^ x.wrapping_mul(0x9E37_79B9_7F4A_7C15));
    }
    h
}

/// A stream of points in [0, 1)⁵ for one (row, replicate).
pub(crate) enum Points {
    /// Independent draws.
    Random(Pcg64Mcg),
    /// Owen-scrambled Sobol points; the seed changes every 2¹⁶ points.
    Sobol {
        /// Stream key.
        key: u64,
        /// Next index.
        index: u32,
        /// The current block's seed and its hashes.
        block: SobolBlock,
    },
}

/// One sobol_burley seed with the hashes `sample_4d` derives from it, computed once per block
/// instead of once per point (the points are bit-identical to `sobol_burley::sample_4d`).
#[derive(Clone, Copy)]
pub(crate) struct SobolBlock {
    table: &'static SobolTable,
    seed: u32,
    index_scramble: u32,
    dim_scramble: sobol_burley::parts::Int4,
}

impl SobolBlock {
    /// Block `block` of the stream `key`: the sequence of the seed mixed from both.
    fn new(key: u64, block: u32) -> Self {
        Self::from_seed(mix64(key ^ block as u64) as u32)
    }

    /// The sequence `sobol_burley::sample_4d(·, 0, seed)`: the hashes of `seed` for dimension
    /// set 0, as in sobol_burley 0.5's `sample_4d`.
    pub(crate) fn from_seed(seed: u32) -> Self {
        use sobol_burley::parts::{hash, hash_int4, Int4};
        let s: Int4 = [seed.wrapping_mul(0x9c8f_2d3b); 4].into();
        let dims: Int4 = [0x912f_69ba, 0x174f_18ab, 0x691e_72ca, 0xb40c_c1b8].into();
        Self {
            table: SobolTable::get(),
            seed,
            index_scramble: hash(seed ^ 0x79c6_8e4a),
            dim_scramble: hash_int4(s ^ dims),
        }
    }

    /// Point `k` (< 2¹⁶) of dimensions 0–3.
    #[inline]
    pub(crate) fn sample_4d(&self, k: u32) -> [f32; 4] {
        use sobol_burley::parts::{owen_scramble_int4_rev, owen_scramble_rev};
        let shuffled = owen_scramble_rev(k.reverse_bits(), self.index_scramble);
        owen_scramble_int4_rev(self.table.sobol_rev(shuffled), self.dim_scramble).reverse_bits().to_f32_norm()
    }
}

/// Sobol dimensions 0–3 (reversed bits) by index byte: entry b of byte table h is the XOR of
/// the direction vectors of the set bits of b, so a 16-bit index costs two look-ups instead
/// of a loop over its bits (`sobol_burley::parts::sobol_int4_rev`, same XORs, same result).
pub(crate) struct SobolTable([[sobol_burley::parts::Int4; 256]; 2]);

impl SobolTable {
    /// The shared table, built on first use from the library's own direction vectors.
    fn get() -> &'static Self {
        use sobol_burley::parts::{sobol_int4_rev, Int4};
        static TABLE: std::sync::OnceLock<SobolTable> = std::sync::OnceLock::new();
        TABLE.get_or_init(|| {
            // A reversed index with the single bit b (from the top) selects direction vector b.
            let dir: [Int4; 16] = std::array::from_fn(|b| sobol_int4_rev(0x8000_0000 >> b, 0));
            let zero: Int4 = [0; 4].into();
            SobolTable(std::array::from_fn(|h| {
                std::array::from_fn(|byte| {
                    (0..8).filter(|i| byte & (0x80 >> i) != 0).fold(zero, |acc, i| acc ^ dir[8 * h + i])
                })
            }))
        })
    }

    /// `sobol_int4_rev(index_rev, 0)`: only the top 16 bits of the reversed index count.
    #[inline]
    fn sobol_rev(&self, index_rev: u32) -> sobol_burley::parts::Int4 {
        self.0[0][(index_rev >> 24) as usize] ^ self.0[1][((index_rev >> 16) & 0xff) as usize]
    }
}

impl Points {
    /// The stream of `sampler` keyed by `key`.
    pub fn new(sampler: Sampler, key: u64) -> Self {
        match sampler {
            Sampler::Random => Points::Random(Pcg64Mcg::new(((key as u128) << 64) | mix64(!key) as u128 | 1)),
            Sampler::Sobol => Points::Sobol { key, index: 0, block: SobolBlock::new(key, 0) },
        }
    }

    /// Advances a Sobol stream: (index within the block, the block).
    #[inline]
    fn step(key: u64, index: &mut u32, block: &mut SobolBlock) -> u32 {
        let k = *index & ((1 << SOBOL_BLOCK_BITS) - 1);
        if k == 0 && *index != 0 {
            *block = SobolBlock::new(key, *index >> SOBOL_BLOCK_BITS);
        }
        *index += 1;
        k
    }

    /// The first four coordinates of [`Points::next`], for estimators that select no receiver
    /// (the Sobol stream skips its fifth dimension; the random stream still draws it, so both
    /// streams match `next` point for point).
    #[inline]
    pub fn next4(&mut self) -> [f64; 4] {
        match self {
            Points::Random(_) => {
                let [a, b, c, d, _] = self.next();
                [a, b, c, d]
            }
            Points::Sobol { key, index, block } => {
                let k = Self::step(*key, index, block);
                block.sample_4d(k).map(|x| x as f64 + SOBOL_HALF_CELL)
            }
        }
    }

    /// Next point: coordinates 0–1 and 2–3 drive the two 2-D warps, 4 selects a receiver.
    #[inline]
    pub fn next(&mut self) -> [f64; 5] {
        match self {
            Points::Random(rng) => std::array::from_fn(|_| rng.random::<f64>()),
            Points::Sobol { key, index, block } => {
                let k = Self::step(*key, index, block);
                let [a, b, c, d] = block.sample_4d(k);
                let e = sobol_burley::sample(k, 4, block.seed);
                // Centre each 2⁻²⁴ cell: never exactly 0, so no warp lands on its boundary.
                [a, b, c, d, e].map(|x| x as f64 + SOBOL_HALF_CELL)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_are_reproducible_and_distinct() {
        for sampler in [Sampler::Random, Sampler::Sobol] {
            let mut a = Points::new(sampler, stream_key(7, 1, 3, 0));
            let mut b = Points::new(sampler, stream_key(7, 1, 3, 0));
            let mut c = Points::new(sampler, stream_key(7, 1, 4, 0));
            let (pa, pb, pc) = (a.next(), b.next(), c.next());
            assert_eq!(pa, pb);
            assert_ne!(pa, pc);
            assert!(pa.iter().all(|&x| x > 0.0 && x < 1.0));
        }
    }

    #[test]
    fn sobol_blocks_reproduce_the_library_points() {
        // Every index of one block, a few of others.
        for (block, step) in [(0u32, 1), (1, 97), (7, 1013)] {
            let b = SobolBlock::new(42, block);
            let seed = mix64(42 ^ block as u64) as u32;
            for k in (0..1u32 << SOBOL_BLOCK_BITS).step_by(step) {
                assert_eq!(b.sample_4d(k), sobol_burley::sample_4d(k, 0, seed), "block {block}, k {k}");
            }
        }
    }

    #[test]
    fn next4_is_the_first_four_coordinates_of_next() {
        for sampler in [Sampler::Random, Sampler::Sobol] {
            let (mut a, mut b) = (Points::new(sampler, 9), Points::new(sampler, 9));
            for _ in 0..100 {
                let (p, q) = (a.next(), b.next4());
                assert_eq!(p[..4], q);
            }
        }
    }

    #[test]
    fn sobol_points_are_balanced_across_blocks() {
        // 2^17 points cross one seed change; each coordinate's mean stays 1/2 to QMC accuracy.
        let mut p = Points::new(Sampler::Sobol, 42);
        let n = 1 << 17;
        let mut sum = [0.0; 5];
        for _ in 0..n {
            for (s, x) in sum.iter_mut().zip(p.next()) {
                *s += x;
            }
        }
        for s in sum {
            assert!((s / n as f64 - 0.5).abs() < 1e-4, "mean {}", s / n as f64);
        }
    }

    #[test]
    fn replicates_share_out_every_sample() {
        for n in [64u32, 100, 1001] {
            assert_eq!((0..16).map(|r| replicate_len(n, 16, r)).sum::<u32>(), n);
        }
    }
}
