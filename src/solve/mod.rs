//! Net-radiation solve (docs/literature.md §5): gray diffuse surfaces with temperature or flux
//! conditions, an optional black ambient, black surfaces eliminated, in the SPD form K = D − S.
//!
//! - this file: [`Params`], [`Info`], [`Solution`] and the gray entry point [`solve_gray`];
//! - [`system`]: nodes and boundary conditions, assembly of K J = b, the anchoring check,
//!   recovery of q, T, H from J;
//! - [`direct`]: dense LLT (small N), sparse LLT with a reusable symbolic factorisation,
//!   LU fallbacks (faer);
//! - `iterative`: Jacobi and Gauss–Seidel with a typed [`NoConvergence`];
//! - [`planck`]: blackbody band fractions F_{0→λT};
//! - [`bands`]: semi-gray bands, temperatures coupled across bands by Newton;
//! - [`clustered`]: the solve on the hierarchical exchange, with heat-rate error estimates;
//! - [`conductance`]: radiative conductances RADK_ij = A_i ε_i B_ij (Gebhart).
use crate::exchange::Exchange;
use crate::scene::{BoundaryCondition, Scene};
use crate::viewfactor::Level;
use crate::{Error, Result};
use std::str::FromStr;
use std::time::{Duration, Instant};

pub mod apriori;
pub mod bands;
pub mod clustered;
pub mod conductance;
pub mod dense;
pub mod direct;
pub(crate) mod iterative;
pub mod planck;
pub mod system;

pub use iterative::NoConvergence;
pub use system::Node;

/// Name of the ambient node in results.
pub const AMBIENT: &str = "ambient";

/// Energy-balance acceptance: |Σ heat_rate| ≤ this × [`Solution::balance_scale`] (SPEC-level
/// check of a conservative, converged solve; round-off of a direct solve is ~1e-14).
pub const BALANCE_TOL: f64 = 1e-9;
/// Default relative residual goal of the iterative solvers (well below the 1e-9 balance).
pub const ITERATIVE_TOL: f64 = 1e-12;
/// Default iteration cap of the iterative solvers.
pub const MAX_ITERATIONS: usize = 100_000;

/// The linear solver (named in [`crate::choice`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Solver {
    /// Dense or sparse Cholesky, LU fallback.
    #[default]
    Direct,
    /// Jacobi iteration.
    Jacobi,
    /// Gauss–Seidel iteration.
    GaussSeidel,
}

impl FromStr for Solver {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        crate::choice::parse_or("solver", s)
    }
}

impl std::fmt::Display for Solver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        crate::choice::write(self, f)
    }
}

/// Options of the solve.
#[derive(Debug, Clone, PartialEq)]
pub struct Params {
    /// Linear solver.
    pub solver: Solver,
    /// Relative residual goal of the iterative solvers.
    pub tolerance: f64,
    /// Iteration cap of the iterative solvers.
    pub max_iterations: usize,
    /// Largest unknown count always solved densely.
    pub dense_max: usize,
    /// Largest unknown count solved densely when the factor would be mostly full (0: never).
    pub dense_full_max: usize,
}

impl Default for Params {
    fn default() -> Self {
        Self {
            solver: Solver::Direct,
            tolerance: ITERATIVE_TOL,
            max_iterations: MAX_ITERATIONS,
            dense_max: direct::DENSE_MAX,
            dense_full_max: direct::DENSE_FULL_MAX,
        }
    }
}

/// How a solve went.
#[derive(Debug, Clone, PartialEq)]
pub struct Info {
    /// The linear solver used, e.g. "dense LLT".
    pub solver: String,
    /// Unknown radiosities.
    pub unknowns: usize,
    /// Iterations (iterative solvers, or Newton steps for bands).
    pub iterations: usize,
    /// Final ‖b − KJ‖/‖b‖ (max over bands).
    pub residual: f64,
    /// Wall time.
    pub wall: Duration,
}

/// Results of one node (patch or surface).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct NodeResult {
    /// T, K.
    pub temperature: f64,
    /// Net outgoing flux q = J − H, W/m².
    pub heat_flux: f64,
    /// Net outgoing heat Q = A q, W.
    pub heat_rate: f64,
    /// Radiosity J, W/m².
    pub radiosity: f64,
    /// Irradiation H, W/m².
    pub irradiation: f64,
}

/// A solved scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Solution {
    /// Node level.
    pub level: Level,
    /// Node names.
    pub names: Vec<String>,
    /// Areas, m².
    pub areas: Vec<f64>,
    /// Emissivities (gray, or the total hemispherical value at the solved T for bands).
    pub emissivity: Vec<f64>,
    /// Owning surface of each node.
    pub surface: Vec<usize>,
    /// Per node.
    pub results: Vec<NodeResult>,
    /// Open scenes: (ambient temperature, net heat the environment gives the scene, W).
    pub ambient: Option<(f64, f64)>,
    /// Solver report.
    pub info: Info,
    /// Estimated bound on each node's heat-rate error from approximate exchange (the
    /// hierarchical path), W; None where the exchange is exact to the method's tolerance.
    pub heat_rate_error: Option<Vec<f64>>,
    /// The signed part of `heat_rate_error` (W, included there as |shift|): heat-rate moves
    /// from the closure scaling, which largely cancel within a surface, so a surface counts
    /// |Σ shift| rather than Σ |shift|.
    pub heat_rate_shift: Option<Vec<f64>>,
    /// Independent errors of sampled pair values: per node the part of `heat_rate_error` they
    /// make (W, included there), and per surface their total in quadrature (W, a few standard
    /// deviations, [`dense::surface_spread`]), which a surface counts instead of its nodes' sum.
    pub heat_rate_spread: Option<(Vec<f64>, Vec<f64>)>,
}

impl Solution {
    /// (Σ heat_rate over all rows incl. ambient, max |heat_rate|): SPEC requires the sum ≈ 0.
    pub fn heat_balance(&self) -> (f64, f64) {
        let amb = self.ambient.map_or(0.0, |a| a.1);
        let sum = self.results.iter().map(|r| r.heat_rate).sum::<f64>() + amb;
        let max = self.results.iter().map(|r| r.heat_rate.abs()).fold(amb.abs(), f64::max);
        (sum, max)
    }

    /// The scale the energy balance is judged against, W: the larger of max |heat_rate| and the
    /// power the nodes exchange, Σ A_i max(J_i, H_i). Each heat rate A_i (J_i − H_i) carries
    /// round-off of the order of A_i J_i, so an isothermal enclosure, whose heat rates are all
    /// round-off, is judged against what it exchanges rather than against that round-off.
    pub fn balance_scale(&self) -> f64 {
        let (_, max) = self.heat_balance();
        let exchanged: f64 =
            self.results.iter().zip(&self.areas).map(|(r, a)| a * r.radiosity.max(r.irradiation)).sum();
        max.max(exchanged)
    }

    /// Per-surface results: areas and heat rates add; T, J and H are area-weighted means.
    pub fn by_surface(&self, scene: &Scene) -> Solution {
        if self.level == Level::Surface {
            return self.clone();
        }
        let m = scene.surfaces.len();
        let mut results = vec![NodeResult::default(); m];
        let mut areas = vec![0.0; m];
        let mut eps = vec![0.0; m];
        for (k, r) in self.results.iter().enumerate() {
            let (s, a) = (self.surface[k], self.areas[k]);
            areas[s] += a;
            eps[s] += a * self.emissivity[k];
            let t = &mut results[s];
            t.temperature += a * r.temperature;
            t.heat_rate += r.heat_rate;
            t.radiosity += a * r.radiosity;
            t.irradiation += a * r.irradiation;
        }
        for s in 0..m {
            let a = areas[s];
            if a > 0.0 {
                let t = &mut results[s];
                (t.temperature, t.radiosity, t.irradiation) =
                    (t.temperature / a, t.radiosity / a, t.irradiation / a);
                t.heat_flux = t.heat_rate / a;
                eps[s] /= a;
            }
            // Values read from the input are written back as given, not as area-weighted
            // means that differ from them by round-off.
            let surface = &scene.surfaces[s];
            match surface.condition {
                Some(BoundaryCondition::Temperature(t)) => results[s].temperature = t,
                Some(BoundaryCondition::HeatFlux(q)) => results[s].heat_flux = q,
                None => {}
            }
            if scene.spectral.is_none() {
                eps[s] = surface.emissivity;
            }
        }
        Solution {
            level: Level::Surface,
            names: scene.surfaces.iter().map(|s| s.name.clone()).collect(),
            areas,
            emissivity: eps,
            surface: (0..m).collect(),
            results,
            ambient: self.ambient,
            info: self.info.clone(),
            heat_rate_error: self.heat_rate_error.as_ref().map(|e| {
                let mut out = vec![0.0; m];
                let mut shift = vec![0.0; m];
                for (k, v) in e.iter().enumerate() {
                    let c = self.heat_rate_shift.as_ref().map_or(0.0, |c| c[k]);
                    let spread = self.heat_rate_spread.as_ref().map_or(0.0, |(p, _)| p[k]);
                    out[self.surface[k]] += v - c.abs() - spread;
                    shift[self.surface[k]] += c;
                }
                let spread = |s: usize| self.heat_rate_spread.as_ref().map_or(0.0, |(_, t)| t[s]);
                (0..m).map(|s| out[s].max(0.0) + shift[s].abs() + spread(s)).collect()
            }),
            heat_rate_shift: None,
            heat_rate_spread: None,
        }
    }
}

/// Solves the gray net-radiation problem on the nodes of `ex` (which must carry the ambient
/// column for open scenes, see [`fn@crate::exchange::enforce`]).
pub fn solve_gray(scene: &Scene, ex: &Exchange, params: &Params) -> Result<Solution> {
    let start = Instant::now();
    let nodes = system::nodes(scene, ex)?;
    let eps: Vec<f64> = nodes.iter().map(|n| n.emissivity).collect();
    let e_amb = scene.ambient.map_or(0.0, |a| crate::SIGMA * a.temperature.powi(4));
    let rows: Vec<system::RowKind> = nodes.iter().map(|n| n.row_kind()).collect();
    let surface: Vec<usize> = nodes.iter().map(|n| n.surface).collect();
    system::check_anchored(scene, ex, &surface, &eps, &rows)?;
    let sys = system::assemble(ex, &eps, &rows, e_amb);
    let (x, mut info) = solve_system(&sys, params, &mut None)?;
    let j = sys.radiosities(&x);
    let results = system::recover(ex, &nodes, &rows, &j, e_amb)?;
    let ambient = scene.ambient.map(|a| (a.temperature, system::ambient_heat(ex, &j, e_amb)));
    info.wall = start.elapsed();
    Ok(Solution {
        level: ex.level,
        names: ex.names.clone(),
        areas: ex.areas.clone(),
        emissivity: eps,
        surface,
        results,
        ambient,
        info,
        heat_rate_error: None,
        heat_rate_shift: None,
        heat_rate_spread: None,
    })
}

/// Solves K x = b with the chosen solver; `symbolic` caches the sparse LLT analysis.
pub fn solve_system(
    sys: &system::System,
    params: &Params,
    cache: &mut direct::Cache,
) -> Result<(Vec<f64>, Info)> {
    let info = |solver: &str, iterations, residual| Info {
        solver: solver.to_string(),
        unknowns: sys.b.len(),
        iterations,
        residual,
        wall: Duration::ZERO,
    };
    match params.solver {
        Solver::Direct => {
            let f = direct::factor(&sys.k, sys.symmetric, params.dense_max, params.dense_full_max, cache)?;
            let x = f.solve(&sys.b);
            let r = system::residual(&sys.k, &x, &sys.b);
            Ok((x, info(f.name(), 0, r)))
        }
        Solver::Jacobi | Solver::GaussSeidel => {
            let gs = params.solver == Solver::GaussSeidel;
            let (x, it, r) = iterative::solve(&sys.k, &sys.b, gs, params.tolerance, params.max_iterations)?;
            Ok((x, info(if gs { "Gauss-Seidel" } else { "Jacobi" }, it, r)))
        }
    }
}
