//! `--enforce none|reciprocity|closure` (docs/SPEC.md "Enforcement defaults"), one function
//! ([`fn@enforce`]) for every exchange store through the [`Operator`] hooks:
//! - none: raw exchange areas; open scenes get S_i,amb = A_i − Σ_j S_ij as they come;
//! - reciprocity: s̄ = ½(s + sᵀ); in open scenes rows that overshoot A_i are scaled down
//!   symmetrically (`super::scaling::capped_scales`) and the ambient takes the rest;
//! - closure (closed scenes): first the leak check ([`leaks`], on the rows and thresholds of
//!   [`Operator::leak_budget`]): a row short of 1 by more than the method's error is refused
//!   (exit 2), never stretched. Then constrained maximum likelihood for hit-count Monte Carlo,
//!   symmetric scaling s_ij = s̄_ij g_i g_j otherwise (`super::scaling::closure_scales`), or
//!   an explicit [`ClosureMethod`] where the store serves it ([`Operator::close_by`]). Plain
//!   row scaling is never used. In open scenes closure equals reciprocity: the ambient node
//!   closes every row;
//! - the residual diagnostics (row sums, reciprocity, signs) before and after.
use super::diagnostics::Diagnostics;
use super::operator::Operator;
use super::scaling::{capped_scales, closure_scales};
use crate::error::InputError;
use crate::{Error, Result};
use std::path::PathBuf;
use std::str::FromStr;

/// Closure target: max |Σ_j F_ij − 1| after enforcement (a few hundred ulps of 1).
pub const CLOSURE_TOL: f64 = 1e-12;
/// The leak thresholds are the methods' own knowledge (`crate::viewfactor::accuracy`).
pub use super::operator::ClosureMethod;
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
    /// Refuse a leaking closed scene before closure (false: a first, loose pass whose result
    /// only bounds a final one that checks).
    pub check_leaks: bool,
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
            check_leaks: true,
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

/// One leaking row: (leak-check row, Σ_j F_ij, allowed shortfall).
#[derive(Debug, Clone, PartialEq)]
pub struct Leak {
    /// Leak-check row ([`Operator::leak_budget`]): the node, or the surface on the clustered
    /// store.
    pub node: usize,
    /// Row sum Σ_j F_ij.
    pub row_sum: f64,
    /// The shortfall allowed by the method's error.
    pub threshold: f64,
}

/// Rows of a closed scene short of 1 by more than the method's error, worst first.
pub fn leaks(op: &dyn Operator) -> Vec<Leak> {
    leaks_of(op, &op.raw_row_sums())
}

/// [`leaks`] of the raw row sums `raw` (m²).
fn leaks_of(op: &dyn Operator, raw: &[f64]) -> Vec<Leak> {
    let mut out: Vec<Leak> = op
        .leak_budget(raw)
        .into_iter()
        .enumerate()
        .filter(|&(_, (p, threshold))| 1.0 - p > threshold)
        .map(|(node, (row_sum, threshold))| Leak { node, row_sum, threshold })
        .collect();
    out.sort_by(|a, b| a.row_sum.total_cmp(&b.row_sum).then(a.node.cmp(&b.node)));
    out
}

/// Applies `p.mode` to any exchange store in place and sets the ambient column of open
/// scenes: the one enforcement of the sparse, packed and clustered stores, through the
/// [`Operator`] hooks.
pub fn enforce(op: &mut dyn Operator, p: &EnforceParams) -> Result<EnforceReport> {
    // The raw row sums serve the diagnostics and the leak check (one product on the store).
    let raw = op.raw_row_sums();
    let before = Diagnostics::with_sums(op, &raw, op.raw_asymmetry(), p.open);
    let (method, iterations) = match (p.mode, p.open) {
        (Enforce::None, _) => ("none", 0),
        (Enforce::Reciprocity, false) => {
            op.symmetrize();
            ("reciprocity average", 0)
        }
        (_, true) => {
            op.symmetrize();
            let (g, sweeps) = capped_scales(op, p.tolerance)?;
            if g.iter().any(|&x| x != 1.0) {
                op.scale(&g);
            }
            ("reciprocity average, over-full rows scaled", sweeps)
        }
        (Enforce::Closure, false) => {
            if p.check_leaks {
                refuse_leaks(op, &raw, p)?;
            }
            close(op, p)?
        }
    };
    let sums = op.row_sums();
    if p.open {
        // Round-off below the closure tolerance is not an overshoot.
        let amb = op.areas().iter().zip(&sums).map(|(a, s)| {
            let r = a - s;
            if r < 0.0 && -r <= p.tolerance * a * 10.0 {
                0.0
            } else {
                r
            }
        });
        op.set_ambient(amb.collect());
    }
    let after = Diagnostics::with_sums(op, &sums, op.asymmetry(), p.open);
    Ok(EnforceReport { before, after, method, iterations })
}

/// Closure of a closed scene by `p.method`: symmetric scaling on any store, the other methods
/// where the store serves them ([`Operator::close_by`]).
fn close(op: &mut dyn Operator, p: &EnforceParams) -> Result<(&'static str, usize)> {
    let method = match p.method {
        ClosureMethod::Auto if op.has_hit_counts() => ClosureMethod::MaxLikelihood,
        ClosureMethod::Auto => ClosureMethod::SymmetricScaling,
        m => m,
    };
    match method {
        ClosureMethod::SymmetricScaling | ClosureMethod::Auto => {
            op.symmetrize();
            let (g, iterations) = closure_scales(op, p.tolerance)?;
            op.scale(&g);
            Ok(("symmetric scaling", iterations))
        }
        ClosureMethod::MaxLikelihood if !op.has_hit_counts() => {
            Err(Error::Usage("maximum-likelihood closure needs Monte Carlo hit counts".into()))
        }
        m => op.close_by(m, p.tolerance).unwrap_or_else(|| {
            Err(Error::Usage(format!("closure by {m:?} needs the sparse exchange store")))
        }),
    }
}

/// SPEC: "never stretch a leaking row to 1" — a closed scene with leaking rows is bad input.
fn refuse_leaks(op: &dyn Operator, raw: &[f64], p: &EnforceParams) -> Result<()> {
    let leaks = leaks_of(op, raw);
    let Some(first) = leaks.first() else { return Ok(()) };
    let rows: Vec<(usize, f64)> = leaks.iter().map(|l| (l.node, l.row_sum)).collect();
    let hint = refusal_hint(p, &op.leak_rows(&rows));
    let names: Vec<String> = leaks
        .iter()
        .take(super::diagnostics::WORST_ROWS)
        .map(|l| format!("{} (row sum {:.6})", op.leak_row_name(l.node), l.row_sum))
        .collect();
    Err(InputError::surface(
        &p.source,
        op.leak_row_name(first.node),
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A store with only the required hooks: a full symmetric matrix (row-major), so every
    /// default hook is the one in use.
    struct Full {
        s: Vec<f64>,
        areas: Vec<f64>,
        names: Vec<String>,
        ambient: Option<Vec<f64>>,
    }

    impl Full {
        /// Three nodes, rows summing to `fill` × A_i: a and b see only c, c also sees itself
        /// (an odd cycle: the closure constraints are definite).
        fn new(fill: f64) -> Self {
            let s = [[0.0, 0.0, 1.0], [0.0, 0.0, 2.0], [1.0, 2.0, 1.0]];
            Full {
                s: s.iter().flatten().map(|v| v * fill).collect(),
                areas: vec![1.0, 2.0, 4.0],
                names: ["a", "b", "c"].map(String::from).to_vec(),
                ambient: None,
            }
        }
    }

    impl Operator for Full {
        fn len(&self) -> usize {
            self.areas.len()
        }
        fn areas(&self) -> &[f64] {
            &self.areas
        }
        fn matvec_scaled(&self, w: Option<&[f64]>, x: &[f64]) -> Vec<f64> {
            let n = self.len();
            let wt = |i: usize| w.map_or(1.0, |w| w[i]);
            (0..n).map(|i| wt(i) * (0..n).map(|j| self.s[i * n + j] * wt(j) * x[j]).sum::<f64>()).collect()
        }
        fn self_term(&self, i: usize) -> f64 {
            self.s[i * self.len() + i]
        }
        fn couplings(&self, f: &mut dyn FnMut(usize, usize)) {
            let n = self.len();
            for i in 0..n {
                for j in (0..n).filter(|&j| j != i && self.s[i * n + j] != 0.0) {
                    f(i, j);
                }
            }
        }
        fn names(&self) -> &[String] {
            &self.names
        }
        fn ambient(&self) -> Option<&[f64]> {
            self.ambient.as_deref()
        }
        fn set_ambient(&mut self, ambient: Vec<f64>) {
            self.ambient = Some(ambient);
        }
        fn scale(&mut self, g: &[f64]) {
            let n = self.len();
            for i in 0..n {
                for j in 0..n {
                    self.s[i * n + j] *= g[i] * g[j];
                }
            }
        }
        fn negatives(&self) -> usize {
            self.s.iter().filter(|&&x| x < 0.0).count()
        }
    }

    fn closure() -> EnforceParams {
        EnforceParams { mode: Enforce::Closure, source: "tri.toml".into(), ..Default::default() }
    }

    #[test]
    fn any_operator_closes_through_its_hooks() {
        // 1e-4 short: within the deterministic leak threshold, so closure scales it up.
        let mut op = Full::new(1.0 - 1e-4);
        let rep = enforce(&mut op, &closure()).unwrap();
        assert_eq!(rep.method, "symmetric scaling");
        assert!((rep.before.max_row_error - 1e-4).abs() < 1e-12, "{}", rep.before);
        assert!(rep.after.max_row_error <= CLOSURE_TOL, "{}", rep.after);
        assert!(rep.iterations > 0);
        // Zeros stay zero and the matrix stays symmetric.
        assert_eq!((op.s[1], op.s[3]), (0.0, 0.0));
        assert_eq!(op.s[2], op.s[6]);
    }

    #[test]
    fn any_operator_refuses_a_leak_and_a_method_it_cannot_serve() {
        let mut op = Full::new(0.9);
        let err = enforce(&mut op, &closure()).unwrap_err();
        let msg = err.to_string();
        assert_eq!(err.exit_code(), 2);
        assert!(
            msg.contains("tri.toml") && msg.contains("3 row(s)") && msg.contains("a (row sum 0.900000)"),
            "{msg}"
        );
        // Refused before any change; a first pass without the check closes it.
        assert_eq!(op.s[2], 0.9);
        enforce(&mut op, &EnforceParams { check_leaks: false, ..closure() }).unwrap();
        assert!((op.row_sums()[0] - 1.0).abs() <= 1e-12);
        for (m, says) in [
            (ClosureMethod::WeightedLs, "needs the sparse exchange store"),
            (ClosureMethod::MaxLikelihood, "needs Monte Carlo hit counts"),
        ] {
            let err = enforce(&mut Full::new(1.0), &EnforceParams { method: m, ..closure() }).unwrap_err();
            assert!(err.exit_code() == 2 && err.to_string().contains(says), "{m:?}: {err}");
        }
    }

    #[test]
    fn an_open_operator_gets_its_ambient_and_over_full_rows_scaled() {
        // a and b over-full by 10 %, c short (without its self term: 3.3 of 4 m²).
        let mut op = Full::new(1.1);
        op.s[8] = 0.0;
        let p = EnforceParams { mode: Enforce::Reciprocity, open: true, ..closure() };
        let rep = enforce(&mut op, &p).unwrap();
        assert!(rep.before.max_row_error > 0.09, "{}", rep.before);
        assert!(rep.after.max_row_error <= CLOSURE_TOL, "{}", rep.after);
        let (sums, amb) = (op.row_sums(), op.ambient.clone().unwrap());
        for i in 0..3 {
            assert!(amb[i] >= 0.0 && (sums[i] + amb[i] - op.areas[i]).abs() <= 1e-12 * op.areas[i]);
        }
        // The over-full rows end full; c keeps its scale and its shortfall goes to the ambient.
        assert!(amb[0] <= 1e-11 && amb[1] <= 1e-11 && amb[2] > 0.7, "{amb:?}");
    }
}
