//! The method registry: the closed [`Method`] enum (its variants' docs are the CLI's help
//! texts, its kebab-case names the CLI's and the scene's values) and one line per method
//! naming the [`MethodInfo`] row that the method's own module fills in. Everything else —
//! the kernel dispatch, the error model the validation suite checks against, the leak
//! thresholds, the knob of the speed charts, the chart colours, the report order — reads
//! these rows. A new method is its own module plus a variant and a line here.
use super::accuracy::{ErrorInputs, Knob, MethodInfo};
use super::{analytic, auto, hemicube, monte_carlo, single_plane, Params};
use crate::{Error, Result};
use std::fmt;
use std::str::FromStr;

/// The view-factor methods of docs/SPEC.md; their names ([`crate::choice`]) are the variants in
/// kebab case (`single-plane`, `mc-area`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Method {
    /// Cheapest method per pair that meets the tolerance.
    #[default]
    Auto,
    /// Exact contour integration for planar polygons.
    Analytic,
    /// Cohen–Greenberg hemicube.
    Hemicube,
    /// Sillion–Puech single projection plane.
    SinglePlane,
    /// Monte Carlo, random point pairs on both patches.
    McArea,
    /// Monte Carlo, uniform hemisphere directions.
    McUniform,
    /// Monte Carlo, cosine-weighted directions.
    McCosine,
}

/// Every method, in report order: exact first, then the approximations.
pub const ALL: [Method; 7] = [
    Method::Analytic,
    Method::Auto,
    Method::Hemicube,
    Method::SinglePlane,
    Method::McArea,
    Method::McUniform,
    Method::McCosine,
];

impl Method {
    /// This method's registry row.
    pub fn info(self) -> &'static MethodInfo {
        match self {
            Method::Analytic => &analytic::INFO,
            Method::Auto => &auto::INFO,
            Method::Hemicube => &hemicube::INFO,
            Method::SinglePlane => &single_plane::INFO,
            Method::McArea => &monte_carlo::area::INFO,
            Method::McUniform => &monte_carlo::hemisphere::UNIFORM_INFO,
            Method::McCosine => &monte_carlo::hemisphere::COSINE_INFO,
        }
    }

    /// True for the Monte Carlo estimators (they report a standard error).
    pub fn is_monte_carlo(self) -> bool {
        self.info().monte_carlo
    }

    /// True when each unordered pair is computed once, so A_i F_ij = A_j F_ji exactly.
    pub fn is_symmetric(self) -> bool {
        self.info().symmetric
    }

    /// True when the method counts ray hits with equal weights (multinomial rows).
    pub fn counts_hits(self) -> bool {
        self.info().counts_hits
    }

    /// True when the method integrates shadows exactly (`analytic`, `auto`): the methods of
    /// point factors and of the clustered store's pairs.
    pub fn exact_shadows(self) -> bool {
        self.info().exact_shadows
    }

    /// The parameter that trades this method's time for accuracy.
    pub fn knob(self) -> Knob {
        self.info().knob
    }

    /// The absolute error on one F that a run with `params` must meet (the method's error
    /// model, [`MethodInfo::error_bound`]).
    pub fn error_bound(self, params: &Params, e: &ErrorInputs) -> f64 {
        (self.info().error_bound)(params, e)
    }

    /// The tighter leak threshold of an exact method on its own rows, when it has one
    /// ([`MethodInfo::own_leak_tol`]); `all_ladder` is evaluated only when needed.
    pub fn own_leak_tol(self, tolerance: f64, all_ladder: impl Fn() -> bool) -> Option<f64> {
        (self.info().own_leak_tol)(tolerance, &all_ladder)
    }

    /// The method's chart colour and whether its series is dashed.
    pub fn colour(self) -> ((u8, u8, u8), bool) {
        self.info().colour
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        crate::choice::write(self, f)
    }
}

impl FromStr for Method {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        crate::choice::parse_or("method", s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::ValueEnum;

    /// `ALL` lists every variant once (the compiler checks `info`, not the list).
    #[test]
    fn all_lists_every_method_once() {
        let mut all: Vec<String> = ALL.iter().map(|m| m.to_string()).collect();
        let mut variants: Vec<String> = Method::value_variants().iter().map(|m| m.to_string()).collect();
        all.sort();
        variants.sort();
        assert_eq!(all, variants);
    }

    /// Every method has its own chart colour, and only `auto` is dashed.
    #[test]
    fn method_colours_are_distinct() {
        let mut c: Vec<_> = ALL.iter().map(|m| m.colour().0).collect();
        c.sort();
        c.dedup();
        assert_eq!(c.len(), ALL.len());
        assert_eq!(ALL.iter().filter(|m| m.colour().1).collect::<Vec<_>>(), vec![&Method::Auto]);
    }

    /// The rows agree with the methods' kinds: Monte Carlo has no row kernel and reports
    /// samples as its knob; the exact methods are symmetric and integrate shadows.
    #[test]
    fn rows_agree_with_the_kinds_of_method() {
        let scene = crate::validate::studies::scenes::cube(1);
        for m in ALL {
            let params = Params { method: m, ..Params::default() };
            let kernel = (m.info().kernel)(&scene, &params).expect("kernel");
            assert_eq!(kernel.is_none(), m.is_monte_carlo(), "{m}");
            assert_eq!(m.knob() == Knob::Samples, m.is_monte_carlo(), "{m}");
            assert_eq!(m.exact_shadows(), m.knob() == Knob::Tolerance, "{m}");
            if let Some(k) = kernel {
                assert_eq!(k.symmetric(), m.is_symmetric(), "{m}");
            }
            assert!(!m.counts_hits() || m.is_monte_carlo(), "{m}");
        }
    }
}
