//! Runs one case with every applicable method and turns the results into [`Check`]s.
use super::case::Case;
use super::check::{Check, Status};
use super::heat;
use super::tolerance::{self, Budget};
use crate::scene::{self, Scene};
use crate::viewfactor::{self, Level, Method, ViewFactors};
use crate::Error;
use std::time::{Duration, Instant};

/// Method order in the report: exact first, then the approximations (the registry's).
pub use crate::viewfactor::registry::ALL as METHODS;

/// All checks of one case.
pub fn run_case(case: &Case, budget: &Budget) -> Vec<Check> {
    if budget.quick && !case.reference.quick {
        return vec![Check::without_value(
            &case.name,
            "all",
            "-",
            Status::Skipped("not in --quick (heavy case)".into()),
        )];
    }
    let scene = match scene::load(&case.scene) {
        Ok(s) => s,
        Err(e) => {
            return vec![Check::without_value(&case.name, "scene", "-", Status::Fail(e.to_string()))];
        }
    };
    let mut checks = Vec::new();
    // Heat-only cases (exact factors from a file) have no geometry worth running methods on.
    let methods = if case.reference.viewfactors.is_empty() { &[][..] } else { &METHODS[..] };
    for &method in methods {
        let name = method.to_string();
        if let Some(why) = case.reference.skip.get(&name) {
            checks.push(Check::without_value(&case.name, "all", &name, Status::Skipped(why.clone())));
            continue;
        }
        checks.extend(run_method(case, &scene, method, budget));
    }
    checks.extend(heat::file_checks(case, &scene));
    checks
}

/// View-factor checks (and heat checks, when the case has them) of one method.
fn run_method(case: &Case, scene: &Scene, method: Method, budget: &Budget) -> Vec<Check> {
    let params = method_params(case, method, budget, scene.patches.len());
    let start = Instant::now();
    let result = viewfactor::compute(scene, &params, Level::Surface);
    let time = start.elapsed();
    let name = method.to_string();
    let vf = match result {
        Ok(vf) => vf,
        Err(Error::Unsupported(why)) => {
            return vec![Check::without_value(&case.name, "all", &name, Status::NotApplicable(why))];
        }
        Err(e) => return vec![Check::without_value(&case.name, "all", &name, Status::Fail(e.to_string()))],
    };
    let mut checks = view_factor_checks(case, scene, method, &params, &vf, time);
    checks.extend(heat::method_checks(case, scene, method, &params, &vf, time));
    match case.reference.known_issue.get(&name) {
        Some(why) if checks.iter().any(|c| matches!(c.status, Status::Fail(_))) => {
            checks.into_iter().map(|c| c.with_known_issue(why)).collect()
        }
        Some(why) => {
            let stale = format!("every check passes: remove the [known_issue] marker ({why})");
            checks.push(Check::without_value(&case.name, "known issue", &name, Status::Fail(stale)));
            checks
        }
        None => checks,
    }
}

/// The suite's parameters for `method`, with the case's looser `auto_goal` (never a tighter one).
fn method_params(case: &Case, method: Method, budget: &Budget, patches: usize) -> viewfactor::Params {
    let mut params = budget.params(method, patches);
    if let (Method::Auto, Some(goal)) = (method, case.reference.auto_goal) {
        params.tolerance = params.tolerance.max(goal);
    }
    params
}

fn view_factor_checks(
    case: &Case,
    scene: &Scene,
    method: Method,
    params: &viewfactor::Params,
    vf: &ViewFactors,
    time: Duration,
) -> Vec<Check> {
    let mut checks = Vec::new();
    for r in &case.reference.viewfactors {
        let quantity = format!("F({}→{})", r.from, r.to);
        let (Some(i), Some(j)) =
            (vf.names.iter().position(|n| *n == r.from), vf.names.iter().position(|n| *n == r.to))
        else {
            let why = format!("reference names a surface the scene lacks ({} or {})", r.from, r.to);
            checks.push(Check::without_value(&case.name, &quantity, &method.to_string(), Status::Fail(why)));
            continue;
        };
        let entry = vf.rows[i].iter().find(|e| e.to as usize == j);
        let (value, sigma) = entry.map(|e| (e.factor, e.std_error)).unwrap_or((0.0, 0.0));
        let rays = params.samples as f64 * scene.surfaces[i].patches.len() as f64;
        let tol = match case.reference.tolerance.get(&method.to_string()) {
            Some(o) => o.abs,
            None => tolerance::view_factor(method, params, r, sigma, rays),
        };
        checks.push(Check::compared(&case.name, quantity, &method.to_string(), value, r.value, tol, time));
    }
    checks
}

#[cfg(test)]
mod tests {
    use super::*;

    fn case(extra: &str) -> (tempfile::TempDir, Case) {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("scene.toml"), "").unwrap();
        let text = format!(
            "title = \"t\"\ncitation = \"c\"\n{extra}\n[[viewfactor]]\nfrom = \"a\"\nto = \"b\"\nvalue = 0.2\nsource = \"C-11\"\n"
        );
        std::fs::write(dir.path().join(super::super::case::REFERENCE_FILE), text).unwrap();
        let c = Case::load(dir.path()).unwrap();
        (dir, c)
    }

    #[test]
    fn a_case_auto_goal_loosens_auto_only() {
        let (_d, plain) = case("");
        let (_e, loose) = case("auto_goal = 1e-4");
        let full = Budget::full();
        assert_eq!(method_params(&plain, Method::Auto, &full, 10).tolerance, 1e-6);
        assert_eq!(method_params(&loose, Method::Auto, &full, 10).tolerance, 1e-4);
        assert_eq!(method_params(&loose, Method::Hemicube, &full, 10), full.params(Method::Hemicube, 10));
        // Never tighter than the suite's own goal.
        let (_f, tight) = case("auto_goal = 1e-9");
        assert_eq!(method_params(&tight, Method::Auto, &Budget::quick(), 10).tolerance, 1e-4);
    }
}
