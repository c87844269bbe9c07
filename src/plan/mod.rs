//! The route to a result, decided in one place: a scene and a typed [`Request`] become a
//! [`Plan`], which names the exchange route, states why in words, fixes what `tolerance`
//! means on that route, and refuses what cannot run before any work. [`Plan::run`] then
//! computes the result and returns it with its [`Diagnostics`]; nothing here prints.
//!
//! Map:
//! - [`Request`]: what the caller asks for (method and its knobs, tolerance, enforcement,
//!   exchange [`Store`], [`Solver`]); plain data, no command-line types.
//! - [`Plan::new`]: chooses the [`Route`] (packed dense triangle, clustered links or the
//!   sparse store) and the [`Tolerance`] meaning; [`PlanError`] names refusals in the
//!   library's own words.
//! - [`Plan::run`]: the chosen route's solve entry point; [`Outcome`] holds the per-patch
//!   solution, the exchange (sparse route) and the [`Diagnostics`].
//! - [`Progress`]: the caller's phase callback ([`Phase`]); [`Silent`] ignores it.
//!
//! Example (library use; the CLI and the validation suite call the same API):
//!
//! ```no_run
//! use lambert::plan::{Plan, Request, Silent};
//! let scene = lambert::scene::load(std::path::Path::new("cases/e3_cube_furnace/scene.toml"))?;
//! let plan = Plan::new(&scene, &Request::default()).map_err(lambert::Error::from)?;
//! println!("route: {} ({})", plan.route, plan.reason);
//! let out = plan.run(&scene, &mut Silent)?;
//! for (name, r) in out.solution.names.iter().zip(&out.solution.results) {
//!     println!("{name}: {} W", r.heat_rate);
//! }
//! # Ok::<(), lambert::Error>(())
//! ```
//!
//! Outputs never enter the plan: no output choice changes a number.
use crate::exchange::{self, Enforce, EnforceParams, EnforceReport, Exchange};
use crate::scene::Scene;
use crate::solve::{self, Solution, Solver};
use crate::viewfactor::{self, Flag, Level, Method};
use crate::{Error, Result};
use std::fmt;
use std::time::{Duration, Instant};

/// Exchange store asked for (named in [`crate::choice`]; the sparse store has no user name).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Store {
    /// Dense up to [`HIERARCHICAL_MIN_PATCHES`] patches and while it fits, else clustered.
    #[default]
    #[value(help = "By patch count, tolerance, memory and method")]
    Auto,
    /// Every patch pair (packed dense triangle, or the sparse store where the packed one
    /// cannot serve).
    #[value(help = "Every patch pair")]
    Dense,
    /// Clustered links with heat-rate error control.
    #[value(help = "Clustered links with heat-rate error control, for large scenes")]
    Hierarchical,
    /// Every patch pair in the sparse store, whatever the request (the reference route that
    /// validation compares the others with).
    #[value(skip)]
    Sparse,
}

/// The route a plan takes: which exchange store and solve stack compute the result.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Route {
    /// Packed dense triangle of patch pairs, dense solve.
    Packed,
    /// Clustered links, heat-rate error control.
    Clustered,
    /// Sparse store of patch pairs (any method, solver, bands, saved view factors).
    Sparse,
}

impl std::str::FromStr for Store {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        crate::choice::parse_or("exchange store", s)
    }
}

impl fmt::Display for Store {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        crate::choice::write(self, f)
    }
}

impl fmt::Display for Route {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Route::Packed => "dense (packed triangle)",
            Route::Clustered => "hierarchical (clustered links)",
            Route::Sparse => "dense (sparse store)",
        })
    }
}

/// What the tolerance means on the chosen route.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Tolerance {
    /// Absolute accuracy goal on each view factor F (packed and sparse routes).
    Factor(f64),
    /// Heat-rate tolerance, relative to the largest |heat rate| (clustered route); `factor`
    /// is the goal on each exactly integrated patch pair's F that comes with it.
    HeatRate {
        /// Relative heat-rate tolerance.
        rate: f64,
        /// Goal on each exact pair's F.
        factor: f64,
    },
}

/// What a request computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Goal {
    /// The radiosity solve ([`Plan::run`]).
    #[default]
    Solve,
    /// The view-factor matrix at `level` ([`Plan::view_factors`]), enforced when asked.
    ViewFactors {
        /// Per surface or per patch.
        level: Level,
    },
}

/// A request: what to compute, in the library's terms.
#[derive(Debug, Clone)]
pub struct Request {
    /// What to compute.
    pub goal: Goal,
    /// View-factor method.
    pub method: Method,
    /// Rays or points per patch of the Monte Carlo methods.
    pub samples: usize,
    /// Pixels along a hemicube face or the single plane.
    pub resolution: usize,
    /// Tolerance as given; `None` takes the scene file's, else the route's default.
    pub tolerance: Option<f64>,
    /// Random seed.
    pub seed: u64,
    /// Enforcement; `None` takes the goal's default (a solve: closure closed, reciprocity
    /// open; view factors: none, or closure where the scene file declares an enclosure).
    pub enforce: Option<Enforce>,
    /// Exchange store.
    pub store: Store,
    /// Linear solver.
    pub solver: Solver,
    /// The view factors come from the caller (a saved file), not from the method.
    pub saved_viewfactors: bool,
    /// Radiative conductances are wanted (needs the sparse store's exchange matrix).
    pub conductances: bool,
    /// Let the view-factor engine draw its own terminal progress bar.
    pub progress_bar: bool,
}

impl Default for Request {
    fn default() -> Self {
        let p = viewfactor::Params::default();
        Self {
            goal: Goal::Solve,
            method: p.method,
            samples: p.samples,
            resolution: p.resolution,
            tolerance: None,
            seed: p.seed,
            enforce: None,
            store: Store::Auto,
            solver: Solver::Direct,
            saved_viewfactors: false,
            conductances: false,
            progress_bar: false,
        }
    }
}

/// Why a request cannot run, in the library's words (the CLI maps them to its flags).
#[derive(Debug)]
pub enum PlanError {
    /// The clustered store was asked for, but it serves only gray solves by an exact kernel
    /// (`auto` or `analytic`) with the direct solver, computing the view factors itself and
    /// writing no conductances.
    ClusteredUnserved,
    /// Any other refusal (memory, bad value), already in the library's error type.
    Other(Error),
}

impl fmt::Display for PlanError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PlanError::ClusteredUnserved => f.write_str(
                "the hierarchical store serves gray solves by an exact kernel (auto or analytic) with the \
                 direct solver, computing the view factors itself and writing no conductances",
            ),
            PlanError::Other(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for PlanError {}

impl From<Error> for PlanError {
    fn from(e: Error) -> Self {
        PlanError::Other(e)
    }
}

impl From<PlanError> for Error {
    fn from(e: PlanError) -> Self {
        match e {
            PlanError::Other(e) => e,
            e @ PlanError::ClusteredUnserved => Error::Usage(e.to_string()),
        }
    }
}

/// `Store::Auto` goes clustered above this many patches (measured in validation/scale.md:
/// below it the dense path is as fast and exact).
pub const HIERARCHICAL_MIN_PATCHES: usize = 12_000;
/// `Store::Auto` stays dense (while it fits) for tolerances below this: the links' cost grows
/// faster than the dense store's as the tolerance tightens (validation/scale.md).
pub const HIERARCHICAL_MIN_TOLERANCE: f64 = 1e-3;
/// Bytes per patch pair of the sparse store and solve (measured: 6.4 GB at N = 8,472, about
/// 85 bytes per ordered pair), used to refuse what cannot fit.
pub const SPARSE_BYTES_PER_PAIR: f64 = 180.0;
/// Bytes per patch pair of the packed triangle (one f64), for the memory check of `auto`.
const PACKED_BYTES_PER_PAIR: f64 = 8.0;

/// Why a plan took its route; `Display` says it in the library's words.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reason {
    /// The store was asked for by name ([`Store::Dense`] or [`Store::Hierarchical`]).
    Asked,
    /// Only the sparse store serves this request (Monte Carlo method, iterative solver,
    /// bands, saved view factors or conductances).
    OnlySparse,
    /// [`Store::Auto`]: few enough patches for every pair.
    Small {
        /// Patches.
        patches: usize,
    },
    /// [`Store::Auto`]: a tolerance below [`HIERARCHICAL_MIN_TOLERANCE`] keeps every pair.
    Tight {
        /// Patches.
        patches: usize,
    },
    /// [`Store::Auto`]: more than [`HIERARCHICAL_MIN_PATCHES`] patches are clustered.
    Large {
        /// Patches.
        patches: usize,
    },
    /// [`Store::Auto`]: more than [`HIERARCHICAL_MIN_PATCHES`] patches, but the method has no
    /// exact kernel for the clustered links, so every pair goes in the dense store.
    NoExactKernel {
        /// Patches.
        patches: usize,
    },
    /// [`Store::Auto`]: the dense store would not fit in memory.
    NoMemory {
        /// Patches.
        patches: usize,
    },
    /// View factors: the output is per patch, enforced or has many surfaces, and the method
    /// has a row kernel, so the packed triangle holds the pairs.
    PackedRows,
    /// View factors: an unenforced per-surface matrix of at most
    /// `viewfactors::LEAN_SURFACES` surfaces is summed in the sparse store.
    FewSurfaces,
}

impl fmt::Display for Reason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Reason::Asked => f.write_str("asked for"),
            Reason::OnlySparse => f.write_str("only the sparse store serves this request"),
            Reason::Small { patches } => write!(f, "{patches} patches <= {HIERARCHICAL_MIN_PATCHES}"),
            Reason::Tight { patches } => {
                write!(f, "{patches} patches, tolerance below {HIERARCHICAL_MIN_TOLERANCE:e}")
            }
            Reason::Large { patches } => write!(f, "{patches} patches > {HIERARCHICAL_MIN_PATCHES}"),
            Reason::NoExactKernel { patches } => write!(
                f,
                "{patches} patches > {HIERARCHICAL_MIN_PATCHES}, but the hierarchical store evaluates its near \
                 pairs by an exact kernel only (auto or analytic)"
            ),
            Reason::NoMemory { patches } => {
                write!(f, "{patches} patches: the dense store would not fit in memory")
            }
            Reason::PackedRows => f.write_str(
                "per-patch, enforced or many-surface output by a method with a row kernel: packed triangle",
            ),
            Reason::FewSurfaces => write!(
                f,
                "unenforced per-surface output of at most {} surfaces: sparse store",
                viewfactors::LEAN_SURFACES
            ),
        }
    }
}

/// A decided route with its settings, ready to run.
#[derive(Debug, Clone)]
pub struct Plan {
    /// What the plan computes.
    pub goal: Goal,
    /// The route.
    pub route: Route,
    /// Why this route.
    pub reason: Reason,
    /// What the tolerance means on this route.
    pub tolerance: Tolerance,
    /// Enforcement mode.
    pub enforce: Enforce,
    /// View-factor parameters of the route.
    pub viewfactors: viewfactor::Params,
    /// Solve parameters.
    pub solve: solve::Params,
    /// Run settings the scene file chose where the request is silent (View3D `eps` and
    /// `encl`), in words, so that a run is reproducible from its request alone.
    pub scene_notes: Vec<String>,
}

/// Phases of a run ([`crate::viewfactor::progress::Phase`]), reported as each starts.
pub use crate::viewfactor::progress::Phase;

/// The caller's progress sink.
pub trait Progress {
    /// A phase starts.
    fn phase(&mut self, phase: Phase);
    /// The view-factor method's accuracy warnings and flagged entries, as soon as they are
    /// known (before a later step can fail); also kept in [`Diagnostics`].
    fn method_report(&mut self, _warnings: &[String], _flags: &[Flag]) {}
}

/// A [`Progress`] that reports nothing.
#[derive(Debug, Default, Clone, Copy)]
pub struct Silent;

impl Progress for Silent {
    fn phase(&mut self, _: Phase) {}
}

/// What a run reported besides its numbers.
#[derive(Debug, Default, Clone)]
pub struct Diagnostics {
    /// The view-factor method's accuracy warnings.
    pub warnings: Vec<String>,
    /// Entries the method flagged.
    pub flags: Vec<Flag>,
    /// What enforcement did.
    pub enforcement: Option<EnforceReport>,
    /// Patch pairs evaluated.
    pub pairs: u64,
    /// Bytes of the exchange store.
    pub store_bytes: usize,
    /// Leak warnings of an unenforced closed scene's view factors (worst rows, the geometry's
    /// hint and an obstruction note), in words.
    pub leak_warnings: Vec<String>,
    /// Wall time of the view-factor computation.
    pub viewfactor_wall: Duration,
    /// Clustered route: the build statistics (and those of a first pass with its tolerance).
    pub clustered:
        Option<(crate::exchange::hierarchy::Stats, Option<(f64, crate::exchange::hierarchy::Stats)>)>,
    /// Wall time of the whole run.
    pub wall: Duration,
}

/// A run's result.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// Per-patch (or per-node) solution.
    pub solution: Solution,
    /// The enforced exchange matrix (sparse route only; conductances read it).
    pub exchange: Option<Exchange>,
    /// What the run reported.
    pub diagnostics: Diagnostics,
}

impl Plan {
    /// Decides the route of the request's goal on `scene` and refuses what cannot run.
    pub fn new(scene: &Scene, req: &Request) -> std::result::Result<Plan, PlanError> {
        if let (None, Some(t)) = (req.tolerance, scene.run_defaults.tolerance) {
            viewfactor::limits::tolerance(t, &format!("{}: View3D eps", scene.source.display()))?;
        }
        if let Goal::ViewFactors { level } = req.goal {
            return Ok(viewfactors::plan(scene, req, level));
        }
        let n = scene.patches.len();
        let mode = req.enforce.unwrap_or_else(|| Enforce::solve_default(!scene.is_closed()));
        let factor = factor_tolerance(scene, req);
        let mut vf = viewfactor::Params {
            method: req.method,
            samples: req.samples,
            resolution: req.resolution,
            tolerance: factor,
            seed: req.seed,
            progress: req.progress_bar,
        };
        let solve = solve::Params { solver: req.solver, ..solve::Params::default() };
        let served = packed_serves(scene, req, mode);
        let packed = |reason| Plan {
            goal: Goal::Solve,
            route: if served { Route::Packed } else { Route::Sparse },
            reason,
            tolerance: Tolerance::Factor(factor),
            enforce: mode,
            viewfactors: vf.clone(),
            solve: solve.clone(),
            scene_notes: Vec::new(),
        };
        let patches = n;
        let reason = match req.store {
            Store::Sparse => return Ok(Plan { route: Route::Sparse, ..packed(Reason::Asked) }),
            Store::Dense => return Ok(packed(if served { Reason::Asked } else { Reason::OnlySparse })),
            // The links evaluate their near pairs with an exact kernel only.
            Store::Hierarchical if !served || !clustered_kernel(req.method) => {
                return Err(PlanError::ClusteredUnserved)
            }
            Store::Hierarchical => Reason::Asked,
            Store::Auto if !served => return Ok(packed(Reason::OnlySparse)),
            Store::Auto => {
                // Under MPI: each rank's row block against its own memory, agreed.
                let symmetric = req.method.is_symmetric();
                let fits = exchange::rowblock::check_fits(scene, PACKED_BYTES_PER_PAIR, symmetric).is_ok();
                // A tight tolerance costs the links more than the dense store costs the pairs.
                let tight = req.tolerance.is_some_and(|t| t < HIERARCHICAL_MIN_TOLERANCE);
                let exact = clustered_kernel(req.method);
                match (fits, tight, n <= HIERARCHICAL_MIN_PATCHES) {
                    (true, true, _) => return Ok(packed(Reason::Tight { patches })),
                    (true, false, true) => return Ok(packed(Reason::Small { patches })),
                    (true, false, false) if !exact => return Ok(packed(Reason::NoExactKernel { patches })),
                    (true, false, false) => Reason::Large { patches },
                    (false, ..) if !exact => return Err(no_store_serves(scene, req.method).into()),
                    (false, ..) => Reason::NoMemory { patches },
                }
            }
        };
        let rate = req.tolerance.unwrap_or(exchange::hierarchy::DEFAULT_HEAT_RATE_TOLERANCE);
        // The exact pairs keep `auto`'s own goal on each F, tightened with the heat-rate
        // tolerance (their errors count in the estimate, in quadrature per surface).
        vf.tolerance =
            (rate * exchange::hierarchy::PAIR_TOLERANCE_SHARE).min(exchange::hierarchy::PAIR_TOLERANCE_MAX);
        Ok(Plan {
            goal: Goal::Solve,
            route: Route::Clustered,
            reason,
            tolerance: Tolerance::HeatRate { rate, factor: vf.tolerance },
            enforce: mode,
            viewfactors: vf,
            solve,
            scene_notes: Vec::new(),
        })
    }

    /// Runs the plan on `scene` (the scene it was made for). The sparse route with saved
    /// view factors takes them from `saved`.
    pub fn run(&self, scene: &Scene, progress: &mut dyn Progress) -> Result<Outcome> {
        self.run_with(scene, None, progress)
    }

    /// [`Plan::run`] with the caller's view factors on the sparse route (`saved`).
    pub fn run_with(
        &self,
        scene: &Scene,
        saved: Option<&viewfactor::ViewFactors>,
        progress: &mut dyn Progress,
    ) -> Result<Outcome> {
        if self.goal != Goal::Solve {
            return Err(Error::Usage(
                "a view-factor plan runs with Plan::view_factors, not Plan::run".into(),
            ));
        }
        let start = Instant::now();
        let mut d = Diagnostics::default();
        let mut exchange = None;
        enter_viewfactors(progress, self.route != Route::Clustered && saved.is_none());
        let solution = match self.route {
            Route::Clustered => {
                let Tolerance::HeatRate { rate, .. } = self.tolerance else {
                    unreachable!("a clustered plan carries a heat-rate tolerance")
                };
                let run = solve::clustered::solve_scene_with(
                    scene,
                    &self.viewfactors,
                    self.enforce,
                    rate,
                    &self.solve,
                    &mut |p| enter(progress, p),
                )?;
                d.enforcement = Some(run.report);
                d.store_bytes = run.stats.bytes;
                d.clustered = Some((run.stats, run.first));
                run.solution
            }
            Route::Packed => {
                match self
                    .packed_solve(scene, &mut d, progress)
                    .map_err(|e| with_obstruction_note(scene, e))?
                {
                    Some(solution) => solution,
                    None => {
                        let (sol, ex) = self.sparse(scene, saved, &mut d, progress)?;
                        exchange = Some(ex);
                        sol
                    }
                }
            }
            Route::Sparse => {
                let (sol, ex) = self.sparse(scene, saved, &mut d, progress)?;
                exchange = Some(ex);
                sol
            }
        };
        d.wall = start.elapsed();
        Ok(Outcome { solution, exchange, diagnostics: d })
    }

    /// The packed route ([`solve::dense::solve_scene_with`], each phase said as it starts):
    /// view factors, enforcement, gray solve; `None` when the method needs the sparse store.
    fn packed_solve(
        &self,
        scene: &Scene,
        d: &mut Diagnostics,
        progress: &mut dyn Progress,
    ) -> Result<Option<Solution>> {
        let mut step = |phase: Phase, ex: &exchange::dense::DenseExchange| {
            if phase == Phase::Enforcement {
                progress.method_report(&ex.t.warnings, &ex.t.flags);
            }
            enter(progress, phase);
        };
        let Some(run) =
            solve::dense::solve_scene_with(scene, &self.viewfactors, self.enforce, &self.solve, &mut step)?
        else {
            return Ok(None);
        };
        d.warnings = run.warnings;
        d.flags = run.flags;
        d.enforcement = Some(run.report);
        d.pairs = run.pairs;
        d.store_bytes = run.store_bytes;
        Ok(Some(run.solution))
    }

    /// The sparse route: view factors (computed or saved), enforcement, gray or band solve.
    fn sparse(
        &self,
        scene: &Scene,
        saved: Option<&viewfactor::ViewFactors>,
        d: &mut Diagnostics,
        progress: &mut dyn Progress,
    ) -> Result<(Solution, Exchange)> {
        let computed;
        let vf = match saved {
            Some(vf) => vf,
            None => {
                exchange::dense::check_fits(scene.patches.len(), SPARSE_BYTES_PER_PAIR, &scene.source)?;
                computed = viewfactor::compute(scene, &self.viewfactors, Level::Patch)?;
                d.warnings = computed.warnings.clone();
                d.flags = computed.flags.clone();
                d.pairs = computed.pairs;
                progress.method_report(&d.warnings, &d.flags);
                &computed
            }
        };
        enter(progress, Phase::Enforcement);
        let rays = if saved.is_none() { hit_rays(&self.viewfactors) } else { None };
        let (ex, rep) = enforced(scene, vf, self.enforce, rays)?;
        d.enforcement = Some(rep);
        enter(progress, Phase::Solve);
        let sol = match &scene.spectral {
            Some(spectral) => solve::bands::solve_bands(scene, &ex, &spectral.into(), &self.solve)?,
            None => solve::solve_gray(scene, &ex, &self.solve)?,
        };
        Ok((sol, ex))
    }
}

/// `phase` starts: the caller's sink and this thread's progress display and watch hear it.
pub(crate) fn enter(sink: &mut dyn Progress, phase: Phase) {
    sink.phase(phase);
    crate::viewfactor::progress::enter(phase);
}

/// The view-factor phase starts. The sink hears [`Phase::ViewFactors`]; the display and watch
/// hear [`Phase::Bvh`] first when a kernel is `set_up` (blockers, their BVH, the method's
/// tables), and the view-factor computation enters [`Phase::ViewFactors`] once it is ready.
pub(crate) fn enter_viewfactors(sink: &mut dyn Progress, set_up: bool) {
    sink.phase(Phase::ViewFactors);
    crate::viewfactor::progress::enter(if set_up { Phase::Bvh } else { Phase::ViewFactors });
}

/// Loads the scene at `path` (`opts` as [`crate::scene::load_with`]) in [`Phase::Load`].
pub fn load(
    path: &std::path::Path,
    opts: &crate::scene::LoadOptions,
    sink: &mut dyn Progress,
) -> Result<Scene> {
    enter(sink, Phase::Load);
    crate::scene::load_with(path, opts)
}

/// The F tolerance of a request: as given, else the scene file's, else the default.
fn factor_tolerance(scene: &Scene, req: &Request) -> f64 {
    match (req.tolerance, scene.run_defaults.tolerance) {
        (Some(t), _) | (None, Some(t)) => t,
        (None, None) => viewfactor::DEFAULT_FACTOR_TOLERANCE,
    }
}

/// True when the clustered links can evaluate their near pairs by `method`: they integrate
/// them with an exact kernel only.
fn clustered_kernel(method: Method) -> bool {
    method.exact_shadows()
}

/// The refusal of [`Store::Auto`] when the dense store would not fit and `method` has no exact
/// kernel for the clustered links: no store can run it.
fn no_store_serves(scene: &Scene, method: Method) -> Error {
    let n = scene.patches.len();
    crate::error::InputError::file(
        &scene.source,
        format!(
            "{n} patches by {method}: the dense store would not fit in memory, and the hierarchical store \
             evaluates its near pairs by an exact kernel only (auto or analytic); use auto or analytic, or \
             coarser patches"
        ),
    )
    .into()
}

/// True when the packed dense triangle or the clustered links can serve the request.
fn packed_serves(scene: &Scene, req: &Request, mode: Enforce) -> bool {
    !req.saved_viewfactors
        && !req.conductances
        && scene.spectral.is_none()
        && req.solver == Solver::Direct
        && !req.method.is_monte_carlo()
        // Without enforcement a non-symmetric kernel's raw rows would be solved as they are.
        && (req.method.is_symmetric() || mode != Enforce::None)
}

/// Rays per patch when the method counts hits with equal weights.
pub fn hit_rays(p: &viewfactor::Params) -> Option<usize> {
    p.method.counts_hits().then_some(p.samples)
}

/// Builds the exchange matrix of `vf` and enforces `mode`. `rays`: rays per patch of a
/// hit-counting method, which lets the closure use maximum likelihood.
pub fn enforced(
    scene: &Scene,
    vf: &viewfactor::ViewFactors,
    mode: Enforce,
    rays: Option<usize>,
) -> Result<(Exchange, EnforceReport)> {
    let mut ex = Exchange::from_viewfactors(vf);
    if let (Some(n), Level::Patch) = (rays, ex.level) {
        if ex.samples.iter().all(|&s| s == 0) {
            ex.samples = vec![u32::try_from(n).unwrap_or(u32::MAX); ex.len()];
        }
    }
    let p = EnforceParams {
        mode,
        open: !scene.is_closed(),
        source: scene.source.clone(),
        facts: Some(std::sync::Arc::new(crate::scene::orientation::SceneFacts::of(scene))),
        ..Default::default()
    };
    let rep = exchange::enforce(&mut ex, &p).map_err(|e| with_obstruction_note(scene, e))?;
    Ok((ex, rep))
}

/// Adds the obstruction note to a leak refusal whose row has obstructions in front of it.
pub fn with_obstruction_note(scene: &Scene, e: Error) -> Error {
    let Error::Input(mut ie) = e else { return e };
    if let Some(note) = ie.surface.as_deref().and_then(|n| crate::scene::hints::obstruction_note(scene, n)) {
        ie.problem = format!("{}. Note: {note}", ie.problem);
    }
    Error::Input(ie)
}

/// Adds to a leak refusal of saved view factors that `file` carries no geometry fingerprint,
/// so it may belong to another scene with the same names.
pub fn with_unstamped_note(e: Error, file: &std::path::Path) -> Error {
    let Error::Input(mut ie) = e else { return e };
    if ie.problem.contains("leaks") {
        ie.problem = format!(
            "{}. Note: {} carries no geometry fingerprint (an older or hand-made file), so it may have \
             been computed for another scene with the same names",
            ie.problem,
            file.display()
        );
    }
    Error::Input(ie)
}

#[cfg(test)]
mod tests;
pub(crate) mod viewfactors;
pub use viewfactors::{flag_warnings, Matrix, VfOutcome};
