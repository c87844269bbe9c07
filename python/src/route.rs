//! The binding's computations on the library's plan (`lambert::plan`), the one the CLI runs:
//! the same method choice, stores, refusals and numbers. This file only checks the keyword
//! arguments (with their names in the messages), builds the plan's request and collects what
//! the CLI prints on stderr as `warnings` (handed to Python's `warnings` module) and `notes`
//! (the run summaries).
use lambert::exchange::{Enforce, EnforceReport};
use lambert::plan::{self, Goal, Plan, PlanError, Progress, Request, Route, Store};
use lambert::report;
use lambert::scene::{self, Scene};
use lambert::solve;
use lambert::viewfactor::{self, Flag, Level, Method, ViewFactors};
use lambert::{Error, Result};
use std::path::Path;

pub use lambert::viewfactor::limits::MAX_SAMPLES;
use lambert::viewfactor::limits::{tolerance as check_tolerance, RESOLUTIONS};

/// Options shared by `view_factors` and `solve`, checked as the CLI checks its flags.
#[derive(Debug, Clone)]
pub struct Options {
    /// The plan's request (goal and store set by the computation).
    request: Request,
    /// Report per patch.
    patches: bool,
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
        let method: Method = keyword("method", method)?;
        let mut request = Request { method, seed, ..Request::default() };
        if let Some(s) = samples {
            if s == 0 || s > MAX_SAMPLES {
                return Err(Error::Usage(format!("samples must be between 1 and {MAX_SAMPLES}, got {s}")));
            }
            request.samples = s;
        }
        if let Some(r) = resolution {
            if !RESOLUTIONS.contains(&r) {
                return Err(Error::Usage(format!(
                    "resolution must be between {} and {}",
                    RESOLUTIONS.start(),
                    RESOLUTIONS.end()
                )));
            }
            request.resolution = r;
        }
        if let Some(t) = tolerance {
            request.tolerance = Some(check_tolerance(t, "tolerance")?);
        }
        request.enforce = enforce.as_deref().map(|e| keyword::<Enforce>("enforce", e)).transpose()?;
        Ok(Self { request, patches })
    }

    /// Lets the view-factor engine draw its terminal progress bar.
    pub fn set_progress(&mut self, on: bool) {
        self.request.progress_bar = on;
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
    /// The scene's own warnings and the panels of an open scene that face away from all.
    fn scene(scene: &Scene) -> Self {
        let mut said = Said { warnings: scene.warnings.clone(), notes: Vec::new() };
        for f in scene::hints::facing_away(scene) {
            said.warnings.push(scene::hints::facing_away_warning(scene, &f));
        }
        said
    }

    /// The residuals before and after enforcement.
    fn enforcement(&mut self, mode: Enforce, rep: &EnforceReport) {
        self.notes.push(format!("exchange before enforcement: {}", rep.before));
        self.notes
            .push(format!("enforce {mode:?} ({}, {} iterations): {}", rep.method, rep.iterations, rep.after));
    }
}

/// The plan's progress sink of the binding: collects the method's warnings and flags.
struct Collect<'a> {
    scene: &'a Scene,
    warnings: Vec<String>,
}

impl Progress for Collect<'_> {
    fn phase(&mut self, _: plan::Phase) {}
    fn method_report(&mut self, warnings: &[String], flags: &[Flag]) {
        self.warnings.extend(warnings.iter().cloned());
        self.warnings.extend(plan::flag_warnings(self.scene, flags));
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

/// `lambert viewfactors` on `scene`.
pub fn view_factors(scene: &Scene, opts: Options) -> Result<VfRun> {
    let mut said = Said::scene(scene);
    let level = if opts.patches { Level::Patch } else { Level::Surface };
    let plan = Plan::new(scene, &Request { goal: Goal::ViewFactors { level }, ..opts.request })?;
    said.notes.extend(plan.scene_notes.iter().cloned());
    let mut sink = Collect { scene, warnings: Vec::new() };
    let out = plan.view_factors(scene, &mut sink)?;
    said.warnings.append(&mut sink.warnings);
    let d = &out.diagnostics;
    said.warnings.extend(d.leak_warnings.iter().cloned());
    if let Some(rep) = &d.enforcement {
        said.enforcement(plan.enforce, rep);
    }
    let store = if out.route == Route::Packed {
        format!(", dense store {:.1} MB", d.store_bytes as f64 / 1e6)
    } else {
        String::new()
    };
    let note = format!(
        "{} patches, {} pairs, {:.3} s, method {}{store}",
        scene.patches.len(),
        d.pairs,
        d.viewfactor_wall.as_secs_f64(),
        plan.viewfactors.method
    );
    let (store, raw_row_sums) =
        (if out.route == Route::Packed { "dense" } else { "sparse" }, out.raw_row_sums.clone());
    let vf = out.into_viewfactors();
    viewfactor::range::check(&vf)?;
    said.notes.push(note);
    Ok(VfRun { vf, raw_row_sums, store, said })
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

/// The value a keyword argument names, through the library's enum; an unknown name is refused
/// with the keyword in the message ("unknown exchange 'x'; expected one of auto, dense,
/// hierarchical").
pub fn keyword<T: lambert::choice::ValueEnum>(name: &str, s: &str) -> Result<T> {
    lambert::choice::parse(s).ok_or_else(|| Error::Usage(lambert::choice::unknown::<T>(name, s)))
}

/// `lambert solve` on `scene`; `saved`: view factors to use instead of computing them, with
/// whether they carried the scene's fingerprint and the file they came from (for messages).
pub fn solve(
    scene: &Scene,
    opts: Options,
    s: &SolveOptions,
    saved: Option<(ViewFactors, bool, Option<&Path>)>,
) -> Result<SolveRun> {
    let solver: solve::Solver = keyword("solver", &s.solver)?;
    let store: Store = keyword("exchange", &s.exchange)?;
    let request = Request { store, solver, saved_viewfactors: saved.is_some(), ..opts.request };
    if let (None, Some(t)) = (request.tolerance, scene.run_defaults.tolerance) {
        check_tolerance(t, &format!("{}: View3D eps", scene.source.display()))?;
    }
    scene.check_boundary_conditions()?;
    let mut said = Said::scene(scene);
    let plan = Plan::new(scene, &request).map_err(|e| match e {
        PlanError::ClusteredUnserved => Error::Usage(
            "exchange='hierarchical' serves gray solves with method auto or analytic and the direct solver, \
             without saved view factors"
                .into(),
        ),
        PlanError::Other(e) => e,
    })?;
    if plan.route == Route::Clustered {
        let why = match plan.reason {
            plan::Reason::Asked => "forced by exchange='hierarchical'".to_string(),
            r => r.to_string(),
        };
        if let plan::Tolerance::HeatRate { rate, .. } = plan.tolerance {
            said.notes.push(format!("exchange: hierarchical, heat-rate tolerance {rate:e} ({why})"));
        }
    }
    if let Some((vf, _, _)) = &saved {
        if opts.patches && vf.level == Level::Surface {
            return Err(Error::Usage(
                "patches=True needs patch-level view factors (computed or saved with patches=True)".into(),
            ));
        }
    }
    let mut sink = Collect { scene, warnings: Vec::new() };
    let out = match &saved {
        Some((vf, stamped, file)) => {
            plan.run_with(scene, Some(vf), &mut sink).map_err(|e| match (file, stamped) {
                (Some(file), false) => plan::with_unstamped_note(e, file),
                _ => e,
            })
        }
        None => plan.run(scene, &mut sink),
    }?;
    said.warnings.append(&mut sink.warnings);
    let d = &out.diagnostics;
    if let Some(rep) = &d.enforcement {
        said.enforcement(plan.enforce, rep);
    }
    let path = match (plan.route, &out.exchange) {
        (Route::Clustered, _) => "hierarchical",
        (_, Some(_)) => "sparse",
        (_, None) => "dense",
    };
    if let Some((s, _)) = &d.clustered {
        said.notes.push(format!(
            "{} patches, {} cluster links, {} patch pairs, {} visibility rays, store {:.1} MB",
            scene.patches.len(),
            s.links,
            s.leaf_pairs,
            s.rays,
            s.bytes as f64 / 1e6
        ));
    } else if path == "dense" {
        said.notes.push(format!(
            "{} patches, {} pairs, dense store {:.1} MB",
            scene.patches.len(),
            d.pairs,
            d.store_bytes as f64 / 1e6
        ));
    }
    Ok(SolveRun { solution: out.solution, path, said })
}

/// Reads a view-factor CSV of the CLI for `scene` (`solve --viewfactors`).
pub fn read_viewfactors(path: &Path, scene: &Scene) -> Result<(ViewFactors, bool)> {
    report::read_vf::read_stamped(path, scene)
}
