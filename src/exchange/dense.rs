//! The packed dense exchange store: the lean triangle (`PackedTriangular`) of symmetric
//! exchange areas with its node names and ambient column, as an [`Operator`] whose hooks serve
//! the one enforcement ([`fn@super::enforce`]) in place and without an N×N copy:
//! - the leak check of closed scenes on the raw rows (the triangle keeps their sums,
//!   variances and methods);
//! - closure and the capped scaling of open scenes by diagonal scales g, applied once
//!   (s̄_ij ← s̄_ij g_i g_j, row by row);
//! - the ambient column as an O(N) vector.
//!
//! Also here: the memory check before a dense store is allocated ([`check_fits`]), the build
//! ([`build`]) and the surface view factors of a patch-level store.
//!
//! The triangle already holds s̄ = ½(s + sᵀ): reciprocity is exact by storage. Under MPI the
//! triangle may be one rank's row block (`super::rowblock`): every hook that sums over the
//! store goes through the store's own methods (the mat-vec, row sums, self terms, scaling,
//! max |s̄| and sign count, couplings, leaking rows), which add the ranks' blocks in a fixed
//! order, so every rank runs the same enforcement on the same numbers.
use super::enforce::LEAK_SIGMAS;
use super::leak::LeakRow;
use super::operator::Operator;
use crate::error::InputError;
use crate::viewfactor::packed::PackedTriangular;
use crate::viewfactor::MethodSet;
use crate::Result;
use std::sync::OnceLock;

/// The packed triangle of exchange areas with node names and, for open scenes, the ambient.
#[derive(Debug, Clone, PartialEq)]
pub struct DenseExchange {
    /// The symmetric exchange areas.
    pub t: PackedTriangular,
    /// Node names.
    pub names: Vec<String>,
    /// S_i,amb = A_i − Σ_j S_ij for open scenes.
    pub ambient: Option<Vec<f64>>,
    /// (max |s̄_ij|, negatives) of the store as built, measured once.
    raw_stats: OnceLock<(f64, usize)>,
}

impl DenseExchange {
    /// A store of the packed triangle `t` with node names, before enforcement.
    pub fn new(t: PackedTriangular, names: Vec<String>) -> Self {
        Self { t, names, ambient: None, raw_stats: OnceLock::new() }
    }

    /// (max |s̄_ij|, count of negative entries) of the store as built, in one pass measured
    /// once (the scalings keep signs; the maximum is only the raw asymmetry's scale). A
    /// collective on a distributed store: enforcement first asks on every rank at the same
    /// step (the before-diagnostics, or the first scaling).
    fn raw_stats(&self) -> (f64, usize) {
        *self.raw_stats.get_or_init(|| self.t.max_abs_and_negatives())
    }
}

/// The packed store: symmetric by storage (it holds s̄), so reciprocity needs no step; the
/// raw rows' sums, variances and methods that the triangle keeps serve the diagnostics and the
/// leak check.
impl Operator for DenseExchange {
    fn len(&self) -> usize {
        self.t.n
    }
    fn areas(&self) -> &[f64] {
        &self.t.areas
    }
    fn matvec_scaled(&self, w: Option<&[f64]>, x: &[f64]) -> Vec<f64> {
        self.t.matvec_scaled(w, x)
    }
    fn self_term(&self, i: usize) -> f64 {
        // Any row's, also one another rank holds (the replicated diagonal).
        self.t.self_term(i)
    }
    fn row_sums(&self) -> Vec<f64> {
        self.t.row_sums()
    }
    fn couplings(&self, f: &mut dyn FnMut(usize, usize)) {
        super::ranks::couplings(&self.t, f);
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
    /// Multiplies s̄_ij by g_i g_j in place, the held rows in parallel (and the replicated
    /// diagonal of a distributed store).
    fn scale(&mut self, g: &[f64]) {
        self.raw_stats();
        self.t.scale(g);
    }
    fn raw_asymmetry(&self) -> f64 {
        let (smax, _) = self.raw_stats();
        if smax > 0.0 {
            self.t.raw_asymmetry / smax
        } else {
            0.0
        }
    }
    fn raw_row_sums(&self) -> Vec<f64> {
        self.t.raw_row_sums.clone()
    }
    fn negatives(&self) -> usize {
        self.raw_stats().1
    }
    /// Per node: the raw row's methods' own leak tolerance, or [`LEAK_SIGMAS`] standard
    /// errors of its sampled entries.
    fn leak_budget(&self, raw: &[f64]) -> Vec<(f64, f64)> {
        let t = &self.t;
        (0..t.n)
            .map(|i| {
                let sigma = t.raw_row_vars[i].sqrt() / t.areas[i];
                (raw[i] / t.areas[i], t.raw_row_methods[i].leak_tol().max(LEAK_SIGMAS * sigma))
            })
            .collect()
    }
    fn leak_rows(&self, leaks: &[(usize, f64)]) -> Vec<LeakRow> {
        super::ranks::rows_from_triangle(&self.t, &self.names, leaks)
    }
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
    Ok(Some(DenseExchange::new(t, names)))
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
