//! Reference checks: the absolute tolerance a method must meet on a reference quantity, and
//! the run budget (samples, resolution, goal) it is evaluated at.
//!
//! The tolerance on F_IJ is the method's own error model
//! ([`Method::error_bound`](crate::viewfactor::Method::error_bound), in
//! [`crate::viewfactor::accuracy`]) plus the reference's uncertainty and [`ABS_FLOOR`]:
//!
//! | method | error model |
//! |---|---|
//! | analytic | `ANALYTIC_REL`·F |
//! | auto | its `--tolerance` goal |
//! | mc-* | `MC_ERROR_SIGMAS`·max(σ̂, σ_binomial) |
//! | hemicube | point-sampling bias + `RASTER_COEFF`·√F / R |
//! | single-plane | the hemicube terms + min(F, missed hemisphere fraction) |
//!
//! The point-sampling bias bounds the hemicube's proximity error whether it projects from the
//! centroid or from a few Gauss points per patch (its adaptive positions).
use super::case::VfRef;
use crate::viewfactor::accuracy::ErrorInputs;
use crate::viewfactor::{Method, Params};

/// Absolute floor for every tolerance: sums of O(1) terms carry ~1e-15 round-off, and a
/// structural zero must come out below this.
pub const ABS_FLOOR: f64 = 1e-13;
/// Heat quantities from exact factors: F exact to 1e-9, amplified by the enclosure's condition
/// (λ_min(K) ≈ 0.29 in E3), plus the solver's round-off.
pub const HEAT_EXACT_REL: f64 = 1e-7;

/// Run budget of the suite: what each method is given, per case.
#[derive(Debug, Clone, PartialEq)]
pub struct Budget {
    /// Monte Carlo rays (or point pairs) per case run, shared among its patches.
    pub rays_per_case: usize,
    /// Lower bound on samples per patch.
    pub min_samples: usize,
    /// Hemicube / single-plane resolution.
    pub resolution: usize,
    /// `auto` accuracy goal.
    pub auto_tolerance: f64,
    /// Random seed.
    pub seed: u64,
    /// The `--quick` subset: cases marked `quick = false` are skipped.
    pub quick: bool,
}

impl Budget {
    /// The CI subset: 10⁵ rays per case (at least 500 per patch), R = 64.
    pub fn quick() -> Budget {
        Budget {
            rays_per_case: 100_000,
            min_samples: 500,
            resolution: 64,
            auto_tolerance: 1e-4,
            seed: 1,
            quick: true,
        }
    }
    /// The full suite: 4·10⁶ rays per case (at least 10⁴ per patch), R = 512.
    pub fn full() -> Budget {
        Budget {
            rays_per_case: 4_000_000,
            min_samples: 10_000,
            resolution: 512,
            auto_tolerance: 1e-6,
            seed: 1,
            quick: false,
        }
    }
    /// Parameters for `method` on a scene of `patches` patches.
    pub fn params(&self, method: Method, patches: usize) -> Params {
        let samples = (self.rays_per_case / patches.max(1)).max(self.min_samples);
        Params {
            method,
            samples,
            resolution: self.resolution,
            tolerance: self.auto_tolerance,
            seed: self.seed,
            progress: false,
        }
    }
}

/// Tolerance of `method` (run with `params`) on reference `r`; `sigma` is the reported standard
/// error and `rays` the samples cast from the emitting surface.
pub fn view_factor(method: Method, params: &Params, r: &VfRef, sigma: f64, rays: f64) -> f64 {
    let model =
        method.error_bound(params, &ErrorInputs { f: r.value, sigma, rays, point_bias: r.point_bias });
    model + r.uncertainty + ABS_FLOOR
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reference(value: f64) -> VfRef {
        VfRef {
            from: "a".into(),
            to: "b".into(),
            value,
            source: String::new(),
            uncertainty: 0.0,
            point_bias: 0.01,
        }
    }

    #[test]
    fn models_scale_as_documented() {
        let r = reference(0.2);
        let p = Params { resolution: 128, ..Budget::quick().params(Method::Hemicube, 1) };
        let t128 = view_factor(Method::Hemicube, &p, &r, 0.0, 0.0);
        let p512 = Params { resolution: 512, ..p };
        let t512 = view_factor(Method::Hemicube, &p512, &r, 0.0, 0.0);
        // Raster part shrinks 4× from R = 128 to 512; the bias stays.
        assert!(((t128 - 0.01) / (t512 - 0.01) - 4.0).abs() < 1e-6, "{t128} {t512}");
        let mc = view_factor(Method::McCosine, &p, &r, 1e-3, 1e6);
        assert!((mc - 4e-3).abs() < 1e-9, "{mc}");
        // A zero-hit estimate is judged by the binomial σ of the reference, not its own 0.
        let zero = view_factor(Method::McCosine, &p, &reference(1e-4), 0.0, 1e4);
        assert!((zero - 4.0 * (1e-4 * (1.0 - 1e-4) / 1e4f64).sqrt()).abs() < 1e-12);
    }
}
