//! Heat-rate and temperature checks of enclosure problems, through the radiation solve.
//!
//! The solve stage is not in this build yet: heat references are reported as n/a until it is.
use super::case::Case;
use super::check::{Check, Status};
use crate::scene::Scene;
use crate::viewfactor::{Method, Params};
use std::time::Duration;

/// Why heat checks cannot run yet.
const NO_SOLVE: &str = "the radiation solve is not available in this build";

fn heat_quantities(case: &Case) -> Vec<String> {
    let mut q = Vec::new();
    for h in &case.reference.heat {
        if h.heat_rate.is_some() {
            q.push(format!("q({}) [W]", h.surface));
        }
        if h.temperature.is_some() {
            q.push(format!("T({}) [K]", h.surface));
        }
    }
    q
}

/// Heat checks with `method`'s view factors.
pub fn method_checks(
    case: &Case,
    _scene: &Scene,
    method: Method,
    _params: &Params,
    _time: Duration,
) -> Vec<Check> {
    if case.reference.heat.is_empty() || !matches!(method, Method::Analytic | Method::Auto) {
        return Vec::new();
    }
    vec![Check::without_value(
        &case.name,
        &heat_quantities(case).join(", "),
        method.name(),
        Status::NotApplicable(NO_SOLVE.into()),
    )]
}

/// Heat checks with the case's exact view-factor file.
pub fn file_checks(case: &Case, _scene: &Scene) -> Vec<Check> {
    if case.reference.viewfactors_file.is_none() || case.reference.heat.is_empty() {
        return Vec::new();
    }
    vec![Check::without_value(
        &case.name,
        &heat_quantities(case).join(", "),
        "vf-file",
        Status::NotApplicable(NO_SOLVE.into()),
    )]
}
