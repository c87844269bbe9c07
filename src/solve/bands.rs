//! Semi-gray (multi-band) radiation (docs/literature.md §5): band k covers [λ_k, λ_{k+1}) µm, each
//! surface has a band emissivity ε_ik, and E_bik = f_k(T_i) σT_i⁴ ([`super::planck`]).
//!
//! Every band is a gray problem on the same S with all rows in temperature form (flux nodes
//! use their current temperature), so each K_k = D_k − S is SPD and factorised once. Unknown
//! temperatures of flux nodes couple the bands: Newton on T solves Σ_k q_ik(T) = q_i, with the
//! exact Jacobian from one extra right-hand side per flux node and band (same factors).
use super::direct::{self, Factor};
use super::system::{self, Node, RowKind};
use super::{Info, NodeResult, Params, Solution};
use crate::error::InputError;
use crate::exchange::Exchange;
use crate::scene::{BoundaryCondition, Scene};
use crate::{Error, Result, SIGMA};
use faer::Mat;
use std::time::Instant;

/// Newton stops when every flux residual is below this fraction of σT_max⁴ (W/m²): far
/// below the 1e-9 energy-balance tolerance.
pub const NEWTON_TOL: f64 = 1e-12;
/// Newton steps allowed (quadratic convergence needs < 10 from the gray start).
const BAND_MAX_NEWTON: usize = 60;
/// Largest number of flux-condition nodes for the dense Newton Jacobian.
pub const MAX_FLUX_NODES: usize = 3000;

/// One wavelength band, µm.
#[derive(Debug, Clone, PartialEq)]
pub struct Band {
    /// Name (e.g. "solar").
    pub name: String,
    /// Lower wavelength limit, µm.
    pub lower: f64,
    /// Upper wavelength limit, µm (∞ allowed).
    pub upper: f64,
}

/// Bands and per-surface band emissivities (`emissivity[surface][band]`).
#[derive(Debug, Clone, PartialEq)]
pub struct BandSpec {
    /// Contiguous bands from 0 to ∞.
    pub bands: Vec<Band>,
    /// ε_ik per surface and band.
    pub emissivity: Vec<Vec<f64>>,
}

impl From<&crate::scene::bands::Spectral> for BandSpec {
    fn from(s: &crate::scene::bands::Spectral) -> Self {
        let bands =
            s.bands.iter().map(|b| Band { name: b.name.clone(), lower: b.lower, upper: b.upper }).collect();
        BandSpec { bands, emissivity: s.emissivity.clone() }
    }
}

impl BandSpec {
    /// Checks contiguity from 0 to ∞ and every ε in (0, 1]; names file and surface.
    pub fn validate(&self, scene: &Scene) -> Result<()> {
        let bad = |p: String| -> Error { InputError::file(&scene.source, p).into() };
        let b = &self.bands;
        if b.is_empty() {
            return Err(bad("[[band]]: at least one band is needed".into()));
        }
        if b[0].lower != 0.0 || b[b.len() - 1].upper != f64::INFINITY {
            return Err(bad(
                "[[band]]: the bands must start at 0 µm and the last must have no upper limit".into()
            ));
        }
        for (k, w) in b.windows(2).enumerate() {
            if w[0].upper != w[1].lower
                || w[0].lower.partial_cmp(&w[0].upper) != Some(std::cmp::Ordering::Less)
            {
                return Err(bad(format!(
                    "[[band]] '{}' (#{k}): bands must be contiguous and increasing",
                    w[0].name
                )));
            }
        }
        for (s, e) in self.emissivity.iter().enumerate() {
            let name = scene.surfaces.get(s).map_or("?", |x| x.name.as_str());
            if e.len() != b.len() {
                return Err(InputError::surface(
                    &scene.source,
                    name,
                    format!("emissivity_bands has {} values for {} bands", e.len(), b.len()),
                )
                .into());
            }
            if let Some(v) = e.iter().find(|v| !(**v > 0.0 && **v <= 1.0)) {
                return Err(InputError::surface(
                    &scene.source,
                    name,
                    format!("band emissivity {v} is outside (0, 1]"),
                )
                .into());
            }
        }
        if self.emissivity.len() != scene.surfaces.len() {
            return Err(bad(format!(
                "band emissivities for {} of {} surfaces",
                self.emissivity.len(),
                scene.surfaces.len()
            )));
        }
        Ok(())
    }
}

/// One band's factorised system.
struct BandSystem {
    eps: Vec<f64>,
    sys: system::System,
    factor: Factor,
    lower: f64,
    upper: f64,
}

/// Solves the semi-gray problem; the result rows report total J, H, q and the total
/// emissivity Σ_k ε_k f_k(T) at the solved temperature.
pub fn solve_bands(scene: &Scene, ex: &Exchange, spec: &BandSpec, params: &Params) -> Result<Solution> {
    let start = Instant::now();
    spec.validate(scene)?;
    let nodes = system::nodes(scene, ex)?;
    let n = nodes.len();
    // Anchoring and the starting temperatures come from a gray solve with band-mean ε.
    let mean_eps: Vec<f64> = nodes.iter().map(|nd| mean(&spec.emissivity[nd.surface])).collect();
    let gray_nodes: Vec<Node> =
        nodes.iter().zip(&mean_eps).map(|(nd, &e)| Node { emissivity: e, ..*nd }).collect();
    let e_amb_gray = scene.ambient.map_or(0.0, |a| SIGMA * a.temperature.powi(4));
    let rows: Vec<RowKind> = gray_nodes.iter().map(Node::row_kind).collect();
    let surface: Vec<usize> = nodes.iter().map(|nd| nd.surface).collect();
    system::check_anchored(scene, ex, &surface, &mean_eps, &rows)?;
    let gsys = system::assemble(ex, &mean_eps, &rows, e_amb_gray);
    let (x, _) =
        super::solve_system(&gsys, &Params { solver: super::Solver::Direct, ..params.clone() }, &mut None)?;
    let start_t = system::recover(ex, &gray_nodes, &rows, &gsys.radiosities(&x), e_amb_gray)?;
    let mut t: Vec<f64> = start_t.iter().map(|r| r.temperature).collect();
    let flux: Vec<usize> =
        (0..n).filter(|&i| matches!(nodes[i].condition, BoundaryCondition::HeatFlux(_))).collect();
    if flux.len() > MAX_FLUX_NODES {
        return Err(Error::Unsupported(format!(
            "semi-gray solve with {} heat-flux patches (the Newton Jacobian is dense, limit {MAX_FLUX_NODES})",
            flux.len()
        )));
    }
    // Factor every band once; K_k does not depend on T.
    let mut cache: direct::Cache = None;
    let mut bands = Vec::with_capacity(spec.bands.len());
    for (k, b) in spec.bands.iter().enumerate() {
        let eps: Vec<f64> = nodes.iter().map(|nd| spec.emissivity[nd.surface][k]).collect();
        let sys = system::assemble(ex, &eps, &vec![RowKind::Temperature(0.0); n], 0.0);
        let factor =
            direct::factor(&sys.k, sys.symmetric, params.dense_max, params.dense_full_max, &mut cache)?;
        bands.push(BandSystem { eps, sys, factor, lower: b.lower, upper: b.upper });
    }
    let t_amb = scene.ambient.map(|a| a.temperature);
    let scale = SIGMA * t.iter().chain(t_amb.iter()).fold(0.0f64, |m, v| m.max(*v)).powi(4);
    let target: Vec<f64> = flux
        .iter()
        .map(|&i| match nodes[i].condition {
            BoundaryCondition::HeatFlux(q) => q,
            BoundaryCondition::Temperature(_) => unreachable!("flux nodes only"),
        })
        .collect();
    let mut steps = 0;
    loop {
        let (q, jac) = evaluate(ex, &bands, &t, t_amb, &flux, true);
        let r: Vec<f64> = flux.iter().zip(&target).map(|(&i, qt)| q[i].heat_flux - qt).collect();
        let worst = r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if worst <= NEWTON_TOL * scale {
            let mut results = q;
            for (i, res) in results.iter_mut().enumerate() {
                res.temperature = t[i];
            }
            let eps_tot: Vec<f64> = (0..n)
                .map(|i| {
                    bands
                        .iter()
                        .map(|b| b.eps[i] * super::planck::band_fraction(b.lower, b.upper, t[i]))
                        .sum()
                })
                .collect();
            let ambient = t_amb.map(|ta| (ta, ambient_heat(ex, &bands, &t, ta)));
            return Ok(Solution {
                level: ex.level,
                names: ex.names.clone(),
                areas: ex.areas.clone(),
                emissivity: eps_tot,
                surface: nodes.iter().map(|nd| nd.surface).collect(),
                results,
                ambient,
                info: Info {
                    solver: format!("{} x {} bands, Newton on T", bands[0].factor.name(), bands.len()),
                    unknowns: bands.iter().map(|b| b.sys.b.len()).sum(),
                    iterations: steps,
                    residual: worst / scale,
                    wall: start.elapsed(),
                },
                heat_rate_error: None,
                heat_rate_shift: None,
                heat_rate_spread: None,
            });
        }
        if steps == BAND_MAX_NEWTON {
            return Err(Error::Compute(format!(
                "semi-gray Newton did not converge: flux residual {worst:.3e} W/m² after {steps} steps"
            )));
        }
        // δT = −J⁻¹ r, damped to keep T positive and steps within half the current T.
        let m = flux.len();
        direct::fix_parallelism();
        let jm = Mat::from_fn(m, m, |a, b| jac[a][b]);
        let rhs = Mat::from_fn(m, 1, |a, _| -r[a]);
        let d = faer::linalg::solvers::Solve::solve(&jm.partial_piv_lu(), &rhs);
        let mut damp = 1.0f64;
        for (a, &i) in flux.iter().enumerate() {
            if d[(a, 0)].abs() > 0.5 * t[i] {
                damp = damp.min(0.5 * t[i] / d[(a, 0)].abs());
            }
        }
        for (a, &i) in flux.iter().enumerate() {
            t[i] += damp * d[(a, 0)];
        }
        steps += 1;
    }
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// Per node totals over bands at temperatures `t`, and (if asked) ∂q_flux/∂T_flux.
fn evaluate(
    ex: &Exchange,
    bands: &[BandSystem],
    t: &[f64],
    t_amb: Option<f64>,
    flux: &[usize],
    jacobian: bool,
) -> (Vec<NodeResult>, Vec<Vec<f64>>) {
    let n = t.len();
    let mut out = vec![NodeResult::default(); n];
    let m = flux.len();
    let mut jac = vec![vec![0.0; m]; m];
    let ip = ex.indptr();
    let (idx, s) = (ex.s.indices(), ex.s.data());
    let amb = ex.ambient.as_deref();
    for b in bands {
        let (eb, deb): (Vec<f64>, Vec<f64>) =
            t.iter().map(|&ti| super::planck::band_power(b.lower, b.upper, ti)).unzip();
        let e_amb = t_amb.map_or(0.0, |ta| super::planck::band_power(b.lower, b.upper, ta).0);
        // Right-hand side of the all-temperature band system at the current T.
        let rows: Vec<RowKind> = eb.iter().map(|&e| RowKind::Temperature(e)).collect();
        let sys = system::assemble(ex, &b.eps, &rows, e_amb);
        let x = b.factor.solve(&sys.b);
        let j = sys.radiosities(&x);
        let h = |i: usize, j: &[f64], with_amb: bool| -> f64 {
            let inc: f64 = (ip[i]..ip[i + 1]).map(|k| s[k] * j[idx[k]]).sum();
            (inc + if with_amb { amb.map_or(0.0, |a| a[i]) * e_amb } else { 0.0 }) / ex.areas[i]
        };
        for i in 0..n {
            let hi = h(i, &j, true);
            let r = &mut out[i];
            r.radiosity += j[i];
            r.irradiation += hi;
            r.heat_flux += j[i] - hi;
            r.heat_rate += ex.areas[i] * (j[i] - hi);
        }
        if !jacobian || m == 0 {
            continue;
        }
        // ∂b/∂T_m for each flux node m, solved together.
        let nu = b.sys.b.len();
        let mut db = Mat::<f64>::zeros(nu, m);
        for (c, &mnode) in flux.iter().enumerate() {
            match b.sys.unknown[mnode] {
                Some(u) => {
                    let e = b.eps[mnode];
                    db[(u, c)] += ex.areas[mnode] * e / (1.0 - e) * deb[mnode];
                }
                None => {
                    // Black in this band: J_m = E_bm moves to the neighbours' right-hand side.
                    for (u, &i) in b.sys.node.iter().enumerate() {
                        let g = ex.get(i, mnode);
                        if g != 0.0 {
                            db[(u, c)] += g * deb[mnode];
                        }
                    }
                }
            }
        }
        let dx = b.factor.solve_many(db);
        for (c, &mnode) in flux.iter().enumerate() {
            let dj: Vec<f64> = (0..n)
                .map(|i| match b.sys.unknown[i] {
                    Some(u) => dx[(u, c)],
                    None if i == mnode => deb[mnode],
                    None => 0.0,
                })
                .collect();
            for (a, &i) in flux.iter().enumerate() {
                jac[a][c] += dj[i] - h(i, &dj, false);
            }
        }
    }
    (out, jac)
}

/// Σ_k Σ_i S_i∞ (E_b∞k − J_ik): net heat the ambient gives the scene.
fn ambient_heat(ex: &Exchange, bands: &[BandSystem], t: &[f64], t_amb: f64) -> f64 {
    let mut total = 0.0;
    for b in bands {
        let e_amb = super::planck::band_power(b.lower, b.upper, t_amb).0;
        let rows: Vec<RowKind> = t
            .iter()
            .map(|&ti| RowKind::Temperature(super::planck::band_power(b.lower, b.upper, ti).0))
            .collect();
        let sys = system::assemble(ex, &b.eps, &rows, e_amb);
        let j = sys.radiosities(&b.factor.solve(&sys.b));
        total += system::ambient_heat(ex, &j, e_amb);
    }
    total
}
