//! What a method says about its own accuracy, in one shape for every method
//! ([`MethodInfo`]); each method fills its row in its own module and the registry
//! ([`super::registry`]) lists the rows. This file imports no method, so every method can
//! use the shared constants and types below:
//! - leak thresholds: [`MethodSet::leak_tol`] for rows by any mix of methods, and a method's
//!   own tighter check of its own rows ([`MethodInfo::own_leak_tol`]);
//! - the error model: [`MethodInfo::error_bound`], the absolute error on one F that a run with
//!   given parameters must meet, built from the shared terms here ([`mc_error_bound`],
//!   [`raster`]);
//! - the accuracy knob: [`Knob`], the parameter that trades time for accuracy.
use super::row::RowKernel;
use super::{MethodSet, Params};
use crate::scene::Scene;
use crate::Result;

/// Leak threshold for deterministic methods: analytic and hemicube rows close to ~1e-5 or
/// better, so a shortfall above 1e-3 is geometry, not method error.
pub const DETERMINISTIC_LEAK_TOL: f64 = 1e-3;
/// Leak threshold for single-plane, whose finite plane misses up to ~1 % of grazing
/// directions (the plane captures 0.9919 of the hemisphere at half-width 10).
pub const LEAK_TOL_SINGLE_PLANE: f64 = 2e-2;
/// Monte Carlo rows leak when short by more than this many standard errors of the row sum
/// (and by more than [`DETERMINISTIC_LEAK_TOL`]): a false alarm needs a 4σ event.
pub const LEAK_SIGMAS: f64 = 4.0;

/// Analytic relative error bound: the contour integral is exact to ~1e-12; 1e-9 leaves room for
/// f64 summation over many patch pairs (the robust integrator recipe).
pub const ANALYTIC_REL: f64 = 1e-9;
/// Monte Carlo: standard errors allowed. Two-sided normal tail 6e-5 per check, so a false alarm
/// over a few hundred Monte Carlo checks stays near 1 %.
pub const MC_ERROR_SIGMAS: f64 = 4.0;
/// Hemicube / single-plane rasterisation error ≤ `RASTER_COEFF`·√F/R: a target of angular size θ
/// spans θR/2 pixels and loses O(1) pixel per edge, so δF ∝ θ/R ∝ √F/R; the adjacent cube face
/// measures 0.42·√0.2 and aliasing small targets ≤ 0.95·√F; 2 bounds both.
pub const RASTER_COEFF: f64 = 2.0;

/// The parameter that trades a method's time for accuracy.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Knob {
    /// The absolute tolerance on each F (analytic, auto).
    Tolerance,
    /// The raster resolution (hemicube, single-plane).
    Resolution,
    /// The sample count (Monte Carlo).
    Samples,
}

/// What a reference check knows besides the method: the reference value and the run's own
/// error report.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorInputs {
    /// The reference F.
    pub f: f64,
    /// The reported standard error of the computed F.
    pub sigma: f64,
    /// Samples cast from the emitting surface.
    pub rays: f64,
    /// Bound on the point-sampling (proximity) bias of a projection method for this pair.
    pub point_bias: f64,
}

/// A deterministic method's row kernel on a scene (`None`: a Monte Carlo method, which runs
/// its own sampler).
pub type KernelFn = for<'a> fn(&'a Scene, &Params) -> Result<Option<Box<dyn RowKernel + 'a>>>;

/// One method's row of the registry: everything the rest of lambert asks about a method.
#[derive(Clone, Copy)]
pub struct MethodInfo {
    /// The parameter that trades this method's time for accuracy.
    pub knob: Knob,
    /// Each unordered pair computed once, so A_i F_ij = A_j F_ji exactly.
    pub symmetric: bool,
    /// A Monte Carlo estimator: reports a standard error, runs its own sampler.
    pub monte_carlo: bool,
    /// Counts ray hits with equal weights (multinomial rows).
    pub counts_hits: bool,
    /// Integrates shadows exactly (the methods that point factors and the clustered store
    /// evaluate their pairs with).
    pub exact_shadows: bool,
    /// The row kernel.
    pub kernel: KernelFn,
    /// The absolute error on one F that a run with these parameters must meet.
    pub error_bound: fn(&Params, &ErrorInputs) -> f64,
    /// The tighter leak threshold of the method on its own rows, given the tolerance and
    /// whether every entry came from the analytic ladder (asked only if needed).
    pub own_leak_tol: fn(f64, &dyn Fn() -> bool) -> Option<f64>,
    /// Chart colour ([`crate::palette`]) and whether the series is dashed.
    pub colour: ((u8, u8, u8), bool),
}

impl std::fmt::Debug for MethodInfo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MethodInfo")
            .field("knob", &self.knob)
            .field("symmetric", &self.symmetric)
            .field("monte_carlo", &self.monte_carlo)
            .field("counts_hits", &self.counts_hits)
            .field("exact_shadows", &self.exact_shadows)
            .field("colour", &self.colour)
            .finish_non_exhaustive()
    }
}

/// No tighter leak threshold of the method's own.
pub fn no_own_leak_tol(_tolerance: f64, _all_ladder: &dyn Fn() -> bool) -> Option<f64> {
    None
}

/// Monte Carlo: `MC_ERROR_SIGMAS`·max(σ̂, σ_binomial); the binomial σ of the reference value
/// guards against a zero-hit estimate whose own σ̂ is 0.
pub fn mc_error_bound(_params: &Params, e: &ErrorInputs) -> f64 {
    let binomial = (e.f * (1.0 - e.f).max(0.0) / e.rays.max(1.0)).sqrt();
    MC_ERROR_SIGMAS * e.sigma.max(binomial)
}

/// The rasterisation term of the projection methods, `RASTER_COEFF`·√F/R.
pub fn raster(f: f64, resolution: usize) -> f64 {
    RASTER_COEFF * f.sqrt() / resolution as f64
}

impl MethodSet {
    /// The deterministic leak threshold of a row produced by these methods: single-plane's
    /// alone when it produced every entry, else [`DETERMINISTIC_LEAK_TOL`].
    pub fn leak_tol(self) -> f64 {
        if self.union(MethodSet::SINGLE_PLANE) == self && !self.is_empty() {
            LEAK_TOL_SINGLE_PLANE
        } else {
            DETERMINISTIC_LEAK_TOL
        }
    }
}
