//! View factors: one closed [`Method`] enum with its registry, one dispatch point
//! ([`compute`]), one engine.
//!
//! - `row`: the [`row::RowKernel`] interface every method implements;
//! - [`engine`]: runs a [`row::RowKernel`] over every patch row in parallel, in waves, and
//!   hands the rows in patch order to a sink (deterministic on any thread count);
//! - `sink`: aggregates rows to the surface level or keeps them per patch, with row-sum
//!   diagnostics; never an N×N dense temporary;
//! - `packed`: the lean dense store, one packed f64 triangle of exchange areas, filled
//!   by the same kernels;
//! - [`points`]: factors from points (sensors) to every surface or patch, exact shadows;
//! - [`progress`]: progress on pairs done (a bar on a terminal, log lines otherwise);
//! - [`limits`]: the bounds on samples, resolution and tolerance, for every caller;
//! - [`range`]: the final check that every written factor lies in [0, 1];
//! - `flags`: entries a method could not bound, reported on stderr;
//! - `distributed`: rows split between MPI ranks and gathered to rank 0 (feature `mpi`);
//! - [`shard`]: rows split between independent runs (`--shard`) and merged (`lambert merge`);
//! - `registry`: the [`Method`] enum and one [`MethodInfo`] row per method (kernel, error
//!   model, leak thresholds, knob, chart colour), asked by the plan, enforcement, validation
//!   and the charts instead of each matching on the method;
//! - `accuracy`: the shape of a row and the error terms the methods share;
//! - the method modules ([`analytic`], [`auto`], [`hemicube`], [`single_plane`],
//!   [`monte_carlo`]: mc-area, mc-uniform, mc-cosine) each provide a kernel and their row.
use crate::scene::Scene;
use crate::Result;
use std::fmt;

pub(crate) mod accuracy;
pub mod analytic;
pub mod auto;
pub mod closed_form;
pub(crate) mod distributed;
pub mod engine;
pub mod exact;
pub(crate) mod flags;
pub mod hemicube;
pub mod limits;
pub mod monte_carlo;
pub(crate) mod packed;
pub mod points;
pub mod progress;
pub(crate) mod projection;
pub mod range;
pub(crate) mod registry;
pub(crate) mod row;
pub(crate) mod row_block;
pub mod shadow;
pub mod shard;
pub mod single_plane;
pub(crate) mod sink;

pub use accuracy::MethodInfo;
pub use flags::Flag;
pub use registry::Method;
pub use sink::{Entry, Level, ViewFactors};

/// Which method(s) produced an entry; a surface aggregate may mix several.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub struct MethodSet(u8);

impl MethodSet {
    /// Exact contour / closed form, unobstructed.
    pub const ANALYTIC: MethodSet = MethodSet(1);
    /// Analytic with exact shadow clipping.
    pub const SHADOWED: MethodSet = MethodSet(2);
    /// Hemicube.
    pub const HEMICUBE: MethodSet = MethodSet(4);
    /// Single plane.
    pub const SINGLE_PLANE: MethodSet = MethodSet(8);
    /// Monte Carlo area sampling.
    pub const MC_AREA: MethodSet = MethodSet(16);
    /// Monte Carlo uniform hemisphere.
    pub const MC_UNIFORM: MethodSet = MethodSet(32);
    /// Monte Carlo cosine hemisphere.
    pub const MC_COSINE: MethodSet = MethodSet(64);
    /// Method names by bit, lowest bit first (bit k stands for 2^k in [`MethodSet::bits`]).
    pub const NAMES: [&'static str; 7] =
        ["analytic", "analytic-shadowed", "hemicube", "single-plane", "mc-area", "mc-uniform", "mc-cosine"];

    /// Union of two sets.
    pub fn union(self, other: MethodSet) -> MethodSet {
        MethodSet(self.0 | other.0)
    }
    /// The bit set as an integer code (bit k = `NAMES[k]`).
    pub fn bits(self) -> u8 {
        self.0
    }
    /// True when no method is recorded.
    pub fn is_empty(self) -> bool {
        self.0 == 0
    }
}

/// How the empty method set is written: a row no method found anything in (every pair culled
/// or zero), such as the ambient row of a surface that sees no other surface.
pub const NO_METHOD: &str = "none";

impl fmt::Display for MethodSet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.0 == 0 {
            return f.write_str(NO_METHOD);
        }
        let mut first = true;
        for (bit, name) in Self::NAMES.iter().enumerate() {
            if self.0 & (1 << bit) != 0 {
                if !first {
                    f.write_str("+")?;
                }
                f.write_str(name)?;
                first = false;
            }
        }
        Ok(())
    }
}

/// Options shared by every method; unused knobs are ignored by methods that lack them.
#[derive(Debug, Clone, PartialEq)]
pub struct Params {
    /// The method.
    pub method: Method,
    /// Rays or points per patch for Monte Carlo.
    pub samples: usize,
    /// Pixels along a hemicube face or the single plane.
    pub resolution: usize,
    /// Absolute accuracy goal on each F for `auto` and adaptive integration.
    pub tolerance: f64,
    /// Random seed; results do not depend on the thread count.
    pub seed: u64,
    /// Show a progress bar on a terminal for long runs.
    pub progress: bool,
}

/// Default Monte Carlo samples per patch.
pub const DEFAULT_SAMPLES: usize = 100_000;
/// Default hemicube / single-plane resolution.
pub const DEFAULT_RESOLUTION: usize = 256;
/// Default `auto` tolerance: 1e-4 absolute on each F (issue brief, View3D's default eps).
pub const DEFAULT_FACTOR_TOLERANCE: f64 = 1e-4;

impl Params {
    /// The settings that change a number, as text for the agreement hash of MPI ranks and
    /// shards (the progress display left out: it never changes one).
    pub fn agreement(&self) -> String {
        format!("{:?}", Params { progress: false, ..self.clone() })
    }
}

impl Default for Params {
    fn default() -> Self {
        Self {
            method: Method::Auto,
            samples: DEFAULT_SAMPLES,
            resolution: DEFAULT_RESOLUTION,
            tolerance: DEFAULT_FACTOR_TOLERANCE,
            seed: 0,
            progress: false,
        }
    }
}

/// The row kernel of a deterministic method (its registry row's); `None` for the Monte Carlo
/// methods, which run their own sampler.
fn row_kernel<'a>(scene: &'a Scene, params: &Params) -> Result<Option<Box<dyn engine::RowKernel + 'a>>> {
    (params.method.info().kernel)(scene, params)
}

/// Computes the view factors of `scene` at the requested level with the chosen method.
pub fn compute(scene: &Scene, params: &Params, level: Level) -> Result<ViewFactors> {
    let start = std::time::Instant::now();
    let Some(kernel) = row_kernel(scene, params)? else {
        progress::enter(progress::Phase::ViewFactors);
        return monte_carlo::compute(scene, params, level);
    };
    // The kernel is set up (blockers, their BVH, the method's tables): the rows start.
    progress::enter(progress::Phase::ViewFactors);
    // The wall time includes the kernel's set-up (planes, rules, blockers, pair tables).
    let mut vf = engine::run(scene, kernel.as_ref(), params, level)?;
    vf.wall = start.elapsed();
    Ok(vf)
}

/// Computes the patch-level exchange areas of `scene` straight into the lean packed store
/// (`packed::PackedTriangular`): symmetric kernels fill their rows in parallel, the others are
/// averaged s̄ = ½(s_ij + s_ji) as they are folded. `None` for the Monte Carlo methods, whose
/// per-entry variances and hit counts need the sparse store.
pub fn compute_triangle(scene: &Scene, params: &Params) -> Result<Option<packed::PackedTriangular>> {
    compute_triangle_with(scene, params, None)
}

/// As [`compute_triangle`]; with `keep_rows`, under MPI each rank computes and keeps its own
/// row block of a symmetric kernel's triangle (`row_block`, the `solve` route) instead of
/// gathering every row to rank 0, after `keep_rows` checked that every rank's final share fits.
pub fn compute_triangle_with(
    scene: &Scene,
    params: &Params,
    keep_rows: Option<row_block::CheckShare>,
) -> Result<Option<packed::PackedTriangular>> {
    let Some(kernel) = row_kernel(scene, params)? else { return Ok(None) };
    progress::enter(progress::Phase::ViewFactors);
    let n = scene.patches.len() as u64;
    let total = if kernel.symmetric() { n * (n + 1) / 2 } else { n * n };
    let symmetric = kernel.symmetric();
    let costs = engine::row_costs(kernel.as_ref(), params.progress, n as usize, |i| {
        if symmetric {
            n - i as u64
        } else {
            n
        }
    });
    let mode = progress::Mode::for_stderr(params.progress);
    let options = format!("packed {}", params.agreement());
    if let Some(check) = keep_rows.filter(|_| row_block::keeps_rows(n as usize, symmetric).is_some()) {
        // This rank's rows only (the progress counts its share).
        let t = row_block::fill(scene, kernel.as_ref(), &options, mode, &costs, check)?;
        return Ok(Some(t));
    }
    let progress = progress::Progress::start_costed(total, "pairs", mode, costs.iter().sum());
    // Under mpirun: every rank computes a block of rows, rank 0 fills the store (others exit).
    let gathered = shard::split_rows(scene, kernel.as_ref(), &options)?;
    let kernel: &dyn engine::RowKernel = match &gathered {
        Some(g) => g,
        None => kernel.as_ref(),
    };
    let t = packed::fill(scene, kernel, &progress, &costs)?;
    progress.finish();
    Ok(Some(t))
}
