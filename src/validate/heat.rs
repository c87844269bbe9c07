//! Heat-rate and temperature checks of enclosure problems, through the radiation solve.
//!
//! Tolerances: exact factors (analytic, a supplied exact file) give `HEAT_EXACT_REL`; an
//! approximate method's view-factor tolerances propagate through the case's sensitivities
//! (∂Q/∂F_IJ after the solve's enforcement, from cases/_generator): Σ_IJ |∂Q/∂F_IJ|·tol(F_IJ)
//! for deterministic methods (biases may align), the root sum of squares for Monte Carlo
//! (independent errors). Without sensitivities (patched cases) only analytic is checked.
use super::case::{Case, HeatRef};
use super::check::{Check, Status};
use super::tolerance::{self, HEAT_EXACT_REL};
use crate::plan::{Plan, PlanError, Request, Route, Silent, Store};
use crate::report;
use crate::scene::Scene;
use crate::viewfactor::{Method, Params, ViewFactors};
use crate::{Error, Result};
use std::time::{Duration, Instant};

/// Per-surface results of a solve: (name, heat rate W, temperature K), plus the ambient's
/// heat rate in open scenes.
#[derive(Debug, Clone, Default)]
pub struct HeatResults {
    /// (surface, heat_rate, temperature).
    pub surfaces: Vec<(String, f64, f64)>,
    /// Net heat the environment gives the scene, W.
    pub ambient: Option<f64>,
}

impl HeatResults {
    fn value(&self, h: &HeatRef, temperature: bool) -> Option<f64> {
        if h.surface == crate::solve::AMBIENT && !temperature {
            return self.ambient;
        }
        self.surfaces.iter().find(|s| s.0 == h.surface).map(|s| if temperature { s.2 } else { s.1 })
    }
}

/// Solves `scene` as `lambert solve` does, through its plan on `store`: patch-level factors
/// (a method's, or the exact file), the solve's default enforcement (closure for closed
/// scenes, reciprocity for open ones; maximum likelihood for hit counts), the gray solve,
/// results per surface. `rate`: the heat-rate tolerance of the clustered store. `None`: the
/// clustered store does not serve this request.
fn solve(scene: &Scene, source: Source, store: Store, rate: f64) -> Result<Option<(HeatResults, Route)>> {
    scene.check_boundary_conditions()?;
    let base = Request { store, ..Request::default() };
    let (req, saved) = match source {
        Source::Method(p) => {
            let tolerance = if store == Store::Hierarchical { rate } else { p.tolerance };
            let req = Request {
                method: p.method,
                samples: p.samples,
                resolution: p.resolution,
                tolerance: Some(tolerance),
                seed: p.seed,
                ..base
            };
            (req, None)
        }
        Source::File(path) => (
            Request { saved_viewfactors: true, ..base },
            Some(report::read_vf::read_viewfactors(path, scene)?),
        ),
    };
    let plan = match Plan::new(scene, &req) {
        Ok(plan) => plan,
        Err(PlanError::ClusteredUnserved) => return Ok(None),
        Err(PlanError::Other(e)) => return Err(e),
    };
    let out = plan.run_with(scene, saved.as_ref(), &mut Silent)?;
    let sol = out.solution.by_surface(scene);
    let res = HeatResults {
        surfaces: sol
            .names
            .iter()
            .zip(&sol.results)
            .map(|(n, r)| (n.clone(), r.heat_rate, r.temperature))
            .collect(),
        ambient: sol.ambient.map(|a| a.1),
    };
    Ok(Some((res, plan.route)))
}

/// Where the view factors come from.
enum Source<'a> {
    /// A method's run parameters.
    Method(&'a Params),
    /// An exact view-factor CSV.
    File(&'a std::path::Path),
}

/// (quantity label, reference, is temperature) of every heat reference.
fn quantities(case: &Case) -> Vec<(String, f64, bool, &HeatRef)> {
    let mut q = Vec::new();
    for h in &case.reference.heat {
        if let Some(v) = h.heat_rate {
            q.push((format!("Q({}) [W]", h.surface), v, false, h));
        }
        if let Some(v) = h.temperature {
            q.push((format!("T({}) [K]", h.surface), v, true, h));
        }
    }
    q
}

/// Heat tolerance of `method` on `h`: exact, or propagated through the sensitivities.
fn heat_tolerance(
    case: &Case,
    method: Option<Method>,
    params: Option<&Params>,
    vf: Option<&ViewFactors>,
    h: &HeatRef,
    reference: f64,
) -> Option<f64> {
    let exact = (HEAT_EXACT_REL + h.uncertainty) * reference.abs();
    let (Some(method), Some(params), Some(vf)) = (method, params, vf) else { return Some(exact) };
    if method == Method::Analytic {
        return Some(exact);
    }
    if h.sensitivity.is_empty() {
        return None;
    }
    // Monte Carlo errors are independent across pairs (root sum of squares); the other
    // methods' biases may align (plain sum).
    let (mut sum, mut squares) = (0.0, 0.0);
    for s in &h.sensitivity {
        let r = case.reference.viewfactors.iter().find(|r| r.from == s.from && r.to == s.to)?;
        let i = vf.names.iter().position(|n| *n == s.from)?;
        let j = vf.names.iter().position(|n| *n == s.to)?;
        let sigma = vf.rows[i].iter().find(|e| e.to as usize == j).map(|e| e.std_error).unwrap_or(0.0);
        let t = s.d.abs() * tolerance::view_factor(method, params, r, sigma, params.samples as f64);
        sum += t;
        squares += t * t;
    }
    Some(exact + if method.is_monte_carlo() { squares.sqrt() } else { sum })
}

/// Heat checks of one solve. `rate`: the route's own heat-rate tolerance relative to the
/// largest |heat rate| (the clustered store's; 0 for every-pair routes), added to the method's.
#[allow(clippy::too_many_arguments)]
fn checks(
    case: &Case,
    label: &str,
    method: Option<Method>,
    params: Option<&Params>,
    vf: Option<&ViewFactors>,
    result: Result<HeatResults>,
    rate: f64,
    time: Duration,
) -> Vec<Check> {
    let res = match result {
        Ok(r) => r,
        Err(e) => {
            let q: Vec<String> = quantities(case).into_iter().map(|q| q.0).collect();
            let status = match e {
                Error::Unsupported(why) => Status::NotApplicable(why),
                e => Status::Fail(e.to_string()),
            };
            return vec![Check::without_value(&case.name, &q.join(", "), label, status)];
        }
    };
    let mut out = Vec::new();
    let largest = quantities(case).iter().filter(|q| !q.2).fold(0.0f64, |m, q| m.max(q.1.abs()));
    for (quantity, reference, temperature, h) in quantities(case) {
        // A temperature is held to the same relative share as the heat rates.
        let route = rate * if temperature { reference.abs() } else { largest };
        let Some(value) = res.value(h, temperature) else {
            let why = format!("the solve has no surface '{}'", h.surface);
            out.push(Check::without_value(&case.name, &quantity, label, Status::Fail(why)));
            continue;
        };
        match heat_tolerance(case, method, params, vf, h, reference) {
            Some(tol) => {
                out.push(Check::compared(&case.name, quantity, label, value, reference, tol + route, time))
            }
            None => {
                let mut c = Check::without_value(
                    &case.name,
                    &quantity,
                    label,
                    Status::NotApplicable(
                        "no heat error model for approximate factors on a patched case".into(),
                    ),
                );
                c.value = Some(value);
                c.reference = Some(reference);
                out.push(c);
            }
        }
    }
    out
}

/// Relative heat-rate tolerance of the clustered store in validation: tight enough that the
/// links of a small case refine to its patch pairs, so the method's own error model holds.
pub const CLUSTERED_RATE: f64 = 1e-6;

/// Heat checks with `method`'s view factors (`vf`: its surface-level result, for σ) on every
/// route the CLI can take: the sparse store (labelled by the method), the packed triangle
/// (`METHOD packed`) and the clustered links (`METHOD clustered`) where they serve.
pub fn method_checks(
    case: &Case,
    scene: &Scene,
    method: Method,
    params: &Params,
    vf: &ViewFactors,
    time: Duration,
) -> Vec<Check> {
    if case.reference.heat.is_empty() {
        return Vec::new();
    }
    let mut out = Vec::new();
    for (store, suffix, route, rate) in [
        (Store::Sparse, "", Route::Sparse, 0.0),
        (Store::Dense, " packed", Route::Packed, 0.0),
        (Store::Hierarchical, " clustered", Route::Clustered, CLUSTERED_RATE),
    ] {
        let start = Instant::now();
        let result = solve(scene, Source::Method(params), store, CLUSTERED_RATE);
        let label = format!("{}{suffix}", method);
        let result = match result {
            Ok(Some((res, taken))) if taken == route => Ok(res),
            // The store does not serve this method (the sparse run covers it).
            Ok(_) => continue,
            Err(e) => Err(e),
        };
        let t = time + start.elapsed();
        out.extend(checks(case, &label, Some(method), Some(params), Some(vf), result, rate, t));
    }
    out
}

/// Heat checks with the case's exact view-factor file.
pub fn file_checks(case: &Case, scene: &Scene) -> Vec<Check> {
    let (Some(file), false) = (&case.reference.viewfactors_file, case.reference.heat.is_empty()) else {
        return Vec::new();
    };
    let start = Instant::now();
    let result = solve(scene, Source::File(&case.dir.join(file)), Store::Sparse, 0.0).and_then(|r| {
        r.map(|r| r.0).ok_or_else(|| Error::Compute("the sparse store is always served".into()))
    });
    checks(case, "vf-file", None, None, None, result, 0.0, start.elapsed())
}
