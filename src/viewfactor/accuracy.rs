//! What each method knows about its own accuracy, asked by the CLI, the enforcement and the
//! validation suite instead of each of them matching on the method:
//! - leak thresholds: [`MethodSet::leak_tol`] for rows by any mix of methods, and
//!   [`Method::own_leak_tol`] for the exact methods' tighter check of their own rows;
//! - the error model: [`Method::error_bound`], the absolute error on one F that a run with
//!   given parameters must meet;
//! - the accuracy knob: [`Method::knob`], the parameter that trades time for accuracy;
//! - how entries are produced: [`Method::is_symmetric`], [`Method::counts_hits`].
//!
//! A new method adds its arms here (and its kernel in `viewfactor`), nowhere else.
use super::analytic::kernel::ANALYTIC_LEAK_TOL;
use super::auto::LADDER_SHARE;
use super::closed_form::element_to_rectangle_corner;
use super::single_plane::DEFAULT_HALF_WIDTH;
use super::{Method, MethodSet, Params};

/// Leak threshold for deterministic methods: analytic and hemicube rows close to ~1e-5 or
/// better, so a shortfall above 1e-3 is geometry, not method error.
pub const DETERMINISTIC_LEAK_TOL: f64 = 1e-3;
/// Leak threshold for single-plane, whose finite plane misses up to ~1 % of grazing
/// directions (literature.md §4: the plane captures 0.9919 at half-width 10).
pub const LEAK_TOL_SINGLE_PLANE: f64 = 2e-2;
/// Monte Carlo rows leak when short by more than this many standard errors of the row sum
/// (and by more than [`DETERMINISTIC_LEAK_TOL`]): a false alarm needs a 4σ event.
pub const LEAK_SIGMAS: f64 = 4.0;

/// Analytic relative error bound: the contour integral is exact to ~1e-12; 1e-9 leaves room for
/// f64 summation over many patch pairs (literature §2, robust integrator recipe).
pub const ANALYTIC_REL: f64 = 1e-9;
/// Monte Carlo: standard errors allowed. Two-sided normal tail 6e-5 per check, so a false alarm
/// over a few hundred Monte Carlo checks stays near 1 %.
pub const MC_ERROR_SIGMAS: f64 = 4.0;
/// Hemicube / single-plane rasterisation error ≤ `RASTER_COEFF`·√F/R: a target of angular size θ
/// spans θR/2 pixels and loses O(1) pixel per edge, so δF ∝ θ/R ∝ √F/R; literature §4 gives
/// 0.42·√0.2 at the adjacent cube face and ≤ 0.95·√F for aliasing small targets; 2 bounds both.
pub const RASTER_COEFF: f64 = 2.0;

/// Single plane: the hemisphere fraction outside its plane of half-width s at unit height,
/// 1 − 4·F_corner(s, s, 1) (literature §4), the method's one-sided grazing bias.
pub fn single_plane_missed() -> f64 {
    single_plane_missed_at(DEFAULT_HALF_WIDTH)
}

/// The same for a plane of half-width `s`.
pub fn single_plane_missed_at(s: f64) -> f64 {
    1.0 - 4.0 * element_to_rectangle_corner(s, s, 1.0)
}

/// The parameter that trades a method's time for accuracy.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Knob {
    /// `--tolerance` (analytic, auto).
    Tolerance,
    /// `--resolution` (hemicube, single-plane).
    Resolution,
    /// `--samples` (Monte Carlo).
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

impl Method {
    /// The absolute error on one F that a run with `params` must meet:
    /// analytic `ANALYTIC_REL`·F; auto its goal; Monte Carlo `MC_ERROR_SIGMAS`·max(σ̂, σ_binomial);
    /// hemicube point bias + `RASTER_COEFF`·√F/R; single-plane those + min(F, missed fraction).
    pub fn error_bound(self, params: &Params, e: &ErrorInputs) -> f64 {
        let f = e.f;
        match self {
            Method::Analytic => ANALYTIC_REL * f,
            Method::Auto => params.tolerance,
            Method::McArea | Method::McUniform | Method::McCosine => {
                // The binomial σ of the reference value guards against a zero-hit estimate whose
                // own σ̂ is 0.
                let binomial = (f * (1.0 - f).max(0.0) / e.rays.max(1.0)).sqrt();
                MC_ERROR_SIGMAS * e.sigma.max(binomial)
            }
            Method::Hemicube => e.point_bias + raster(f, params.resolution),
            Method::SinglePlane => e.point_bias + raster(f, params.resolution) + f.min(single_plane_missed()),
        }
    }

    /// The tighter leak threshold of an exact method on its own rows, when it has one:
    /// analytic [`ANALYTIC_LEAK_TOL`]; auto the same, or its ladder target if looser, but only
    /// when every entry came from the ladder (`all_ladder`, evaluated only for auto), since
    /// its sampled and shadow-integrated entries are covered by the general check alone.
    pub fn own_leak_tol(self, tolerance: f64, all_ladder: impl FnOnce() -> bool) -> Option<f64> {
        match self {
            Method::Analytic => Some(ANALYTIC_LEAK_TOL),
            Method::Auto if all_ladder() => Some(ANALYTIC_LEAK_TOL.max(LADDER_SHARE * tolerance)),
            _ => None,
        }
    }

    /// The parameter that trades this method's time for accuracy.
    pub fn knob(self) -> Knob {
        match self {
            Method::Analytic | Method::Auto => Knob::Tolerance,
            Method::Hemicube | Method::SinglePlane => Knob::Resolution,
            Method::McArea | Method::McUniform | Method::McCosine => Knob::Samples,
        }
    }

    /// True when each unordered pair is computed once, so A_i F_ij = A_j F_ji exactly.
    pub fn is_symmetric(self) -> bool {
        matches!(self, Method::Auto | Method::Analytic)
    }

    /// True when the method counts ray hits with equal weights (multinomial rows).
    pub fn counts_hits(self) -> bool {
        matches!(self, Method::McCosine | Method::McUniform)
    }
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

fn raster(f: f64, resolution: usize) -> f64 {
    RASTER_COEFF * f.sqrt() / resolution as f64
}
