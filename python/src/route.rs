//! The route of every computation of the binding: method checks, store choice (lean dense,
//! sparse or clustered), enforcement, refusals and warnings, as `lambert viewfactors` and
//! `lambert solve` take them (src/cli/run.rs). All of the binding's route logic lives in this
//! file so that it can be replaced by the library's plan in one place.
//!
//! Messages the CLI prints on stderr are collected as `warnings` (the binding hands them to
//! Python's `warnings` module) and as `notes` (the run summaries).
use lambert::exchange::{self, Enforce, EnforceParams, Exchange};
use lambert::report;
use lambert::scene::{self, Scene};
use lambert::solve;
use lambert::viewfactor::{self, Entry, Level, Method, MethodSet, ViewFactors};
use lambert::{Error, Result};
use std::path::Path;
use std::time::{Duration, Instant};

pub use lambert::viewfactor::limits::MAX_SAMPLES;
use lambert::viewfactor::limits::{tolerance as check_tolerance, RESOLUTIONS};
/// Output surfaces above which the surface-level matrix is kept in the packed store (CLI).
const LEAN_SURFACES: usize = 512;
/// Bytes per patch pair of the sparse store (CLI), used to refuse what cannot fit.
const SPARSE_BYTES_PER_PAIR: f64 = 180.0;
/// `exchange="auto"` goes hierarchical above this many patches (CLI).
const HIERARCHICAL_MIN_PATCHES: usize = 12_000;
/// `exchange="auto"` stays dense for tolerances below this (CLI).
const HIERARCHICAL_MIN_TOLERANCE: f64 = 1e-3;
/// Flagged entries listed at most this many at a time (CLI).
const FLAGS_SHOWN: usize = 10;

/// Options shared by `view_factors` and `solve`, checked as the CLI checks its flags.
#[derive(Debug, Clone)]
pub struct Options {
    /// View-factor parameters.
    pub params: viewfactor::Params,
    /// `tolerance` as given (`None`: the default, or the scene file's).
    pub tolerance_given: Option<f64>,
    /// Report per patch.
    pub patches: bool,
    /// `enforce` as given (`None`: the computation's default).
    pub enforce: Option<String>,
}

impl Options {
    /// Checks the options (the CLI's limits, with the keyword names in the messages).
    pub fn new(
        method: &str,
        tolerance: Option<f64>,
        samples: Option<usize>,
        resolution: Option<usize>,
        seed: u64,
        patches: bool,
        enforce: Option<String>,
    ) -> Result<Self> {
        let method: Method = method.parse()?;
        let mut params = viewfactor::Params { method, seed, progress: false, ..Default::default() };
        if let Some(s) = samples {
            if s == 0 || s > MAX_SAMPLES {
                return Err(Error::Usage(format!("samples must be between 1 and {MAX_SAMPLES}, got {s}")));
            }
            params.samples = s;
        }
        if let Some(r) = resolution {
            if !RESOLUTIONS.contains(&r) {
                return Err(Error::Usage(format!(
                    "resolution must be between {} and {}",
                    RESOLUTIONS.start(),
                    RESOLUTIONS.end()
                )));
            }
            params.resolution = r;
        }
        if let Some(t) = tolerance {
            params.tolerance = check_tolerance(t, "tolerance")?;
        }
        if let Some(e) = &enforce {
            e.parse::<Enforce>()?;
        }
        Ok(Self { params, tolerance_given: tolerance, patches, enforce })
    }
}

/// What a computation said besides its result.
#[derive(Debug, Default, Clone)]
pub struct Said {
    /// Warnings (the CLI's `lambert: warning:` lines).
    pub warnings: Vec<String>,
    /// Run summaries (the CLI's other stderr lines).
    pub notes: Vec<String>,
}

impl Said {
    fn warn(&mut self, w: impl Into<String>) {
        self.warnings.push(w.into());
    }
    fn note(&mut self, n: impl Into<String>) {
        self.notes.push(n.into());
    }
}

/// View factors of `viewfactors`: the matrix at the asked level and what was said.
pub struct VfRun {
    /// The matrix.
    pub vf: ViewFactors,
    /// Σ_j F_ij per patch before enforcement.
    pub raw_row_sums: Vec<f64>,
    /// The store that held the pairs (`dense` or `sparse`).
    pub store: &'static str,
    /// Warnings and notes.
    pub said: Said,
}

/// Scene warnings and the run settings the scene file asks for (View3D `eps`, `encl`).
fn scene_defaults(scene: &Scene, opts: &mut Options, said: &mut Said) -> Result<()> {
    for w in &scene.warnings {
        said.warn(w.clone());
    }
    for f in scene::hints::facing_away(scene) {
        said.warn(scene::hints::facing_away_warning(scene, &f));
    }
    if let (None, Some(t)) = (opts.tolerance_given, scene.run_defaults.tolerance) {
        opts.params.tolerance = check_tolerance(t, &format!("{}: View3D eps", scene.source.display()))?;
        said.note(format!("tolerance {t} from the scene file (View3D eps)"));
    }
    Ok(())
}

/// `lambert viewfactors` on `scene`.
pub fn view_factors(scene: &Scene, mut opts: Options) -> Result<VfRun> {
    let mut said = Said::default();
    scene_defaults(scene, &mut opts, &mut said)?;
    if opts.enforce.is_none() && scene.run_defaults.closure {
        said.note("enforce closure: the scene file declares a closed enclosure (View3D encl = 1)");
    }
    let level = if opts.patches { Level::Patch } else { Level::Surface };
    let fallback = if scene.run_defaults.closure { "closure" } else { "none" };
    let mode: Enforce = opts.enforce.as_deref().unwrap_or(fallback).parse()?;
    if let Some(run) = lean_viewfactors(scene, &opts, level, mode, &mut said)? {
        return Ok(run);
    }
    let (vf, raw) = if mode == Enforce::None {
        let vf = viewfactor::compute(scene, &opts.params, level)?;
        said.warnings.extend(vf.warnings.iter().cloned());
        warn_flags(scene, &vf.flags, &mut said);
        warn_leaks(scene, &vf, opts.params.method, opts.params.tolerance, &mut said);
        let sums = vf.patch_row_sums.clone();
        (vf, sums)
    } else {
        let raw = viewfactor::compute(scene, &opts.params, Level::Patch)?;
        said.warnings.extend(raw.warnings.iter().cloned());
        warn_flags(scene, &raw.flags, &mut said);
        let ex = enforced(scene, &raw, mode, hit_rays(&opts.params), &mut said)?;
        let mut vf = at_level(scene, &ex, level).to_viewfactors(raw.wall);
        vf.pairs = raw.pairs;
        (vf, raw.patch_row_sums)
    };
    viewfactor::range::check(&vf)?;
    said.note(format!(
        "{} patches, {} pairs, {:.3} s, method {}",
        scene.patches.len(),
        vf.pairs,
        vf.wall.as_secs_f64(),
        opts.params.method
    ));
    Ok(VfRun { vf, raw_row_sums: raw, store: "sparse", said })
}

/// The CLI's lean `viewfactors` path (packed store) when it serves the run; `None` otherwise.
fn lean_viewfactors(
    scene: &Scene,
    opts: &Options,
    level: Level,
    mode: Enforce,
    said: &mut Said,
) -> Result<Option<VfRun>> {
    let method = opts.params.method;
    let wanted = level == Level::Patch || mode != Enforce::None || scene.surfaces.len() > LEAN_SURFACES;
    if method.is_monte_carlo() || !(method.is_symmetric() || mode != Enforce::None) || !wanted {
        return Ok(None);
    }
    let start = Instant::now();
    let Some(mut ex) = exchange::dense::build(scene, &opts.params)? else { return Ok(None) };
    let wall = start.elapsed();
    said.warnings.extend(ex.t.warnings.iter().cloned());
    warn_flags(scene, &ex.t.flags, said);
    let open = !scene.is_closed();
    if mode == Enforce::None {
        warn_dense_leaks(scene, &ex, said);
    } else {
        let p = EnforceParams {
            mode,
            open,
            source: scene.source.clone(),
            facts: facts(scene),
            ..Default::default()
        };
        let rep = exchange::dense::enforce(&mut ex, &p).map_err(|e| with_obstruction_note(scene, e))?;
        note_enforcement(mode, &rep, said);
    }
    let raw: Vec<f64> = ex.t.raw_row_sums.iter().zip(&ex.t.areas).map(|(s, a)| s / a).collect();
    let one_patch_each = scene.surfaces.iter().all(|s| s.patches.len() == 1);
    let vf = if level == Level::Patch || one_patch_each {
        let names = match level {
            Level::Patch => std::mem::take(&mut ex.names),
            Level::Surface => scene.surfaces.iter().map(|s| s.name.clone()).collect(),
        };
        triangle_viewfactors(&ex.t, names, level, wall)?
    } else {
        exchange::dense::to_surface_viewfactors(&ex, scene, wall)
    };
    viewfactor::range::check(&vf)?;
    said.note(format!(
        "{} patches, {} pairs, {:.3} s, method {}, dense store {:.1} MB",
        scene.patches.len(),
        ex.t.pairs,
        wall.as_secs_f64(),
        method,
        ex.t.bytes() as f64 / 1e6
    ));
    Ok(Some(VfRun { vf, raw_row_sums: raw, store: "dense", said: std::mem::take(said) }))
}

/// The view factors F_ij = s̄_ij / A_i of a packed store as sparse rows: the records the CLI's
/// `write_triangle` writes (zeros without an error skipped).
fn triangle_viewfactors(
    t: &viewfactor::triangle::Triangle,
    names: Vec<String>,
    level: Level,
    wall: Duration,
) -> Result<ViewFactors> {
    let rows: Vec<Vec<Entry>> = (0..t.n)
        .map(|i| {
            let a = t.areas[i];
            (0..t.n)
                .filter_map(|j| {
                    let s = t.get(i, j);
                    let (method, var) = t.meta(i, j);
                    (s != 0.0 || var != 0.0).then(|| Entry {
                        to: j as u32,
                        factor: s / a,
                        std_error: var.sqrt() / a,
                        method,
                    })
                })
                .collect()
        })
        .collect();
    let patch_row_sums = rows.iter().map(|r| r.iter().map(|e| e.factor).sum()).collect();
    Ok(ViewFactors {
        level,
        names,
        areas: t.areas.clone(),
        rows,
        patch_row_sums,
        patch_samples: vec![0; t.n],
        pairs: t.pairs,
        wall,
        warnings: t.warnings.clone(),
        flags: t.flags.clone(),
    })
}

/// Options of `solve` beyond [`Options`].
#[derive(Debug, Clone)]
pub struct SolveOptions {
    /// `solver`: direct, jacobi or gauss-seidel.
    pub solver: String,
    /// `exchange`: auto, dense or hierarchical.
    pub exchange: String,
}

/// A solved scene at patch level (or surface level from saved surface view factors).
pub struct SolveRun {
    /// The solution as the solver returned it.
    pub solution: solve::Solution,
    /// Which path solved it (`hierarchical`, `dense` or `sparse`).
    pub path: &'static str,
    /// Warnings and notes.
    pub said: Said,
}

/// `lambert solve` on `scene`; `saved`: view factors to use instead of computing them, with
/// whether they carried the scene's fingerprint and the file they came from (for messages).
pub fn solve(
    scene: &Scene,
    mut opts: Options,
    s: &SolveOptions,
    saved: Option<(ViewFactors, bool, Option<&Path>)>,
) -> Result<SolveRun> {
    let mut said = Said::default();
    let params = solve::Params { solver: s.solver.parse()?, ..solve::Params::default() };
    let exchange_path = ExchangePath::from_name(&s.exchange)?;
    for w in &scene.warnings {
        said.warn(w.clone());
    }
    if let (None, Some(t)) = (opts.tolerance_given, scene.run_defaults.tolerance) {
        opts.params.tolerance = check_tolerance(t, &format!("{}: View3D eps", scene.source.display()))?;
    }
    scene.check_boundary_conditions()?;
    for f in scene::hints::facing_away(scene) {
        said.warn(scene::hints::facing_away_warning(scene, &f));
    }
    let mode = match opts.enforce.as_deref() {
        Some(e) => e.parse()?,
        None => Enforce::solve_default(!scene.is_closed()),
    };
    let has_saved = saved.is_some();
    if let Some(sol) = clustered(scene, &opts, has_saved, exchange_path, mode, &params, &mut said)? {
        return Ok(SolveRun { solution: sol, path: "hierarchical", said });
    }
    if lean_served(scene, &opts.params, has_saved, mode, &params) {
        let run = solve::dense::solve_scene(scene, &opts.params, mode, &params)
            .map_err(|e| with_obstruction_note(scene, e))?;
        if let Some(run) = run {
            said.warnings.extend(run.warnings.iter().cloned());
            warn_flags(scene, &run.flags, &mut said);
            note_enforcement(mode, &run.report, &mut said);
            said.note(format!(
                "{} patches, {} pairs, dense store {:.1} MB",
                scene.patches.len(),
                run.pairs,
                run.store_bytes as f64 / 1e6
            ));
            return Ok(SolveRun { solution: run.solution, path: "dense", said });
        }
    }
    let (vf, stamped, file) = match saved {
        Some(v) => v,
        None => {
            exchange::dense::check_fits(scene.patches.len(), SPARSE_BYTES_PER_PAIR, &scene.source)?;
            let vf = viewfactor::compute(scene, &opts.params, Level::Patch)?;
            said.warnings.extend(vf.warnings.iter().cloned());
            warn_flags(scene, &vf.flags, &mut said);
            (vf, true, None)
        }
    };
    if opts.patches && vf.level == Level::Surface {
        return Err(Error::Usage(
            "patches=True needs patch-level view factors (computed or saved with patches=True)".into(),
        ));
    }
    let rays = if has_saved { None } else { hit_rays(&opts.params) };
    let ex = enforced(scene, &vf, mode, rays, &mut said).map_err(|e| match (file, stamped) {
        (Some(file), false) => with_unstamped_note(e, file),
        _ => e,
    })?;
    let sol = match &scene.spectral {
        Some(spectral) => solve::bands::solve_bands(scene, &ex, &spectral.into(), &params)?,
        None => solve::solve_gray(scene, &ex, &params)?,
    };
    Ok(SolveRun { solution: sol, path: "sparse", said })
}

/// `exchange=`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum ExchangePath {
    Auto,
    Dense,
    Hierarchical,
}

impl ExchangePath {
    fn from_name(s: &str) -> Result<Self> {
        match s {
            "auto" => Ok(Self::Auto),
            "dense" => Ok(Self::Dense),
            "hierarchical" => Ok(Self::Hierarchical),
            _ => Err(Error::Usage(format!("unknown exchange '{s}'; expected auto, dense or hierarchical"))),
        }
    }
}

/// True when the lean paths (dense triangle or hierarchy) can serve this solve (CLI).
fn lean_served(
    scene: &Scene,
    vf: &viewfactor::Params,
    saved: bool,
    mode: Enforce,
    params: &solve::Params,
) -> bool {
    !saved
        && scene.spectral.is_none()
        && params.solver == solve::Solver::Direct
        && !vf.method.is_monte_carlo()
        && (vf.method.is_symmetric() || mode != Enforce::None)
}

/// The clustered path when chosen (forced, or by `auto` for a large scene or one whose dense
/// store cannot fit), as the CLI chooses it.
fn clustered(
    scene: &Scene,
    opts: &Options,
    saved: bool,
    path: ExchangePath,
    mode: Enforce,
    params: &solve::Params,
    said: &mut Said,
) -> Result<Option<solve::Solution>> {
    let n = scene.patches.len();
    let served = lean_served(scene, &opts.params, saved, mode, params);
    let why = match path {
        ExchangePath::Dense => return Ok(None),
        ExchangePath::Hierarchical => {
            if !served {
                return Err(Error::Usage(
                    "exchange='hierarchical' serves gray solves with method auto or analytic and the direct \
                     solver, without saved view factors"
                        .into(),
                ));
            }
            "forced by exchange='hierarchical'".to_string()
        }
        ExchangePath::Auto => {
            if !served {
                return Ok(None);
            }
            let fits = exchange::dense::check_fits(n, 8.0, &scene.source).is_ok();
            let tight = opts.tolerance_given.is_some_and(|t| t < HIERARCHICAL_MIN_TOLERANCE);
            if fits && (n <= HIERARCHICAL_MIN_PATCHES || tight) {
                return Ok(None);
            }
            if fits {
                format!("{n} patches > {HIERARCHICAL_MIN_PATCHES}")
            } else {
                format!("{n} patches: the dense store would not fit in memory")
            }
        }
    };
    let tol = opts.tolerance_given.unwrap_or(exchange::hierarchy::DEFAULT_TOLERANCE);
    said.note(format!("exchange: hierarchical, heat-rate tolerance {tol:e} ({why})"));
    let vf = viewfactor::Params {
        tolerance: (tol * exchange::hierarchy::PAIR_TOLERANCE_SHARE).min(viewfactor::DEFAULT_TOLERANCE),
        ..opts.params.clone()
    };
    let run = solve::clustered::solve_scene(scene, &vf, mode, tol, params)?;
    note_enforcement(mode, &run.report, said);
    let s = &run.stats;
    said.note(format!(
        "{n} patches, {} cluster links, {} patch pairs, {} visibility rays, store {:.1} MB",
        s.links,
        s.leaf_pairs,
        s.rays,
        s.bytes as f64 / 1e6
    ));
    Ok(Some(run.solution))
}

/// Reads a view-factor CSV of the CLI for `scene` (`solve --viewfactors`).
pub fn read_viewfactors(path: &Path, scene: &Scene) -> Result<(ViewFactors, bool)> {
    report::read_vf::read_stamped(path, scene)
}

/// Builds the exchange matrix of `vf` and enforces `mode` (CLI `enforced`).
fn enforced(
    scene: &Scene,
    vf: &ViewFactors,
    mode: Enforce,
    rays: Option<usize>,
    said: &mut Said,
) -> Result<Exchange> {
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
        facts: facts(scene),
        ..Default::default()
    };
    let rep = exchange::enforce(&mut ex, &p).map_err(|e| with_obstruction_note(scene, e))?;
    note_enforcement(mode, &rep, said);
    Ok(ex)
}

/// The residuals before and after enforcement.
fn note_enforcement(mode: Enforce, rep: &exchange::enforce::EnforceReport, said: &mut Said) {
    said.note(format!("exchange before enforcement: {}", rep.before));
    said.note(format!("enforce {mode:?} ({}, {} iterations): {}", rep.method, rep.iterations, rep.after));
}

/// The exchange matrix at the output level (CLI `at_level`).
fn at_level(scene: &Scene, ex: &Exchange, level: Level) -> Exchange {
    if level == ex.level {
        return ex.clone();
    }
    let group: Vec<usize> = scene.patches.iter().map(|p| p.surface).collect();
    let names = scene.surfaces.iter().map(|s| s.name.clone()).collect();
    let areas = scene.surfaces.iter().map(|s| s.area).collect();
    ex.aggregate(&group, names, areas, Level::Surface)
}

/// Rays per patch when the method counts hits with equal weights.
fn hit_rays(p: &viewfactor::Params) -> Option<usize> {
    p.method.counts_hits().then_some(p.samples)
}

/// The geometry facts that leak hints are checked against.
fn facts(scene: &Scene) -> Option<std::sync::Arc<scene::orientation::SceneFacts>> {
    Some(std::sync::Arc::new(scene::orientation::SceneFacts::of(scene)))
}

/// Entries a method flagged, naming the pairs (CLI `warn_flags`).
fn warn_flags(scene: &Scene, flags: &[viewfactor::Flag], said: &mut Said) {
    let name = |p: usize| {
        let s = &scene.surfaces[scene.patches[p].surface];
        if s.patches.len() == 1 {
            s.name.clone()
        } else {
            scene.patch_name(p)
        }
    };
    for f in flags.iter().take(FLAGS_SHOWN) {
        said.warn(format!("{} entry {} -> {}: {}", f.method, name(f.from), name(f.to), f.note));
    }
    if flags.len() > FLAGS_SHOWN {
        said.warn(format!("{} more flagged entries not shown", flags.len() - FLAGS_SHOWN));
    }
}

/// A row sum for a message (CLI `row_sum`).
fn row_sum(s: f64) -> String {
    if s.abs() < 5e-7 {
        "0".into()
    } else {
        format!("{s:.6}")
    }
}

/// The leak warning of a closed scene's packed store (CLI `warn_dense_leaks`).
fn warn_dense_leaks(scene: &Scene, ex: &exchange::dense::DenseExchange, said: &mut Said) {
    if !scene.is_closed() {
        return;
    }
    let leaks = exchange::dense::leaks(&ex.t);
    if leaks.is_empty() {
        return;
    }
    let rows: Vec<(usize, f64)> = leaks.iter().map(|l| (l.0, l.1)).collect();
    leak_hint(scene, &exchange::leak::rows_from_triangle(&ex.t, &ex.names, &rows), said);
    let worst: Vec<String> =
        leaks.iter().take(5).map(|&(i, s, _)| format!("{} (row sum {})", ex.names[i], row_sum(s))).collect();
    said.warn(format!(
        "closed scene leaks: {} row(s) sum to less than 1 beyond the method's error; worst: {}",
        leaks.len(),
        worst.join(", ")
    ));
    if let Some(note) = scene::hints::obstruction_note(scene, &ex.names[leaks[0].0]) {
        said.warn(note);
    }
}

/// The leak warning of a closed scene's sparse matrix (CLI `warn_leaks`).
fn warn_leaks(scene: &Scene, vf: &ViewFactors, method: Method, tolerance: f64, said: &mut Said) {
    if !scene.is_closed() {
        return;
    }
    let ex = Exchange::from_viewfactors(vf);
    let mut leaks: Vec<(usize, f64)> =
        exchange::enforce::leaks(&ex).iter().map(|l| (l.node, l.row_sum)).collect();
    if leaks.is_empty() {
        let all_ladder = || vf.rows.iter().flatten().all(|e| e.method == MethodSet::ANALYTIC);
        if let Some(tol) = method.own_leak_tol(tolerance, all_ladder) {
            leaks = viewfactor::analytic::kernel::leaks(vf, tol);
        }
    }
    if leaks.is_empty() {
        return;
    }
    leak_hint(scene, &exchange::leak::rows_from_viewfactors(vf, &leaks), said);
    let worst: Vec<String> =
        leaks.iter().take(5).map(|&(i, s)| format!("{} (row sum {})", vf.names[i], row_sum(s))).collect();
    said.warn(format!(
        "closed scene leaks: {} row(s) sum to less than 1 beyond the method's error; worst: {}",
        leaks.len(),
        worst.join(", ")
    ));
    if let Some(note) = scene::hints::obstruction_note(scene, &vf.names[leaks[0].0]) {
        said.warn(note);
    }
}

/// The hint for leaking rows, when the geometry facts name a cause.
fn leak_hint(scene: &Scene, rows: &[exchange::leak::LeakRow], said: &mut Said) {
    let hint = exchange::leak::hint(&scene::orientation::SceneFacts::of(scene), rows);
    if !hint.is_empty() {
        said.warn(hint);
    }
}

/// Adds the obstruction note to a leak refusal (CLI `with_obstruction_note`).
fn with_obstruction_note(scene: &Scene, e: Error) -> Error {
    let Error::Input(mut ie) = e else { return e };
    if let Some(note) = ie.surface.as_deref().and_then(|n| scene::hints::obstruction_note(scene, n)) {
        ie.problem = format!("{}. Note: {note}", ie.problem);
    }
    Error::Input(ie)
}

/// Adds to a leak refusal of saved view factors that the file carries no fingerprint (CLI).
fn with_unstamped_note(e: Error, file: &Path) -> Error {
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
