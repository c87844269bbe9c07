//! The `solve` run on the hierarchical exchange ([`crate::exchange::hierarchy`]): links built
//! for the relative heat-rate tolerance, enforced (closure or capped scaling with the
//! ambient), solved by the same Jacobi-preconditioned CG as the dense path, and each patch's
//! heat rate given an error estimate: the links' direct errors carried through the
//! inter-reflections ([`super::dense::propagate_errors`]), plus the signed move of the closure
//! and of the links' sharing by area ([`super::dense::propagate_shift`]), plus the patch
//! pairs' independent errors (a surface's in quadrature, [`super::dense::surface_spread`]).
//!
//! Tight tolerances take two passes (Hanrahan–Salzman–Aupperle's refinement on B·F): a loose
//! first pass bounds every patch's radiosity (its solution ± its own error estimate), and the
//! final links are weighed against those ranges instead of the a-priori ones, so links
//! between surfaces of nearly equal radiosity stay coarse. The first pass's patch pairs are
//! reused.
//!
//! The boundary conditions reach the links only through a [`Budget`] built here ([`budget`]:
//! a-priori radiosity bounds and the heat-rate scale of the tolerance).
use super::{Params, Solution};
use crate::exchange::enforce::CLOSURE_TOL;
use crate::exchange::hierarchy::{Budget, Hierarchy, Stats};
use crate::exchange::{Enforce, EnforceParams, EnforceReport};
use crate::scene::{BoundaryCondition, Scene};
use crate::viewfactor::progress::Phase;
use crate::{Result, SIGMA};

/// Everything the hierarchical `solve` run produced.
#[derive(Debug, Clone)]
pub struct ClusteredRun {
    /// The per-patch solution, with heat-rate error estimates.
    pub solution: Solution,
    /// What enforcement did.
    pub report: EnforceReport,
    /// Build statistics.
    pub stats: Stats,
    /// The first pass of a two-pass run: its tolerance and build statistics.
    pub first: Option<(f64, Stats)>,
}

/// Tolerances at or below this take two passes (above it the first pass would cost more
/// than its sharper radiosity ranges save; validation/scale.md).
pub const TWO_PASS_BELOW: f64 = 3e-3;
/// The first pass runs at this multiple of the tolerance ...
pub const FIRST_PASS_LOOSENESS: f64 = 100.0;
/// ... but no looser than this: its links must still bound its own radiosities.
pub const FIRST_PASS_MAX_TOL: f64 = 3e-2;

/// The first pass's radiosity error estimates times this make the ranges: its bounds hold
/// for cluster means, single patches stray further (a link shares its exchange by area, a
/// first-order error per patch, while the link's own bound is fourth order between planar
/// clusters; 3.4× on the heated room of tests/heat/dense.rs, 2.4× on room_5k with first-order
/// links). The ranges only steer the final refinement — the final estimate uses the final
/// radiosities — and a wider margin costs little (room_10k at 1e-3: 1 → 3 adds 14 % links,
/// 1 % pairs, with first-order links).
pub const RANGE_MARGIN: f64 = 5.0;

/// Links for relative heat-rate tolerance `tol`, enforcement (`mode`) and the gray solve.
pub fn solve_scene(
    scene: &Scene,
    vf: &crate::viewfactor::Params,
    mode: Enforce,
    tol: f64,
    params: &Params,
) -> Result<ClusteredRun> {
    solve_scene_with(scene, vf, mode, tol, params, &mut |_| {})
}

/// As [`solve_scene`], saying to `phase` when the enforcement and the solve of the final links
/// start (the links, and a first pass where the tolerance asks for two, belong to the
/// view-factor phase the caller is in).
pub fn solve_scene_with(
    scene: &Scene,
    vf: &crate::viewfactor::Params,
    mode: Enforce,
    tol: f64,
    params: &Params,
    phase: &mut dyn FnMut(Phase),
) -> Result<ClusteredRun> {
    let (mut h, first) = if tol <= TWO_PASS_BELOW {
        let loose = (tol * FIRST_PASS_LOOSENESS).min(FIRST_PASS_MAX_TOL);
        let (bounds, h1) = radiosity_ranges(scene, vf, mode, loose, params)?;
        let stats = h1.stats.clone();
        let pairs = h1.into_pairs();
        let budget = budget_within(scene, bounds);
        let h = Hierarchy::build_bounded(scene, vf, tol, &budget, Some(pairs))?;
        (h, Some((loose, stats)))
    } else {
        (Hierarchy::build(scene, vf, tol, &budget(scene))?, None)
    };
    phase(Phase::Enforcement);
    let report = crate::exchange::enforce(&mut h, &enforce_params(scene, mode, true))?;
    phase(Phase::Solve);
    let mut solution = super::dense::solve_operator(scene, &h, params)?;
    let j: Vec<f64> = solution.results.iter().map(|r| r.radiosity).collect();
    let (direct, pairs) = h.heat_rate_error_parts(&j, e_amb(scene));
    let mut error = super::dense::propagate_errors(scene, &h, &direct)?;
    // The patch pairs' independent errors: per patch as the links, per surface in quadrature
    // where the surfaces are few enough for one solve each.
    let pairs = super::dense::propagate_errors(scene, &h, &pairs)?;
    for (e, s) in error.iter_mut().zip(&pairs) {
        *e += s;
    }
    let spread = super::dense::surface_spread(scene, &h, h.independent_pairs(), &j, e_amb(scene))?;
    solution.heat_rate_spread = spread
        .map(|t| (pairs, t.into_iter().map(|sd| crate::exchange::hierarchy::LEAK_ERR_SIGMAS * sd).collect()));
    // The closure's move and the links' sharing by area, with their signs: the closure undoes
    // part of what sharing moves between patches, and sharing cancels in part over a surface.
    let sharing = h.sharing_shift(&j, e_amb(scene));
    let moved: Vec<f64> = h.enforcement_shift(&j).iter().zip(&sharing).map(|(c, s)| c + s).collect();
    let shift = super::dense::propagate_shift(scene, &h, &moved)?;
    for (e, c) in error.iter_mut().zip(&shift) {
        *e += c.abs();
    }
    solution.heat_rate_error = Some(error);
    solution.heat_rate_shift = Some(shift);
    solution.info.solver = "conjugate gradients on the link hierarchy".into();
    report_bytes_sent();
    Ok(ClusteredRun { solution, report, stats: h.stats, first })
}

/// Under MPI with [`crate::distributed::STATS_VAR`] set: rank 0 prints the bytes each rank sent
/// in the hierarchy's sums (a collective: every rank calls it).
fn report_bytes_sent() {
    use crate::distributed::{reduce, STATS_VAR};
    if std::env::var_os(STATS_VAR).is_none() || !reduce::active() {
        return;
    }
    let sent = reduce::all_gather_u64(reduce::bytes_sent());
    if crate::distributed::writes_outputs() {
        for (r, b) in sent.iter().enumerate() {
            eprintln!("lambert: mpi: hierarchy rank {r} sent {b} bytes");
        }
    }
}

/// A first pass at tolerance `loose`: each patch's radiosity range (W/m²) — its solved J ±
/// [`RANGE_MARGIN`] × the pass's radiosity error estimate, within the a-priori bounds — and
/// the pass's hierarchy
/// (whose patch pairs the final pass reuses). The leak check is left to the final pass.
pub fn radiosity_ranges(
    scene: &Scene,
    vf: &crate::viewfactor::Params,
    mode: Enforce,
    loose: f64,
    params: &Params,
) -> Result<(Vec<(f64, f64)>, Hierarchy)> {
    let apriori = budget(scene);
    let mut h = Hierarchy::build(scene, vf, loose, &apriori)?;
    crate::exchange::enforce(&mut h, &enforce_params(scene, mode, false))?;
    let solution = super::dense::solve_operator(scene, &h, params)?;
    let j: Vec<f64> = solution.results.iter().map(|r| r.radiosity).collect();
    let mut e = h.heat_rate_errors(&j, e_amb(scene));
    for (e, c) in e.iter_mut().zip(h.enforcement_shift(&j)) {
        *e += c.abs();
    }
    let dj = super::dense::radiosity_errors(scene, &h, &e)?;
    let dj: Vec<f64> = dj.into_iter().map(|d| d * RANGE_MARGIN).collect();
    let bounds = (0..j.len())
        .map(|i| ((j[i] - dj[i]).max(apriori.radiosity[i].0), (j[i] + dj[i]).min(apriori.radiosity[i].1)))
        .collect();
    Ok((bounds, h))
}

/// The enforcement of `scene`'s links in `mode` to the closure tolerance; `check_leaks`
/// false for a first pass, whose links only bound the final pass's radiosities.
fn enforce_params(scene: &Scene, mode: Enforce, check_leaks: bool) -> EnforceParams {
    EnforceParams {
        mode,
        open: !scene.is_closed(),
        source: scene.source.clone(),
        tolerance: CLOSURE_TOL,
        facts: check_leaks.then(|| std::sync::Arc::new(crate::scene::orientation::SceneFacts::of(scene))),
        check_leaks,
        ..Default::default()
    }
}

/// Emissive power of the ambient of an open scene, W/m².
fn e_amb(scene: &Scene) -> Option<f64> {
    scene.ambient.map(|a| SIGMA * a.temperature.powi(4))
}

/// The a-priori [`Budget`] of `scene`'s boundary conditions: [`radiosity_bounds`] and the
/// heat-rate scale.
pub fn budget(scene: &Scene) -> Budget {
    budget_within(scene, radiosity_bounds(scene))
}

/// The [`Budget`] of `scene` with the radiosity ranges `radiosity` (per patch) and the
/// surfaces' weights under them.
fn budget_within(scene: &Scene, radiosity: Vec<(f64, f64)>) -> Budget {
    let surface_weight = super::apriori::surface_weights(scene, &radiosity);
    Budget { radiosity, heat_rate_scale: heat_rate_scale(scene), surface_weight }
}

/// Radiosity bounds of each patch before the solve (W/m²): the emissive powers' range, narrowed
/// by the view caps of the surfaces' bounding spheres ([`super::apriori`]).
pub fn radiosity_bounds(scene: &Scene) -> Vec<(f64, f64)> {
    super::apriori::radiosity_bounds(scene)
}

/// The largest heat rate to expect (W): A ε |E_b − Ē_b| of temperature surfaces (Ē_b their
/// area mean), A |q| of flux surfaces.
fn heat_rate_scale(scene: &Scene) -> f64 {
    let eb = |t: f64| SIGMA * t.powi(4);
    let (mut ae, mut a) = (0.0, 0.0);
    for s in &scene.surfaces {
        if let Some(BoundaryCondition::Temperature(t)) = s.condition {
            (ae, a) = (ae + s.area * eb(t), a + s.area);
        }
    }
    let mean = if a > 0.0 { ae / a } else { 0.0 };
    let q = scene
        .surfaces
        .iter()
        .map(|s| match s.condition {
            Some(BoundaryCondition::Temperature(t)) => s.area * s.emissivity * (eb(t) - mean).abs(),
            Some(BoundaryCondition::HeatFlux(q)) => s.area * q.abs(),
            None => 0.0,
        })
        .fold(0.0, f64::max);
    let amb = scene.ambient.map_or(0.0, |am| {
        scene
            .surfaces
            .iter()
            .map(|s| s.area * s.emissivity * (eb(am.temperature) - mean).abs())
            .fold(0.0, f64::max)
    });
    q.max(amb).max(f64::MIN_POSITIVE)
}
