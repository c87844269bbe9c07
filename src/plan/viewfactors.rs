//! The view-factor goal of a plan ([`Goal::ViewFactors`]): the matrix at a level, enforced
//! when asked, with the leak check of a closed scene; nothing here prints.
//!
//! Map:
//! - `plan`: the route (packed triangle where it serves, sparse rows otherwise), the
//!   enforcement default and the scene file's settings.
//! - [`Plan::view_factors`]: runs it; [`VfOutcome`] holds the [`Matrix`], the raw row sums
//!   and the [`Diagnostics`] (method warnings, flags, leak warnings, enforcement).
//! - [`flag_warnings`]: a run's flagged entries in words.
use super::{enforced, hit_rays, with_obstruction_note, Diagnostics, Goal, Phase, Plan, Progress, Reason};
use super::{factor_tolerance, Request, Route, Tolerance};
use crate::exchange::{self, Enforce, EnforceParams, Exchange};
use crate::scene::{self, Scene};
use crate::solve;
use crate::viewfactor::{self, packed::PackedTriangular, Entry, Flag, Level, Method, MethodSet, ViewFactors};
use crate::Result;
use std::time::{Duration, Instant};

/// Output surfaces above which a per-surface matrix is kept in the packed store (its sparse
/// per-surface rows would cost more than the packed patch pairs).
pub const LEAN_SURFACES: usize = 512;
/// Flagged entries said at most this many at a time (the count is always given).
pub const FLAGS_SHOWN: usize = 10;
/// Worst leaking rows named in a leak warning.
const LEAKS_SHOWN: usize = 5;

/// The view factors of a view-factor plan.
#[derive(Debug, Clone)]
pub enum Matrix {
    /// The packed triangle of exchange areas s̄_ij (enforced when asked), one row per patch;
    /// `names` names its rows (patches, or surfaces where each surface is one patch).
    Packed {
        /// The exchange areas.
        triangle: PackedTriangular,
        /// Row names.
        names: Vec<String>,
    },
    /// Sparse rows at the asked level.
    Rows(ViewFactors),
}

/// A view-factor run's result.
#[derive(Debug, Clone)]
pub struct VfOutcome {
    /// The route that computed it ([`Route::Packed`] or [`Route::Sparse`]).
    pub route: Route,
    /// Level of the rows.
    pub level: Level,
    /// The matrix.
    pub matrix: Matrix,
    /// Σ_j F_ij per patch before enforcement.
    pub raw_row_sums: Vec<f64>,
    /// A closed scene's worst |row sum − 1| with its row's name and level (the packed store's
    /// rows are patches); `None` for an open or empty scene.
    pub worst_row: Option<(f64, String, Level)>,
    /// What the run reported.
    pub diagnostics: Diagnostics,
}

/// The view-factor plan of `req` at `level` (`req.goal` is [`Goal::ViewFactors`]).
pub(super) fn plan(scene: &Scene, req: &Request, level: Level) -> Plan {
    let fallback = if scene.run_defaults.closure { Enforce::Closure } else { Enforce::None };
    let mode = req.enforce.unwrap_or(fallback);
    let factor = factor_tolerance(scene, req);
    let mut scene_notes = Vec::new();
    if let (None, Some(t)) = (req.tolerance, scene.run_defaults.tolerance) {
        scene_notes.push(format!("tolerance {t} from the scene file (View3D eps)"));
    }
    if req.enforce.is_none() && scene.run_defaults.closure {
        scene_notes
            .push("enforce closure: the scene file declares a closed enclosure (View3D encl = 1)".into());
    }
    let m = req.method;
    let kernel = !m.is_monte_carlo() && (m.is_symmetric() || mode != Enforce::None);
    let wanted = level == Level::Patch || mode != Enforce::None || scene.surfaces.len() > LEAN_SURFACES;
    let (route, reason) = match (kernel, wanted) {
        (false, _) => (Route::Sparse, Reason::OnlySparse),
        (true, false) => (Route::Sparse, Reason::FewSurfaces),
        (true, true) => (Route::Packed, Reason::PackedRows),
    };
    Plan {
        goal: Goal::ViewFactors { level },
        route,
        reason,
        tolerance: Tolerance::Factor(factor),
        enforce: mode,
        viewfactors: viewfactor::Params {
            method: m,
            samples: req.samples,
            resolution: req.resolution,
            tolerance: factor,
            seed: req.seed,
            progress: req.progress_bar,
        },
        solve: solve::Params { solver: req.solver, ..solve::Params::default() },
        scene_notes,
    }
}

impl Plan {
    /// Runs a view-factor plan on `scene` (the scene it was made for).
    pub fn view_factors(&self, scene: &Scene, progress: &mut dyn Progress) -> Result<VfOutcome> {
        let Goal::ViewFactors { level } = self.goal else {
            return Err(crate::Error::Usage(
                "a solve plan runs with Plan::run, not Plan::view_factors".into(),
            ));
        };
        let start = Instant::now();
        super::enter_viewfactors(progress, true);
        let mut out = match self.route {
            Route::Packed => match self.packed(scene, level, progress)? {
                Some(out) => out,
                None => self.rows(scene, level, progress)?,
            },
            _ => self.rows(scene, level, progress)?,
        };
        out.diagnostics.wall = start.elapsed();
        Ok(out)
    }

    /// The packed route; `None` when the method has no row kernel for this scene.
    fn packed(&self, scene: &Scene, level: Level, progress: &mut dyn Progress) -> Result<Option<VfOutcome>> {
        let start = Instant::now();
        let Some(mut ex) = exchange::dense::build(scene, &self.viewfactors)? else { return Ok(None) };
        let wall = start.elapsed();
        let mut d = Diagnostics {
            warnings: ex.t.warnings.clone(),
            flags: ex.t.flags.clone(),
            pairs: ex.t.pairs,
            viewfactor_wall: wall,
            ..Diagnostics::default()
        };
        progress.method_report(&d.warnings, &d.flags);
        let open = !scene.is_closed();
        if self.enforce == Enforce::None {
            d.leak_warnings = packed_leak_warnings(scene, &ex);
        } else {
            super::enter(progress, Phase::Enforcement);
            let p = EnforceParams {
                mode: self.enforce,
                open,
                source: scene.source.clone(),
                facts: Some(std::sync::Arc::new(scene::orientation::SceneFacts::of(scene))),
                ..Default::default()
            };
            let rep = exchange::enforce(&mut ex, &p).map_err(|e| with_obstruction_note(scene, e))?;
            d.enforcement = Some(rep);
        }
        let worst_row = packed_worst_row(scene, &ex.t, d.enforcement.is_some());
        let raw_row_sums = ex.t.raw_row_sums.iter().zip(&ex.t.areas).map(|(s, a)| s / a).collect();
        let one_patch_each = scene.surfaces.iter().all(|s| s.patches.len() == 1);
        let matrix = if level == Level::Patch || one_patch_each {
            let names = match level {
                Level::Patch => std::mem::take(&mut ex.names),
                Level::Surface => scene.surfaces.iter().map(|s| s.name.clone()).collect(),
            };
            d.store_bytes = ex.t.bytes();
            Matrix::Packed { triangle: ex.t, names }
        } else {
            d.store_bytes = ex.t.bytes();
            Matrix::Rows(exchange::dense::to_surface_viewfactors(&ex, scene, wall))
        };
        Ok(Some(VfOutcome { route: Route::Packed, level, matrix, raw_row_sums, worst_row, diagnostics: d }))
    }

    /// The sparse route: rows at `level`, or patch rows enforced and then summed to `level`
    /// (S_IJ = Σ S_ij keeps reciprocity and closure).
    fn rows(&self, scene: &Scene, level: Level, progress: &mut dyn Progress) -> Result<VfOutcome> {
        let mut d = Diagnostics::default();
        let (vf, raw_row_sums) = if self.enforce == Enforce::None {
            let vf = viewfactor::compute(scene, &self.viewfactors, level)?;
            d.warnings = vf.warnings.clone();
            d.flags = vf.flags.clone();
            progress.method_report(&d.warnings, &d.flags);
            d.leak_warnings = leak_warnings(scene, &vf, self.viewfactors.method, self.viewfactors.tolerance);
            let sums = vf.patch_row_sums.clone();
            (vf, sums)
        } else {
            let raw = viewfactor::compute(scene, &self.viewfactors, Level::Patch)?;
            d.warnings = raw.warnings.clone();
            d.flags = raw.flags.clone();
            progress.method_report(&d.warnings, &d.flags);
            super::enter(progress, Phase::Enforcement);
            let (ex, rep) = enforced(scene, &raw, self.enforce, hit_rays(&self.viewfactors))?;
            d.enforcement = Some(rep);
            let mut vf = at_level(scene, &ex, level).to_viewfactors(raw.wall);
            vf.pairs = raw.pairs;
            (vf, raw.patch_row_sums)
        };
        d.pairs = vf.pairs;
        d.viewfactor_wall = vf.wall;
        let worst_row = rows_worst_row(scene, &vf);
        let matrix = Matrix::Rows(vf);
        Ok(VfOutcome { route: Route::Sparse, level, matrix, raw_row_sums, worst_row, diagnostics: d })
    }
}

impl VfOutcome {
    /// The matrix as sparse rows (a packed triangle's zeros without an error skipped, as its
    /// CSV writer skips them).
    pub fn into_viewfactors(self) -> ViewFactors {
        match self.matrix {
            Matrix::Rows(vf) => vf,
            Matrix::Packed { triangle, names } => {
                triangle_viewfactors(&triangle, names, self.level, self.diagnostics.viewfactor_wall)
            }
        }
    }

    /// [`VfOutcome::into_viewfactors`] of a borrowed outcome (a copy).
    pub fn to_viewfactors(&self) -> ViewFactors {
        match &self.matrix {
            Matrix::Rows(vf) => vf.clone(),
            Matrix::Packed { triangle, names } => {
                triangle_viewfactors(triangle, names.clone(), self.level, self.diagnostics.viewfactor_wall)
            }
        }
    }
}

/// The worst |row sum − 1| of a closed scene's packed store, with its patch's name.
fn packed_worst_row(scene: &Scene, t: &PackedTriangular, enforced: bool) -> Option<(f64, String, Level)> {
    if !scene.is_closed() || t.n == 0 {
        return None;
    }
    let sums = if enforced { t.row_sums() } else { t.raw_row_sums.clone() };
    let (e, at) = worst(sums.iter().zip(&t.areas).map(|(s, a)| (s / a - 1.0).abs()));
    Some((e, scene.patch_name(at), Level::Patch))
}

/// The worst |row sum − 1| of a closed scene's rows at their level, with the row's name.
fn rows_worst_row(scene: &Scene, vf: &ViewFactors) -> Option<(f64, String, Level)> {
    if !scene.is_closed() || scene.patches.is_empty() {
        return None;
    }
    let (e, at) = match vf.level {
        Level::Patch => vf.max_patch_row_error(),
        Level::Surface => worst(vf.row_sums().iter().map(|s| (s - 1.0).abs())),
    };
    Some((e, vf.names[at].clone(), vf.level))
}

/// The largest value of `errs` and its index (the first of equals; 0 when empty).
fn worst(errs: impl Iterator<Item = f64>) -> (f64, usize) {
    errs.enumerate().map(|(i, e)| (e, i)).fold((0.0, 0), |a, b| if b.0 > a.0 { b } else { a })
}

/// The view factors F_ij = s̄_ij / A_i of a packed store as sparse rows (zeros without an error
/// skipped).
fn triangle_viewfactors(
    t: &PackedTriangular,
    names: Vec<String>,
    level: Level,
    wall: Duration,
) -> ViewFactors {
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
    ViewFactors {
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
    }
}

/// The exchange matrix at the output level (patches as they are, or summed per surface).
fn at_level(scene: &Scene, ex: &Exchange, level: Level) -> Exchange {
    if level == ex.level {
        return ex.clone();
    }
    let group: Vec<usize> = scene.patches.iter().map(|p| p.surface).collect();
    let names = scene.surfaces.iter().map(|s| s.name.clone()).collect();
    let areas = scene.surfaces.iter().map(|s| s.area).collect();
    ex.aggregate(&group, names, areas, Level::Surface)
}

/// The entries a method flagged (error not bounded, receiver cut), naming the pairs; at most
/// `FLAGS_SHOWN`, then the count of the rest.
pub fn flag_warnings(scene: &Scene, flags: &[Flag]) -> Vec<String> {
    // A surface of one patch is named as itself.
    let name = |p: usize| {
        let s = &scene.surfaces[scene.patches[p].surface];
        if s.patches.len() == 1 {
            s.name.clone()
        } else {
            scene.patch_name(p)
        }
    };
    let mut out: Vec<String> = flags
        .iter()
        .take(FLAGS_SHOWN)
        .map(|f| format!("{} entry {} -> {}: {}", f.method, name(f.from), name(f.to), f.note))
        .collect();
    if flags.len() > FLAGS_SHOWN {
        out.push(format!("{} more flagged entries not shown", flags.len() - FLAGS_SHOWN));
    }
    out
}

/// A row sum for a message: six decimals, and a sum that rounds to zero (a surface that sees
/// nothing, with round-off of either sign) as `0`, never `-0.000000`.
fn row_sum(s: f64) -> String {
    if s.abs() < 5e-7 {
        "0".into()
    } else {
        format!("{s:.6}")
    }
}

/// The leak warnings of a closed scene whose `leaks` (row, row sum; worst first) are named by
/// `names`: the geometry's hint, the worst rows, and the obstruction note of the worst.
fn leak_lines(
    scene: &Scene,
    rows: &[exchange::leak::LeakRow],
    leaks: &[(usize, f64)],
    names: &[String],
) -> Vec<String> {
    let mut out = Vec::new();
    let hint = exchange::leak::hint(&scene::orientation::SceneFacts::of(scene), rows);
    if !hint.is_empty() {
        out.push(hint);
    }
    let worst: Vec<String> = leaks
        .iter()
        .take(LEAKS_SHOWN)
        .map(|&(i, s)| format!("{} (row sum {})", names[i], row_sum(s)))
        .collect();
    out.push(format!(
        "closed scene leaks: {} row(s) sum to less than 1 beyond the method's error; worst: {}",
        leaks.len(),
        worst.join(", ")
    ));
    out.extend(scene::hints::obstruction_note(scene, &names[leaks[0].0]));
    out
}

/// Leak warnings of the packed store of a closed scene (the general thresholds).
fn packed_leak_warnings(scene: &Scene, ex: &exchange::dense::DenseExchange) -> Vec<String> {
    if !scene.is_closed() {
        return Vec::new();
    }
    let leaks: Vec<(usize, f64)> = exchange::enforce::leaks(ex).iter().map(|l| (l.node, l.row_sum)).collect();
    if leaks.is_empty() {
        return Vec::new();
    }
    let rows = exchange::ranks::rows_from_triangle(&ex.t, &ex.names, &leaks);
    leak_lines(scene, &rows, &leaks, &ex.names)
}

/// Leak warnings of a closed scene's sparse rows; an exact method is held to its own error.
fn leak_warnings(scene: &Scene, vf: &ViewFactors, method: Method, tolerance: f64) -> Vec<String> {
    if !scene.is_closed() {
        return Vec::new();
    }
    let ex = Exchange::from_viewfactors(vf);
    let mut leaks: Vec<(usize, f64)> =
        exchange::enforce::leaks(&ex).iter().map(|l| (l.node, l.row_sum)).collect();
    // An exact method's error is far below the general threshold: check against its own.
    if leaks.is_empty() {
        let all_ladder = || vf.rows.iter().flatten().all(|e| e.method == MethodSet::ANALYTIC);
        if let Some(tol) = method.own_leak_tol(tolerance, all_ladder) {
            leaks = viewfactor::analytic::kernel::leaks(vf, tol);
        }
    }
    if leaks.is_empty() {
        return Vec::new();
    }
    let rows = exchange::leak::rows_from_viewfactors(vf, &leaks);
    leak_lines(scene, &rows, &leaks, &vf.names)
}
