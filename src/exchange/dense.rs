//! Enforcement on the lean packed triangle (`PackedTriangular`), in place and without an N×N copy:
//! - the leak check of closed scenes on the raw rows (same thresholds as [`mod@super::enforce`]:
//!   a leaking closed scene is refused, never stretched);
//! - closure by symmetric scaling s_ij = s̄_ij g_i g_j: Newton on log g with the scaled
//!   operator applied as g ∘ S̄(g ∘ x), so S̄ is only read until the single final rescaling;
//! - open scenes: over-full rows scaled down (g_i ≤ 1) and the ambient column as an O(N) vector;
//! - residual diagnostics (row sums, reciprocity, signs) before and after.
//!
//! The triangle already holds s̄ = ½(s + sᵀ): reciprocity is exact by storage.
use super::diagnostics::{Diagnostics, WORST_ROWS};
use super::enforce::{Enforce, EnforceParams, EnforceReport, LEAK_SIGMAS};
use super::linalg::{cg, max_iter, Linear, CG_TOL};
use super::operator::Operator;
use super::scaling::{MAX_CAPPED, MAX_NEWTON};
use crate::error::InputError;
use crate::viewfactor::packed::PackedTriangular;
use crate::viewfactor::MethodSet;
use crate::{Error, Result};

/// Loosest relative CG residual of a Newton step (inexact Newton forcing term).
const NEWTON_FORCING: f64 = 1e-2;

/// The packed triangle of exchange areas with node names and, for open scenes, the ambient.
#[derive(Debug, Clone, PartialEq)]
pub struct DenseExchange {
    /// The symmetric exchange areas.
    pub t: PackedTriangular,
    /// Node names.
    pub names: Vec<String>,
    /// S_i,amb = A_i − Σ_j S_ij for open scenes.
    pub ambient: Option<Vec<f64>>,
}

/// Rows of a closed scene short of 1 by more than the method's error (as
/// [`super::enforce::leaks`]): (node, row sum, threshold), worst first.
pub fn leaks(t: &PackedTriangular) -> Vec<(usize, f64, f64)> {
    let mut out: Vec<(usize, f64, f64)> = (0..t.n)
        .filter_map(|i| {
            let p = t.raw_row_sums[i] / t.areas[i];
            let m = t.raw_row_methods[i];
            let sigma = t.raw_row_vars[i].sqrt() / t.areas[i];
            let threshold = m.leak_tol().max(LEAK_SIGMAS * sigma);
            (1.0 - p > threshold).then_some((i, p, threshold))
        })
        .collect();
    out.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
    out
}

/// Residuals of the raw rows (before) or of the triangle with its ambient (after).
fn diagnostics(
    d: &DenseExchange,
    sums: &[f64],
    reciprocity: f64,
    open: bool,
    negatives: usize,
) -> Diagnostics {
    let negatives = negatives + d.ambient.as_ref().map_or(0, |a| a.iter().filter(|&&x| x < 0.0).count());
    Diagnostics::from_rows(sums, &d.t.areas, &d.names, open, reciprocity, negatives)
}

/// max |s̄_ij| and the count of negative entries, in one pass over the store.
fn max_abs_and_negatives(t: &PackedTriangular) -> (f64, usize) {
    t.max_abs_and_negatives()
}

/// Applies `p.mode` in place and sets the ambient of open scenes. Only the default closure
/// method (symmetric scaling) is served here; the others need the sparse store.
pub fn enforce(d: &mut DenseExchange, p: &EnforceParams) -> Result<EnforceReport> {
    let (smax, negatives) = max_abs_and_negatives(&d.t);
    let rec = if smax > 0.0 { d.t.raw_asymmetry / smax } else { 0.0 };
    let raw = d.t.raw_row_sums.clone();
    let before = diagnostics(d, &raw, rec, p.open, negatives);
    let (method, iterations) = match (p.mode, p.open) {
        (Enforce::None, _) => ("none (reciprocity average of the packed store)", 0),
        (Enforce::Reciprocity, false) => ("reciprocity average", 0),
        (_, true) => ("reciprocity average, over-full rows scaled", capped_scaling(&mut d.t, p.tolerance)?),
        (Enforce::Closure, false) => {
            refuse_leaks(d, p)?;
            ("symmetric scaling", symmetric_scaling(&mut d.t, p.tolerance)?)
        }
    };
    let sums = d.t.row_sums();
    if p.open {
        let amb = d.t.areas.iter().zip(&sums).map(|(a, s)| {
            let r = a - s;
            if r < 0.0 && -r <= p.tolerance * a * 10.0 {
                0.0
            } else {
                r
            }
        });
        d.ambient = Some(amb.collect());
    }
    // Both scalings multiply by g_i g_j > 0: signs, so the negative count, are kept.
    let after = diagnostics(d, &sums, 0.0, p.open, negatives);
    Ok(EnforceReport { before, after, method, iterations })
}

fn refuse_leaks(d: &DenseExchange, p: &EnforceParams) -> Result<()> {
    let leaks = leaks(&d.t);
    let Some(first) = leaks.first() else { return Ok(()) };
    let rows: Vec<(usize, f64)> = leaks.iter().map(|l| (l.0, l.1)).collect();
    let hint = super::enforce::refusal_hint(p, &super::leak::rows_from_triangle(&d.t, &d.names, &rows));
    let names: Vec<String> =
        leaks.iter().take(WORST_ROWS).map(|l| format!("{} (row sum {:.6})", d.names[l.0], l.1)).collect();
    Err(InputError::surface(
        &p.source,
        d.names[first.0].clone(),
        format!(
            "the closed scene leaks: {} row(s) sum to less than 1 by more than the method's error \
             ({:.1e}); worst: {}. {hint}; closure will not stretch a leaking row",
            leaks.len(),
            first.2,
            names.join(", ")
        ),
    )
    .into())
}

/// max_i |r_i / A_i − 1|.
fn closure_error(sums: &[f64], areas: &[f64]) -> f64 {
    sums.iter().zip(areas).map(|(s, a)| (s / a - 1.0).abs()).fold(0.0, f64::max)
}

/// Multiplies s̄_ij by g_i g_j in place.
fn rescale(t: &mut PackedTriangular, g: &[f64]) {
    t.scale(g);
}

/// Closure Σ_j s̄_ij g_i g_j = A_i by Newton on log g (the step solves
/// Σ_j w_ij(u_i + u_j) = A_i − Σ_j w_ij with w = the current scaled s, see `super::scaling`);
/// returns the CG iterations spent.
pub fn symmetric_scaling(t: &mut PackedTriangular, tol: f64) -> Result<usize> {
    let (g, total) = closure_scales(t, tol)?;
    rescale(t, &g);
    Ok(total)
}

/// The scales g of [`symmetric_scaling`] for any exchange operator, and the CG iterations
/// spent; the operator itself is left as it is.
pub fn closure_scales(t: &dyn Operator, tol: f64) -> Result<(Vec<f64>, usize)> {
    let n = t.len();
    let areas = t.areas();
    let ones = vec![1.0; n];
    let mut logg = vec![0.0; n];
    let mut g = ones.clone();
    let mut sums = t.matvec_scaled(Some(&g), &ones);
    let mut err = closure_error(&sums, areas);
    let mut total = 0;
    for _ in 0..MAX_NEWTON {
        if err <= tol {
            break;
        }
        let r: Vec<f64> = areas.iter().zip(&sums).map(|(a, s)| a - s).collect();
        // Operator diagonal Σ_j w_ij + w_ii.
        let diag: Vec<f64> = (0..n).map(|i| sums[i] + t.self_term(i) * g[i] * g[i]).collect();
        let apply = Linear {
            n,
            apply: |x: &[f64], y: &mut [f64]| {
                let wx = t.matvec_scaled(Some(&g), x);
                y.iter_mut().zip(wx).zip(&sums).zip(x).for_each(|(((y, w), s), x)| *y = w + s * x);
            },
        };
        // Inexact Newton: each step solved to the current closure error (quadratic
        // convergence is kept), never looser than NEWTON_FORCING.
        let goal = err.clamp(CG_TOL, NEWTON_FORCING);
        let (u, info) = cg(&apply, &diag, &r, goal, max_iter(n));
        let (it, res) = (info.iterations, info.residual);
        total += it;
        if res > goal && res > 1e-8 {
            return Err(Error::Compute(format!(
                "closure constraints have no solution (CG stopped at relative residual {res:.3e} after \
                 {it} iterations): a group of patches that see only each other has unequal areas on its two sides"
            )));
        }
        let mut step = 1.0;
        loop {
            let trial: Vec<f64> = logg.iter().zip(&u).map(|(l, u)| l + step * u).collect();
            let tg: Vec<f64> = trial.iter().map(|l| l.exp()).collect();
            let ts = t.matvec_scaled(Some(&tg), &ones);
            let e = closure_error(&ts, areas);
            if e < err || step < 1e-3 {
                (logg, g, sums, err) = (trial, tg, ts, e);
                break;
            }
            step *= 0.5;
        }
    }
    if err > tol {
        return Err(Error::Compute(format!(
            "symmetric scaling did not converge: closure error {err:.3e} after {MAX_NEWTON} Newton steps"
        )));
    }
    Ok((g, total))
}

/// Open scenes: scales rows whose sum exceeds A_i(1 + tol) down until Σ_j S_ij ≤ A_i, by
/// g_i ← min(1, √(g_i A_i / (S̄g)_i)); returns sweeps.
pub fn capped_scaling(t: &mut PackedTriangular, tol: f64) -> Result<usize> {
    let (g, sweeps) = capped_scales(t, tol)?;
    if g.iter().any(|&x| x != 1.0) {
        rescale(t, &g);
    }
    Ok(sweeps)
}

/// The scales g of [`capped_scaling`] for any exchange operator, and the sweeps spent.
pub fn capped_scales(t: &dyn Operator, tol: f64) -> Result<(Vec<f64>, usize)> {
    let n = t.len();
    let areas = t.areas();
    let mut g = vec![1.0; n];
    for sweep in 0..MAX_CAPPED {
        let r = t.matvec_scaled(None, &g);
        let over = (0..n).any(|i| g[i] * r[i] > areas[i] * (1.0 + tol));
        if !over {
            return Ok((g, sweep));
        }
        for i in 0..n {
            if r[i] > 0.0 {
                g[i] = (g[i] * areas[i] / r[i]).sqrt().min(1.0);
            }
        }
    }
    Err(Error::Compute(format!("capped scaling of over-full rows did not converge in {MAX_CAPPED} sweeps")))
}

/// Environment variable overriding the available memory in bytes (tests, batch schedulers).
pub use super::memory::MEM_AVAILABLE_ENV;
/// Peak bytes of the dense path per byte of the packed triangle: the triangle itself, the
/// exceptions of mixed rows and the O(N) vectors, with room to spare.
pub const DENSE_PEAK_FACTOR: f64 = 1.25;

/// Refuses (exit 2) a dense request for `n` nodes whose store, `bytes_per_pair` × n²/2 plus
/// headroom, exceeds the memory available to the process (`super::memory::available`:
/// free memory, rlimits, cgroup), before anything large is allocated.
pub fn check_fits(n: usize, bytes_per_pair: f64, source: &std::path::Path) -> Result<()> {
    let need = n as f64 * (n as f64 + 1.0) / 2.0 * bytes_per_pair * DENSE_PEAK_FACTOR;
    let Some(avail) = super::memory::available() else { return Ok(()) };
    if need <= avail.bytes as f64 {
        return Ok(());
    }
    Err(InputError::file(
        source,
        format!(
            "{n} patches need about {:.1} GB for the dense exchange matrix (n²/2 pairs × {bytes_per_pair} bytes) \
             but only {:.1} GB is available ({}); use `{} hierarchical`, or coarser `subdivide`",
            need / 1e9,
            avail.bytes as f64 / 1e9,
            avail.bound,
            crate::error::opt("exchange"),
        ),
    )
    .into())
}

/// Computes the patch-level lean store of `scene` (after the memory check); `None` when the
/// method needs the sparse store (Monte Carlo).
pub fn build(
    scene: &crate::scene::Scene,
    params: &crate::viewfactor::Params,
) -> Result<Option<DenseExchange>> {
    if params.method.is_monte_carlo() {
        return Ok(None);
    }
    check_fits(scene.patches.len(), 8.0, &scene.source)?;
    let Some(t) = crate::viewfactor::compute_triangle(scene, params)? else { return Ok(None) };
    let names = (0..scene.patches.len()).map(|p| scene.patch_name(p)).collect();
    Ok(Some(DenseExchange { t, names, ambient: None }))
}

/// Surface-level view factors of a patch-level store: S_IJ = Σ_{i∈I, j∈J} s̄_ij (variances
/// add, methods unite), F_IJ = S_IJ / A_I, accumulated in one n_s × n_s table.
pub fn to_surface_viewfactors(
    d: &DenseExchange,
    scene: &crate::scene::Scene,
    wall: std::time::Duration,
) -> crate::viewfactor::ViewFactors {
    use crate::viewfactor::{Entry, Level, ViewFactors};
    let t = &d.t;
    let m = scene.surfaces.len();
    let group: Vec<usize> = scene.patches.iter().map(|p| p.surface).collect();
    let mut s = vec![0.0; m * m];
    let mut var = vec![0.0; m * m];
    let mut met = vec![MethodSet::default(); m * m];
    for i in 0..t.n {
        let gi = group[i];
        let mut ex = t.exceptions[i].iter().peekable();
        for (k, &x) in t.row(i).iter().enumerate() {
            let j = i + k;
            let (mut me, mut v) = (t.row_method[i], 0.0);
            if ex.peek().is_some_and(|e| e.j as usize == j) {
                let e = ex.next().expect("peeked");
                (me, v) = (e.method, e.var);
            }
            if x == 0.0 {
                continue;
            }
            let gj = group[j];
            let mut add = |a: usize, b: usize| {
                s[a * m + b] += x;
                var[a * m + b] += v;
                met[a * m + b] = met[a * m + b].union(me);
            };
            add(gi, gj);
            if j != i {
                add(gj, gi);
            }
        }
    }
    let areas: Vec<f64> = scene.surfaces.iter().map(|s| s.area).collect();
    let rows: Vec<Vec<Entry>> = (0..m)
        .map(|a| {
            (0..m)
                .filter(|&b| s[a * m + b] != 0.0)
                .map(|b| Entry {
                    to: b as u32,
                    factor: s[a * m + b] / areas[a],
                    std_error: var[a * m + b].sqrt() / areas[a],
                    method: met[a * m + b],
                })
                .collect()
        })
        .collect();
    let patch_row_sums = t.row_sums().iter().zip(&t.areas).map(|(s, a)| s / a).collect();
    ViewFactors {
        level: Level::Surface,
        names: scene.surfaces.iter().map(|s| s.name.clone()).collect(),
        areas,
        rows,
        patch_row_sums,
        patch_samples: vec![0; t.n],
        pairs: t.pairs,
        wall,
        warnings: Vec::new(),
        flags: t.flags.clone(),
    }
}
