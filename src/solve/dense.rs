//! The lean dense solve: the net-radiation system K J = b (K = D − S̄ on the unknowns, black
//! surfaces eliminated, docs/literature.md §5) solved by Jacobi-preconditioned conjugate gradients
//! with the symmetric packed mat-vec of `crate::viewfactor::packed::PackedTriangular`. K is never assembled: the only N²
//! object is the triangle of exchange areas, read once per iteration. Under MPI each rank
//! holds a row block of it and every product adds the ranks' blocks in a fixed order
//! (`crate::exchange::rowblock`): every rank runs the same CG on the same numbers.
//!
//! - [`solve_gray`]: solve on an enforced [`DenseExchange`];
//! - [`solve_scene`]: view factors → enforcement → solve, the whole `solve` run on the lean
//!   path (`None` when the method needs the sparse store).
use super::system::RowKind;
use super::{Info, NodeResult, Params, Solution};
use crate::error::InputError;
use crate::exchange::dense::DenseExchange;
use crate::exchange::linalg::{cg, Linear, CG_TOL};
use crate::exchange::operator::Operator;
use crate::exchange::{Enforce, EnforceParams, EnforceReport};
use crate::scene::Scene;
use crate::viewfactor::progress::Phase;
use crate::viewfactor::Level;
use crate::{Error, Result, SIGMA};
use std::time::Instant;

/// Accepted residual when round-off stalls CG before `CG_TOL` (at which the heat rates agree
/// with a direct factorisation to ~1e-12: K is diagonally dominant wherever a temperature
/// anchors it): far below the 1e-9 energy balance.
pub const CG_STALL_TOL: f64 = 1e-12;
/// CG iterations allowed: a floor plus a share of the unknowns (convergence takes tens of
/// iterations on anchored enclosures; this only stops a runaway).
const SOLVE_CG_ITER_FLOOR: usize = 5000;

/// Everything the lean `solve` run produced.
#[derive(Debug, Clone)]
pub struct DenseRun {
    /// The per-patch solution.
    pub solution: Solution,
    /// What enforcement did.
    pub report: EnforceReport,
    /// Patch pairs evaluated by the view-factor kernel.
    pub pairs: u64,
    /// Bytes of the packed store (triangle and exceptions).
    pub store_bytes: usize,
    /// What the view-factor method reported about its own accuracy.
    pub warnings: Vec<String>,
    /// Entries the view-factor method flagged (reported on stderr).
    pub flags: Vec<crate::viewfactor::Flag>,
}

/// View factors, enforcement (`mode`) and the gray solve on the lean path; `None` when the
/// view-factor method needs the sparse store (Monte Carlo).
pub fn solve_scene(
    scene: &Scene,
    vf: &crate::viewfactor::Params,
    mode: Enforce,
    params: &Params,
) -> Result<Option<DenseRun>> {
    solve_scene_with(scene, vf, mode, params, &mut |_, _| {})
}

/// As [`solve_scene`], saying to `step` when the enforcement and the solve start, with the
/// store as built (the view-factor method's warnings and flagged entries are known by then).
pub fn solve_scene_with(
    scene: &Scene,
    vf: &crate::viewfactor::Params,
    mode: Enforce,
    params: &Params,
    step: &mut dyn FnMut(Phase, &DenseExchange),
) -> Result<Option<DenseRun>> {
    // Under MPI each rank keeps its row block of the store (`crate::exchange::rowblock`).
    let Some(mut ex) = crate::exchange::rowblock::build(scene, vf)? else { return Ok(None) };
    step(Phase::Enforcement, &ex);
    let facts = Some(std::sync::Arc::new(crate::scene::orientation::SceneFacts::of(scene)));
    let p = EnforceParams {
        mode,
        open: !scene.is_closed(),
        source: scene.source.clone(),
        facts,
        ..Default::default()
    };
    let report = crate::exchange::enforce(&mut ex, &p).map_err(|e| e.with_notes(&ex.t.warnings))?;
    step(Phase::Solve, &ex);
    let solution = solve_gray(scene, &ex, params)?;
    let flags = std::mem::take(&mut ex.t.flags);
    let warnings = std::mem::take(&mut ex.t.warnings);
    crate::exchange::rowblock::report(&ex.t);
    let store_bytes = crate::exchange::rowblock::total_bytes(&ex.t);
    Ok(Some(DenseRun { solution, report, pairs: ex.t.pairs, store_bytes, warnings, flags }))
}

/// Solves the gray net-radiation problem on the patches of `ex` (with its ambient column for
/// open scenes).
pub fn solve_gray(scene: &Scene, ex: &DenseExchange, params: &Params) -> Result<Solution> {
    solve_operator(scene, ex, params)
}

/// Solves the gray net-radiation problem on the patches of any exchange operator `t` (already
/// enforced: for open scenes it carries the ambient column).
pub fn solve_operator(scene: &Scene, t: &dyn Operator, params: &Params) -> Result<Solution> {
    let start = Instant::now();
    let (names, amb) = (t.names(), t.ambient());
    let n = t.len();
    if n != scene.patches.len() {
        return Err(InputError::file(
            &scene.source,
            format!("the exchange matrix has {n} nodes but the scene has {} patches", scene.patches.len()),
        )
        .into());
    }
    let sys = LeanSystem::new(scene, t)?;
    let LeanSystem { eps, rows, unknown, .. } = &sys;
    let e_amb = scene.ambient.map_or(0.0, |a| SIGMA * a.temperature.powi(4));
    let areas = t.areas();
    // Unknowns: every node but the black temperature nodes, whose J = E_b is known.
    let mut known = vec![0.0; n];
    let mut b = vec![0.0; n];
    for i in 0..n {
        let a = areas[i];
        match rows[i] {
            RowKind::Temperature(eb) if !unknown[i] => known[i] = eb,
            RowKind::Temperature(eb) => b[i] = a * eps[i] / (1.0 - eps[i]) * eb,
            RowKind::Flux(q) => b[i] = a * q,
        }
        b[i] += amb.map_or(0.0, |am| am[i]) * e_amb;
    }
    if unknown.iter().any(|u| !u) {
        let sk = t.matvec_scaled(None, &known);
        for i in (0..n).filter(|&i| unknown[i]) {
            b[i] += sk[i];
        }
    }
    let surface: Vec<usize> = scene.patches.iter().map(|p| p.surface).collect();
    super::system::check_anchored(scene, t, &surface, eps, rows)?;
    for i in (0..n).filter(|&i| !unknown[i]) {
        b[i] = 0.0;
    }
    let max_iter = SOLVE_CG_ITER_FLOOR + n;
    let (x, cg_info) = cg(&sys.linear(t), &sys.diag, &b, CG_TOL, max_iter);
    let (iterations, residual) = (cg_info.iterations, cg_info.residual);
    if !(residual <= CG_STALL_TOL) {
        return Err(Error::Compute(format!(
            "conjugate gradients stopped at relative residual {residual:.3e} after {iterations} iterations"
        )));
    }
    let _ = params;
    let j: Vec<f64> = (0..n).map(|i| if unknown[i] { x[i] } else { known[i] }).collect();
    let sj = t.matvec_scaled(None, &j);
    let mut results = Vec::with_capacity(n);
    for i in 0..n {
        let a = areas[i];
        let h = (sj[i] + amb.map_or(0.0, |am| am[i] * e_amb)) / a;
        let q = j[i] - h;
        let temperature = match rows[i] {
            RowKind::Temperature(eb) => (eb / SIGMA).powf(0.25),
            RowKind::Flux(qp) => {
                let eb = j[i] + (1.0 - eps[i]) / eps[i] * qp;
                if eb < 0.0 {
                    return Err(Error::Compute(format!(
                        "{}: the prescribed heat flux {qp} W/m² would need a negative emissive power",
                        names[i]
                    )));
                }
                (eb / SIGMA).powf(0.25)
            }
        };
        results.push(NodeResult {
            temperature,
            heat_flux: q,
            heat_rate: a * q,
            radiosity: j[i],
            irradiation: h,
        });
    }
    let ambient = scene.ambient.map(|a| {
        let heat = amb.map_or(0.0, |am| am.iter().zip(&j).map(|(s, j)| s * (e_amb - j)).sum());
        (a.temperature, heat)
    });
    let info = Info {
        solver: "packed conjugate gradients".into(),
        unknowns: unknown.iter().filter(|&&u| u).count(),
        iterations,
        residual,
        wall: start.elapsed(),
    };
    Ok(Solution {
        level: Level::Patch,
        names: names.to_vec(),
        areas: areas.to_vec(),
        emissivity: sys.eps,
        surface: scene.patches.iter().map(|p| p.surface).collect(),
        results,
        ambient,
        info,
        heat_rate_error: None,
        heat_rate_shift: None,
        heat_rate_spread: None,
    })
}

/// The net-radiation system K = D − S̄ of an operator's patches, restricted to the unknowns
/// (black temperature patches are known: J = E_b).
struct LeanSystem {
    /// Emissivity per patch.
    eps: Vec<f64>,
    /// Row kind per patch.
    rows: Vec<RowKind>,
    /// D: A/ρ on gray temperature rows, A on flux rows, 0 on known rows.
    d: Vec<f64>,
    /// True where J is unknown.
    unknown: Vec<bool>,
    /// 1 on unknown rows, 0 on known ones.
    mask: Vec<f64>,
    /// Jacobi diagonal of K (1 on known rows).
    diag: Vec<f64>,
}

impl LeanSystem {
    fn new(scene: &Scene, t: &dyn Operator) -> Result<Self> {
        let n = t.len();
        let (eps, rows) = row_kinds(scene)?;
        let areas = t.areas();
        let mut d = vec![0.0; n];
        let mut unknown = vec![true; n];
        for i in 0..n {
            match rows[i] {
                RowKind::Temperature(_) if eps[i] >= 1.0 => unknown[i] = false,
                RowKind::Temperature(_) => d[i] = areas[i] / (1.0 - eps[i]),
                RowKind::Flux(_) => d[i] = areas[i],
            }
        }
        let mask = unknown.iter().map(|&u| if u { 1.0 } else { 0.0 }).collect();
        let diag = (0..n).map(|i| if unknown[i] { d[i] - t.self_term(i) } else { 1.0 }).collect();
        Ok(LeanSystem { eps, rows, d, unknown, mask, diag })
    }

    /// K as a linear operator: K x = D x − S̄ x on the unknowns (x is 0 on known rows, so is
    /// K x).
    fn linear<'a>(&'a self, t: &'a dyn Operator) -> Linear<impl Fn(&[f64], &mut [f64]) + Sync + 'a> {
        Linear {
            n: t.len(),
            apply: move |x: &[f64], y: &mut [f64]| {
                let sx = t.matvec_scaled(None, x);
                for i in 0..x.len() {
                    y[i] = self.mask[i] * (self.d[i] * x[i] - sx[i]);
                }
            },
        }
    }

    /// K⁻¹ r on the unknowns (r masked), to the error estimates' accuracy.
    fn solve(&self, t: &dyn Operator, r: &[f64]) -> Vec<f64> {
        let rhs: Vec<f64> = r.iter().zip(&self.mask).map(|(r, m)| r * m).collect();
        cg(&self.linear(t), &self.diag, &rhs, ERROR_CG_TOL, SOLVE_CG_ITER_FLOOR + r.len()).0
    }
}

/// Per patch: emissivity and row kind (T or q), or the error of a surface without a boundary
/// condition.
fn row_kinds(scene: &Scene) -> Result<(Vec<f64>, Vec<RowKind>)> {
    let mut eps = Vec::with_capacity(scene.patches.len());
    let mut rows = Vec::with_capacity(scene.patches.len());
    for p in &scene.patches {
        let surf = &scene.surfaces[p.surface];
        let condition = super::system::condition(scene, p.surface)?;
        eps.push(surf.emissivity);
        rows.push(
            super::Node { surface: p.surface, area: 0.0, emissivity: surf.emissivity, condition }.row_kind(),
        );
    }
    Ok((eps, rows))
}

/// Carries per-patch errors `e` of the exchange term (W, |δS J|) through the inter-reflections:
/// K δJ = δS J with K = D − S an M-matrix (K⁻¹ ≥ 0), so |δJ| ≤ K⁻¹ e, and a temperature
/// patch's heat rate A ε/ρ (E_b − J) moves by at most A ε/ρ · (K⁻¹ e)_i. A black patch's error
/// is its direct e_i; a flux patch's heat rate is prescribed (its temperature carries the
/// error). Returns the heat-rate error bound per patch, W.
pub fn propagate_errors(scene: &Scene, t: &dyn Operator, e: &[f64]) -> Result<Vec<f64>> {
    let sys = LeanSystem::new(scene, t)?;
    let y = sys.solve(t, e);
    let areas = t.areas();
    Ok((0..t.len())
        .map(|i| match sys.rows[i] {
            RowKind::Temperature(_) if !sys.unknown[i] => e[i],
            RowKind::Temperature(_) => areas[i] * sys.eps[i] / (1.0 - sys.eps[i]) * y[i].max(0.0),
            RowKind::Flux(_) => 0.0,
        })
        .collect())
}

/// Per-patch bound on the radiosity error (W/m²) from direct errors `e` (W), carried through
/// the inter-reflections as in [`propagate_errors`]: zero on black temperature patches
/// (J = E_b), the irradiation error on flux patches.
pub fn radiosity_errors(scene: &Scene, t: &dyn Operator, e: &[f64]) -> Result<Vec<f64>> {
    let sys = LeanSystem::new(scene, t)?;
    let y = sys.solve(t, e);
    Ok((0..t.len()).map(|i| if sys.unknown[i] { y[i].max(0.0) } else { 0.0 }).collect())
}

/// Heat-rate moves (W, signed) of a change `c` of each patch's net exchange Σ_j δs_ij (J_j − J_i)
/// at fixed J, carried through the inter-reflections to first order: K δJ = c, a gray
/// temperature patch moves by −A ε/ρ δJ_i, a black one by −c_i − (S̄ δJ)_i, a flux patch not
/// at all (its temperature moves).
pub fn propagate_shift(scene: &Scene, t: &dyn Operator, c: &[f64]) -> Result<Vec<f64>> {
    let sys = LeanSystem::new(scene, t)?;
    let y = sys.solve(t, c);
    let sy = t.matvec_scaled(None, &y);
    let areas = t.areas();
    Ok((0..t.len())
        .map(|i| match sys.rows[i] {
            RowKind::Temperature(_) if !sys.unknown[i] => -c[i] - sy[i],
            RowKind::Temperature(_) => -areas[i] * sys.eps[i] / (1.0 - sys.eps[i]) * y[i],
            RowKind::Flux(_) => 0.0,
        })
        .collect())
}

/// Surfaces above this count keep the per-patch view of independent pair errors (one solve of
/// K per surface).
pub const SPREAD_MAX_SURFACES: usize = 64;

/// Per surface, the standard deviation (W) of its heat rate from independent errors of pair
/// values (`pairs`: patch a, patch b, variance of s_ab), carried through the
/// inter-reflections to first order as in [`propagate_shift`]: an error δs moves the net
/// exchange of a by δs (J_b − J_a) and of b by δs (J_a − J_b) (in an open scene, where the
/// ambient takes the rest, by δs (J_b − E_amb) and δs (J_a − E_amb)), and surface t's heat rate
/// by δs (x_a u_t(a) + x_b u_t(b)) with u_t = Pᵀ 1_t the adjoint of the shift map, one solve
/// of the symmetric K per surface. A pair within one surface moves that surface's heat rate
/// only through the reflections, which a per-patch sum of standard errors counts in full.
/// `None` above [`SPREAD_MAX_SURFACES`] surfaces.
pub fn surface_spread(
    scene: &Scene,
    t: &dyn Operator,
    pairs: impl Iterator<Item = (u32, u32, f64)> + Clone,
    j: &[f64],
    e_amb: Option<f64>,
) -> Result<Option<Vec<f64>>> {
    let m = scene.surfaces.len();
    if m > SPREAD_MAX_SURFACES {
        return Ok(None);
    }
    let sys = LeanSystem::new(scene, t)?;
    let areas = t.areas();
    let n = t.len();
    let surface: Vec<usize> = scene.patches.iter().map(|p| p.surface).collect();
    let black = |i: usize| matches!(sys.rows[i], RowKind::Temperature(_)) && !sys.unknown[i];
    let mut out = vec![0.0; m];
    for (s, sd) in out.iter_mut().enumerate() {
        if !surface.contains(&s) {
            continue;
        }
        // δQ_s = −(H 1_s + S̄ B 1_s)ᵀ y − (B 1_s)ᵀ c with K y = c on the unknowns: H the gray
        // temperature rows' A ε/ρ, B the black rows.
        let b1: Vec<f64> = (0..n).map(|i| if surface[i] == s && black(i) { 1.0 } else { 0.0 }).collect();
        let sb = t.matvec_scaled(None, &b1);
        let r: Vec<f64> = (0..n)
            .map(|i| {
                let h = match sys.rows[i] {
                    RowKind::Temperature(_) if surface[i] == s && sys.unknown[i] => {
                        areas[i] * sys.eps[i] / (1.0 - sys.eps[i])
                    }
                    _ => 0.0,
                };
                h + sb[i]
            })
            .collect();
        let y = sys.solve(t, &r);
        let u: Vec<f64> = (0..n).map(|i| -sys.mask[i] * y[i] - b1[i]).collect();
        let var: f64 = pairs
            .clone()
            .map(|(a, b, v)| {
                let (a, b) = (a as usize, b as usize);
                let (xa, xb) = match e_amb {
                    Some(ea) => (j[b] - ea, j[a] - ea),
                    None => (j[b] - j[a], j[a] - j[b]),
                };
                v * (xa * u[a] + xb * u[b]).powi(2)
            })
            .sum();
        *sd = var.sqrt();
    }
    Ok(Some(out))
}

/// Relative residual of the error propagation solve (an estimate needs two digits).
const ERROR_CG_TOL: f64 = 1e-6;
