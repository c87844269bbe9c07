//! `--enforce none|reciprocity|closure` (docs/SPEC.md "Enforcement defaults"):
//! - none: raw exchange areas; open scenes get S_i,amb = A_i − Σ_j S_ij as they come;
//! - reciprocity: s̄ = ½(s + sᵀ); in open scenes rows that overshoot A_i are scaled down
//!   symmetrically (`super::scaling::capped_scaling`) and the ambient takes the rest;
//! - closure (closed scenes): first the leak check ([`leaks`]): a row short of 1 by more than
//!   the method's error is refused (exit 2), never stretched. Then constrained maximum
//!   likelihood for hit-count Monte Carlo, symmetric scaling otherwise (or an explicit
//!   [`ClosureMethod`]). Plain row scaling is never used. In open scenes closure equals
//!   reciprocity: the ambient node closes every row.
use super::diagnostics::Diagnostics;
use super::lsq::{weighted_least_squares, Weight};
use super::{ml, scaling, Exchange};
use crate::error::InputError;
use crate::viewfactor::MethodSet;
use crate::{Error, Result};
use std::path::PathBuf;
use std::str::FromStr;

/// Closure target: max |Σ_j F_ij − 1| after enforcement (a few hundred ulps of 1).
pub const CLOSURE_TOL: f64 = 1e-12;
/// The leak thresholds are the methods' own knowledge (`crate::viewfactor::accuracy`).
pub use crate::viewfactor::accuracy::{DETERMINISTIC_LEAK_TOL, LEAK_SIGMAS, LEAK_TOL_SINGLE_PLANE};

/// The docs/SPEC.md enforcement modes (named in [`crate::choice`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Enforce {
    /// Raw factors.
    None,
    /// A_iF_ij = A_jF_ji by averaging.
    Reciprocity,
    /// Reciprocity plus Σ_j F_ij = 1 (closed) or ≤ 1 (open).
    Closure,
}

impl FromStr for Enforce {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        crate::choice::parse_or("enforcement", s)
    }
}

impl std::fmt::Display for Enforce {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        crate::choice::write(self, f)
    }
}

impl Enforce {
    /// SPEC default of `solve`: closure for closed scenes, reciprocity for open ones.
    pub fn solve_default(open: bool) -> Self {
        if open {
            Enforce::Reciprocity
        } else {
            Enforce::Closure
        }
    }
}

/// How closure is reached (the study compares all of them).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ClosureMethod {
    /// ML for hit counts, symmetric scaling otherwise.
    #[default]
    Auto,
    /// Constrained maximum likelihood (needs hit counts).
    MaxLikelihood,
    /// s_ij = s̄_ij g_i g_j.
    SymmetricScaling,
    /// One weighted least-squares projection, w = s̄.
    WeightedLs,
    /// One least-squares projection, w = 1 on the pattern.
    UnweightedLs,
}

/// Options of [`enforce`].
#[derive(Debug, Clone, PartialEq)]
pub struct EnforceParams {
    /// The mode.
    pub mode: Enforce,
    /// Closure method.
    pub method: ClosureMethod,
    /// Open scene (an ambient node takes the rest of every row).
    pub open: bool,
    /// Scene file, for messages.
    pub source: PathBuf,
    /// Closure target.
    pub tolerance: f64,
    /// Geometry facts for the hint of a leak refusal (none: the generic hint).
    pub facts: Option<std::sync::Arc<crate::scene::orientation::SceneFacts>>,
}

impl Default for EnforceParams {
    fn default() -> Self {
        Self {
            mode: Enforce::None,
            method: ClosureMethod::Auto,
            open: false,
            source: PathBuf::new(),
            tolerance: CLOSURE_TOL,
            facts: None,
        }
    }
}

/// What [`enforce`] did.
#[derive(Debug, Clone, PartialEq)]
pub struct EnforceReport {
    /// Residuals of the raw matrix.
    pub before: Diagnostics,
    /// Residuals after enforcement.
    pub after: Diagnostics,
    /// The method applied.
    pub method: &'static str,
    /// Newton steps, CG iterations or sweeps spent.
    pub iterations: usize,
}

/// One leaking row: (node, Σ_j F_ij, allowed shortfall).
#[derive(Debug, Clone, PartialEq)]
pub struct Leak {
    /// Node index.
    pub node: usize,
    /// Row sum Σ_j F_ij.
    pub row_sum: f64,
    /// The shortfall allowed by the method's error.
    pub threshold: f64,
}

/// Rows of a closed scene short of 1 by more than the method's error, worst first.
pub fn leaks(ex: &Exchange) -> Vec<Leak> {
    let sums = ex.row_sums();
    let ip = ex.indptr();
    let mut out: Vec<Leak> = (0..ex.len())
        .filter_map(|i| {
            let p = sums[i] / ex.areas[i];
            let methods = ex.methods[ip[i]..ip[i + 1]].iter().fold(MethodSet::default(), |a, &m| a.union(m));
            let sigma = if ex.samples[i] > 0 && ex.has_hit_counts() {
                // Multinomial: the row sum is a binomial proportion of n rays.
                let q = p.clamp(0.0, 1.0);
                (q * (1.0 - q) / ex.samples[i] as f64).sqrt()
            } else {
                ex.var[ip[i]..ip[i + 1]].iter().sum::<f64>().sqrt() / ex.areas[i]
            };
            let threshold = methods.leak_tol().max(LEAK_SIGMAS * sigma);
            (1.0 - p > threshold).then_some(Leak { node: i, row_sum: p, threshold })
        })
        .collect();
    out.sort_by(|a, b| a.row_sum.total_cmp(&b.row_sum).then(a.node.cmp(&b.node)));
    out
}

/// Applies `p.mode` to `ex` in place and sets the ambient column of open scenes.
pub fn enforce(ex: &mut Exchange, p: &EnforceParams) -> Result<EnforceReport> {
    let before = Diagnostics::of(ex, p.open);
    let (method, iterations) = match (p.mode, p.open) {
        (Enforce::None, _) => ("none", 0),
        (Enforce::Reciprocity, false) => {
            ex.symmetrize();
            ("reciprocity average", 0)
        }
        (_, true) => {
            ex.symmetrize();
            let it = scaling::capped_scaling(ex, p.tolerance)?;
            ("reciprocity average, over-full rows scaled", it)
        }
        (Enforce::Closure, false) => {
            refuse_leaks(ex, p)?;
            close(ex, p)?
        }
    };
    if p.open {
        let sums = ex.row_sums();
        // Round-off below the closure tolerance is not an overshoot.
        let amb = ex.areas.iter().zip(&sums).map(|(a, s)| {
            let r = a - s;
            if r < 0.0 && -r <= p.tolerance * a * 10.0 {
                0.0
            } else {
                r
            }
        });
        ex.ambient = Some(amb.collect());
    }
    let after = Diagnostics::of(ex, p.open);
    Ok(EnforceReport { before, after, method, iterations })
}

fn close(ex: &mut Exchange, p: &EnforceParams) -> Result<(&'static str, usize)> {
    let method = match p.method {
        ClosureMethod::Auto if ex.has_hit_counts() => ClosureMethod::MaxLikelihood,
        ClosureMethod::Auto => ClosureMethod::SymmetricScaling,
        m => m,
    };
    match method {
        ClosureMethod::MaxLikelihood => {
            if !ex.has_hit_counts() {
                return Err(Error::Usage("maximum-likelihood closure needs Monte Carlo hit counts".into()));
            }
            Ok(("maximum likelihood", ml::max_likelihood(ex, p.tolerance)?))
        }
        ClosureMethod::SymmetricScaling | ClosureMethod::Auto => {
            ex.symmetrize();
            Ok(("symmetric scaling", scaling::symmetric_scaling(ex, p.tolerance)?))
        }
        ClosureMethod::WeightedLs => {
            ex.symmetrize();
            Ok(("weighted least squares (w = s)", weighted_least_squares(ex, Weight::Sbar)?))
        }
        ClosureMethod::UnweightedLs => {
            ex.symmetrize();
            Ok(("least squares (w = 1)", weighted_least_squares(ex, Weight::Unit)?))
        }
    }
}

/// SPEC: "never stretch a leaking row to 1" — a closed scene with leaking rows is bad input.
fn refuse_leaks(ex: &Exchange, p: &EnforceParams) -> Result<()> {
    let leaks = leaks(ex);
    let Some(first) = leaks.first() else { return Ok(()) };
    let rows: Vec<(usize, f64)> = leaks.iter().map(|l| (l.node, l.row_sum)).collect();
    let hint = refusal_hint(p, &super::leak::rows_from_exchange(ex, &rows));
    let names: Vec<String> = leaks
        .iter()
        .take(super::diagnostics::WORST_ROWS)
        .map(|l| format!("{} (row sum {:.6})", ex.names[l.node], l.row_sum))
        .collect();
    Err(InputError::surface(
        &p.source,
        ex.names[first.node].clone(),
        format!(
            "the closed scene leaks: {} row(s) sum to less than 1 by more than the method's error \
             ({:.1e}); worst: {}. {hint}; closure will not stretch a leaking row",
            leaks.len(),
            first.threshold,
            names.join(", ")
        ),
    )
    .into())
}

/// The cause named by the geometry facts, else the generic advice.
pub fn refusal_hint(p: &EnforceParams, rows: &[super::leak::LeakRow]) -> String {
    let hint = p.facts.as_ref().map(|f| super::leak::hint(f, rows)).unwrap_or_default();
    if hint.is_empty() {
        "Look for a gap, a flipped normal or a missing [ambient]".to_string()
    } else {
        hint
    }
}
