//! Exchange matrix: symmetric exchange areas S_ij = A_i F_ij, ambient node, enforcement and
//! diagnostics.
//!
//! - this file: [`Exchange`] (sparse S in sprs CSR, per-entry variance and method, ambient
//!   column), assembly from any method's [`ViewFactors`], symmetrisation s̄ = ½(s + sᵀ),
//!   aggregation to surfaces and conversion back to [`ViewFactors`] for output;
//! - `diagnostics`: row-sum, reciprocity and sign residuals, worst rows by name;
//! - [`mod@enforce`]: `--enforce none|reciprocity|closure`, the leak check and method dispatch:
//!   one function for every store;
//! - [`operator`]: the trait every store implements (sparse [`Exchange`], packed
//!   [`dense::DenseExchange`], clustered [`hierarchy::Hierarchy`]): the symmetric operator the
//!   solves work on and the hooks of the enforcement;
//! - `leak`: why a closed scene leaks, checked against the geometry facts;
//! - `scaling`: symmetric diagonal scaling s_ij = s̄_ij g_i g_j on any operator (also capped,
//!   for open scenes);
//! - `lsq`: weighted least squares s_ij = s̄_ij + w_ij(λ_i + λ_j), w = s̄ or 1 (sparse store);
//! - `ml`: constrained maximum likelihood s_ij = M_ij/(λ_i + λ_j) (Daun, Morton & Howell 2005;
//!   sparse store);
//! - [`dense`]: the packed dense store, its memory check and build;
//! - [`hierarchy`]: clustered exchange with error-bounded links for large scenes;
//! - `linalg`: deterministic parallel reductions and the PSD conjugate-gradient solver;
//! - `memory`: the memory a run may still allocate (free memory, rlimits, cgroup).
//!
//! Everything is O(nnz): no dense N×N temporary is ever formed.
use crate::viewfactor::{Entry, Level, MethodSet, ViewFactors};
use rayon::prelude::*;
use sprs::CsMat;
use std::time::Duration;

pub mod dense;
pub(crate) mod diagnostics;
pub mod enforce;
pub mod hierarchy;
pub(crate) mod leak;
pub(crate) mod linalg;
pub(crate) mod lsq;
pub(crate) mod memory;
pub(crate) mod ml;
pub mod operator;
pub(crate) mod ranks;
pub mod rowblock;
pub(crate) mod scaling;
pub(crate) mod sparse;

pub use diagnostics::Diagnostics;
/// One CSR row under construction: (columns, values, variances, methods).
type RowBuf = (Vec<usize>, Vec<f64>, Vec<f64>, Vec<MethodSet>);

pub use enforce::{enforce, ClosureMethod, Enforce, EnforceParams, EnforceReport};

/// Sparse exchange areas between the nodes (patches or surfaces) of a scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Exchange {
    /// Node level (patches or surfaces).
    pub level: Level,
    /// Node names, as in the view-factor output.
    pub names: Vec<String>,
    /// Node areas A_i, m².
    pub areas: Vec<f64>,
    /// S_ij = A_i F_ij, CSR with sorted columns; symmetric once reciprocity is enforced.
    pub s: CsMat<f64>,
    /// Variance of each stored S_ij, aligned with `s.data()`, m⁴.
    pub var: Vec<f64>,
    /// Method(s) behind each stored S_ij, aligned with `s.data()`.
    pub methods: Vec<MethodSet>,
    /// Rays behind each row for hit-counting estimators (0 = deterministic or unknown).
    pub samples: Vec<u32>,
    /// S_i,amb = A_i − Σ_j S_ij for open scenes (set by [`fn@enforce`]).
    pub ambient: Option<Vec<f64>>,
}

impl Exchange {
    /// Raw exchange areas s_ij = A_i F_ij from any method's view factors (not yet symmetric).
    pub fn from_viewfactors(vf: &ViewFactors) -> Self {
        let n = vf.names.len();
        let rows: Vec<&Vec<Entry>> = vf.rows.iter().collect();
        let mut indptr = Vec::with_capacity(n + 1);
        indptr.push(0usize);
        for r in &rows {
            indptr.push(indptr.last().copied().unwrap_or(0) + r.len());
        }
        let nnz = *indptr.last().unwrap_or(&0);
        let mut indices = vec![0usize; nnz];
        let mut data = vec![0.0; nnz];
        let mut var = vec![0.0; nnz];
        let mut methods = vec![MethodSet::default(); nnz];
        // Fill each row's slice in parallel: rows are disjoint ranges of the output arrays.
        let parts = split_rows(&indptr, &mut indices, &mut data, &mut var, &mut methods);
        parts.into_par_iter().enumerate().for_each(|(i, (ind, dat, va, me))| {
            let a = vf.areas[i];
            for (k, e) in rows[i].iter().enumerate() {
                ind[k] = e.to as usize;
                dat[k] = a * e.factor;
                va[k] = (a * e.std_error).powi(2);
                me[k] = e.method;
            }
        });
        let samples = match vf.level {
            Level::Patch if vf.patch_samples.len() == n => vf.patch_samples.clone(),
            _ => vec![0; n],
        };
        Self {
            level: vf.level,
            names: vf.names.clone(),
            areas: vf.areas.clone(),
            s: CsMat::new((n, n), indptr, indices, data),
            var,
            methods,
            samples,
            ambient: None,
        }
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.areas.len()
    }

    /// True when there are no nodes.
    pub fn is_empty(&self) -> bool {
        self.areas.is_empty()
    }

    /// CSR row pointer.
    pub fn indptr(&self) -> &[usize] {
        self.s.indptr().into_raw_storage()
    }

    /// Visits every stored entry as (S_ij, S_ji), S_ji = 0 when not stored, in row order and
    /// O(nnz) time: rows are sorted, so per row j a cursor only moves forward as i grows.
    pub fn fold_mirrored<T>(&self, init: T, mut f: impl FnMut(T, f64, f64) -> T) -> T {
        let (ip, idx, d) = (self.indptr(), self.s.indices(), self.s.data());
        let mut cursor: Vec<usize> = ip[..self.len()].to_vec();
        let mut acc = init;
        for i in 0..self.len() {
            for k in ip[i]..ip[i + 1] {
                let j = idx[k];
                let (c, end) = (&mut cursor[j], ip[j + 1]);
                while *c < end && idx[*c] < i {
                    *c += 1;
                }
                let sji = if *c < end && idx[*c] == i { d[*c] } else { 0.0 };
                acc = f(acc, d[k], sji);
            }
        }
        acc
    }

    /// S_ij, 0 when not stored.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        let (lo, hi) = (self.indptr()[i], self.indptr()[i + 1]);
        self.s.indices()[lo..hi].binary_search(&j).map(|k| self.s.data()[lo + k]).unwrap_or(0.0)
    }

    /// Σ_j S_ij per row (ambient excluded).
    pub fn row_sums(&self) -> Vec<f64> {
        let ip = self.indptr();
        let d = self.s.data();
        (0..self.len()).into_par_iter().map(|i| d[ip[i]..ip[i + 1]].iter().sum()).collect()
    }

    /// True when every row comes from a hit-counting Monte Carlo estimator (mc-cosine or
    /// mc-uniform with rays per row known): the case for constrained maximum likelihood.
    pub fn has_hit_counts(&self) -> bool {
        let mc = MethodSet::MC_COSINE.union(MethodSet::MC_UNIFORM);
        !self.is_empty()
            && self.samples.iter().all(|&n| n > 0)
            && self.methods.iter().all(|m| !m.is_empty() && m.union(mc) == mc)
    }

    /// Reciprocity by averaging: s̄ = ½(s + sᵀ), var̄ = ¼(var + varᵀ); the pattern becomes the
    /// union of both patterns.
    pub fn symmetrize(&mut self) {
        let t = self.transpose();
        let n = self.len();
        let (a, b) = (&*self, &t);
        let rows: Vec<RowBuf> = (0..n)
            .into_par_iter()
            .map(|i| {
                let (ra, rb) = (a.row(i), b.row(i));
                let mut out = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
                let (mut p, mut q) = (0, 0);
                while p < ra.0.len() || q < rb.0.len() {
                    let ja = ra.0.get(p).copied().unwrap_or(usize::MAX);
                    let jb = rb.0.get(q).copied().unwrap_or(usize::MAX);
                    let j = ja.min(jb);
                    let (mut s, mut v, mut m) = (0.0, 0.0, MethodSet::default());
                    if ja == j {
                        (s, v, m) = (s + ra.1[p], v + ra.2[p], m.union(ra.3[p]));
                        p += 1;
                    }
                    if jb == j {
                        (s, v, m) = (s + rb.1[q], v + rb.2[q], m.union(rb.3[q]));
                        q += 1;
                    }
                    out.0.push(j);
                    out.1.push(0.5 * s);
                    out.2.push(0.25 * v);
                    out.3.push(m);
                }
                out
            })
            .collect();
        self.set_rows(rows);
    }

    /// Row i as (columns, values, variances, methods).
    fn row(&self, i: usize) -> (&[usize], &[f64], &[f64], &[MethodSet]) {
        let (lo, hi) = (self.indptr()[i], self.indptr()[i + 1]);
        (&self.s.indices()[lo..hi], &self.s.data()[lo..hi], &self.var[lo..hi], &self.methods[lo..hi])
    }

    /// The transpose, by a counting sort over columns (O(nnz), columns stay sorted).
    fn transpose(&self) -> Exchange {
        let n = self.len();
        let ip = self.indptr();
        let mut count = vec![0usize; n + 1];
        for &j in self.s.indices() {
            count[j + 1] += 1;
        }
        for k in 0..n {
            count[k + 1] += count[k];
        }
        let indptr = count.clone();
        let nnz = self.s.nnz();
        let (mut ind, mut dat, mut var) = (vec![0usize; nnz], vec![0.0; nnz], vec![0.0; nnz]);
        let mut met = vec![MethodSet::default(); nnz];
        for i in 0..n {
            for k in ip[i]..ip[i + 1] {
                let j = self.s.indices()[k];
                let dst = count[j];
                count[j] += 1;
                (ind[dst], dat[dst], var[dst], met[dst]) =
                    (i, self.s.data()[k], self.var[k], self.methods[k]);
            }
        }
        Exchange {
            s: CsMat::new((n, n), indptr, ind, dat),
            var,
            methods: met,
            ambient: None,
            ..self.clone_meta()
        }
    }

    fn clone_meta(&self) -> Exchange {
        Exchange {
            level: self.level,
            names: self.names.clone(),
            areas: self.areas.clone(),
            s: CsMat::zero((0, 0)),
            var: Vec::new(),
            methods: Vec::new(),
            samples: self.samples.clone(),
            ambient: self.ambient.clone(),
        }
    }

    /// Replaces the matrix by the given sorted rows.
    fn set_rows(&mut self, rows: Vec<RowBuf>) {
        let n = self.len();
        let mut indptr = vec![0usize];
        let (mut ind, mut dat, mut var, mut met) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for (c, d, v, m) in rows {
            ind.extend(c);
            dat.extend(d);
            var.extend(v);
            met.extend(m);
            indptr.push(ind.len());
        }
        self.s = CsMat::new((n, n), indptr, ind, dat);
        self.var = var;
        self.methods = met;
    }

    /// Sums nodes into groups: S_IJ = Σ_{i∈I, j∈J} S_ij, exact for reciprocity and closure.
    /// `group[i]` is node i's group; `names`/`areas` describe the groups.
    pub fn aggregate(&self, group: &[usize], names: Vec<String>, areas: Vec<f64>, level: Level) -> Exchange {
        let m = names.len();
        let mut acc: Vec<std::collections::BTreeMap<usize, (f64, f64, MethodSet)>> =
            vec![Default::default(); m];
        let mut samples = vec![0u32; m];
        for i in 0..self.len() {
            let gi = group[i];
            samples[gi] = samples[gi].saturating_add(self.samples[i]);
            let (c, d, v, me) = self.row(i);
            for k in 0..c.len() {
                let e = acc[gi].entry(group[c[k]]).or_insert((0.0, 0.0, MethodSet::default()));
                (e.0, e.1, e.2) = (e.0 + d[k], e.1 + v[k], e.2.union(me[k]));
            }
        }
        let ambient = self.ambient.as_ref().map(|amb| {
            let mut out = vec![0.0; m];
            for (i, a) in amb.iter().enumerate() {
                out[group[i]] += a;
            }
            out
        });
        let mut ex = Exchange {
            level,
            names,
            areas,
            s: CsMat::zero((m, m)),
            var: Vec::new(),
            methods: Vec::new(),
            samples,
            ambient,
        };
        let rows = acc
            .into_iter()
            .map(|r| {
                let mut out = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
                for (j, (s, v, me)) in r {
                    out.0.push(j);
                    out.1.push(s);
                    out.2.push(v);
                    out.3.push(me);
                }
                out
            })
            .collect();
        ex.set_rows(rows);
        ex
    }

    /// View factors F_ij = S_ij / A_i (with σ_F = √var / A_i) for the CSV writers.
    pub fn to_viewfactors(&self, wall: Duration) -> ViewFactors {
        let rows: Vec<Vec<Entry>> = (0..self.len())
            .into_par_iter()
            .map(|i| {
                let (c, d, v, me) = self.row(i);
                let a = self.areas[i];
                (0..c.len())
                    .filter(|&k| d[k] != 0.0)
                    .map(|k| Entry {
                        to: c[k] as u32,
                        factor: d[k] / a,
                        std_error: v[k].sqrt() / a,
                        method: me[k],
                    })
                    .collect()
            })
            .collect();
        let patch_row_sums = self.row_sums().iter().zip(&self.areas).map(|(s, a)| s / a).collect();
        ViewFactors {
            level: self.level,
            names: self.names.clone(),
            areas: self.areas.clone(),
            rows,
            patch_row_sums,
            patch_samples: self.samples.clone(),
            pairs: 0,
            wall,
            warnings: Vec::new(),
            flags: Vec::new(),
        }
    }
}

type RowParts<'a> = (&'a mut [usize], &'a mut [f64], &'a mut [f64], &'a mut [MethodSet]);

/// Splits the CSR arrays into one mutable slice set per row.
fn split_rows<'a>(
    indptr: &[usize],
    mut ind: &'a mut [usize],
    mut dat: &'a mut [f64],
    mut var: &'a mut [f64],
    mut met: &'a mut [MethodSet],
) -> Vec<RowParts<'a>> {
    let mut out = Vec::with_capacity(indptr.len().saturating_sub(1));
    for w in indptr.windows(2) {
        let len = w[1] - w[0];
        let (a, ra) = std::mem::take(&mut ind).split_at_mut(len);
        let (b, rb) = std::mem::take(&mut dat).split_at_mut(len);
        let (c, rc) = std::mem::take(&mut var).split_at_mut(len);
        let (d, rd) = std::mem::take(&mut met).split_at_mut(len);
        out.push((a, b, c, d));
        (ind, dat, var, met) = (ra, rb, rc, rd);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// The cursor sweep pairs every stored entry with its mirror exactly as a lookup does,
    /// on random patterns that are neither symmetric in values nor in structure.
    #[test]
    fn fold_mirrored_pairs_each_entry_with_its_mirror() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(5);
        for trial in 0..20 {
            let n = 1 + trial * 3;
            let mut tri = sprs::TriMat::new((n, n));
            for i in 0..n {
                for j in 0..n {
                    if rng.random_bool(0.3) {
                        tri.add_triplet(
                            i,
                            j,
                            if rng.random_bool(0.5) { 1.0 } else { rng.random_range(0.0..2.0) },
                        );
                    }
                }
            }
            let s: CsMat<f64> = tri.to_csr();
            let nnz = s.nnz();
            let ex = Exchange {
                level: Level::Patch,
                names: vec![String::new(); n],
                areas: vec![1.0; n],
                s,
                var: vec![0.0; nnz],
                methods: vec![MethodSet::default(); nnz],
                samples: vec![0; n],
                ambient: None,
            };
            let mut want = Vec::new();
            for (i, row) in ex.s.outer_iterator().enumerate() {
                for (j, &v) in row.iter() {
                    want.push((v, ex.get(j, i)));
                }
            }
            let got = ex.fold_mirrored(Vec::new(), |mut acc, s, sji| {
                acc.push((s, sji));
                acc
            });
            assert_eq!(got, want, "trial {trial}");
        }
    }
}
