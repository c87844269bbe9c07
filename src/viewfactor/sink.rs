//! Sinks: fold patch rows into the output matrix at surface or patch level, plus patch-level
//! row-sum diagnostics. Symmetric rows (j > i only) are mirrored with reciprocity
//! s_ji = s_ij. Storage is sparse: only non-zero entries are kept.
use super::row::Row;
use super::MethodSet;
use crate::scene::Scene;
use std::collections::BTreeMap;
use std::time::Duration;

/// Report per surface (default) or per patch (`--patches`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Level {
    /// Rows and columns are surfaces: F_IJ = Σ_{i∈I} (A_i/A_I) Σ_{j∈J} F_ij.
    Surface,
    /// Rows and columns are patches, named `surface#k`.
    Patch,
}

/// One non-zero view factor F(from → to) of a row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Entry {
    /// Column index.
    pub to: u32,
    /// F(from → to).
    pub factor: f64,
    /// Standard error of `factor` (0 for deterministic methods).
    pub std_error: f64,
    /// The method(s) that produced it.
    pub method: MethodSet,
}

/// A view-factor matrix with its diagnostics.
#[derive(Debug, Clone, PartialEq)]
pub struct ViewFactors {
    /// Row/column level.
    pub level: Level,
    /// Row/column names (surfaces, or `surface#k`).
    pub names: Vec<String>,
    /// Row/column areas, m².
    pub areas: Vec<f64>,
    /// Sparse rows, sorted by column.
    pub rows: Vec<Vec<Entry>>,
    /// Per patch: Σ_j F_ij before any enforcement.
    pub patch_row_sums: Vec<f64>,
    /// Per patch: samples behind the row (0 for deterministic methods).
    pub patch_samples: Vec<u32>,
    /// Patch pairs evaluated.
    pub pairs: u64,
    /// Wall time of the computation.
    pub wall: Duration,
    /// What the method reported about its own accuracy (entries above their error goal).
    pub warnings: Vec<String>,
    /// Patch pairs whose entry the method could not bound (reported on stderr).
    pub flags: Vec<super::Flag>,
}

impl ViewFactors {
    /// Σ_j F_ij per output row.
    pub fn row_sums(&self) -> Vec<f64> {
        self.rows.iter().map(|r| r.iter().map(|e| e.factor).sum()).collect()
    }
    /// F(from → to), 0 when absent.
    pub fn get(&self, from: usize, to: usize) -> f64 {
        self.rows[from]
            .binary_search_by_key(&(to as u32), |e| e.to)
            .map(|k| self.rows[from][k].factor)
            .unwrap_or(0.0)
    }
    /// Largest |Σ_j F_ij − 1| over patches, with the patch index.
    pub fn max_patch_row_error(&self) -> (f64, usize) {
        self.patch_row_sums.iter().enumerate().map(|(i, s)| ((s - 1.0).abs(), i)).fold((0.0, 0), |a, b| {
            if b.0 > a.0 {
                b
            } else {
                a
            }
        })
    }
}

#[derive(Default, Clone, Copy)]
struct Acc {
    s: f64,
    var: f64,
    method: MethodSet,
}

/// Output matrices with at most this many rows are accumulated densely (n² small cells, no
/// map lookups); larger ones (patch level) in ordered maps.
const DENSE_MAX_OUT: usize = 512;

/// Accumulated output: Σ s and Σ var per (row, column).
enum Store {
    /// n × n cells, row-major.
    Dense { n: usize, cells: Vec<Acc> },
    /// One ordered map per row.
    Sparse(Vec<BTreeMap<u32, Acc>>),
}

impl Store {
    fn cell(&mut self, row: u32, col: u32) -> &mut Acc {
        match self {
            Store::Dense { n, cells } => &mut cells[row as usize * *n + col as usize],
            Store::Sparse(rows) => rows[row as usize].entry(col).or_default(),
        }
    }
}

/// One row folded to output columns: Σ s, Σ var, Σ s² (multinomial union rule), methods.
#[derive(Default, Clone, Copy)]
struct Fold {
    s: f64,
    var: f64,
    s2: f64,
    method: MethodSet,
    /// Listed in `touched`.
    hit: bool,
}

/// Accumulates rows in patch order.
pub(crate) struct Sink<'a> {
    scene: &'a Scene,
    level: Level,
    symmetric: bool,
    /// Output patch index → output row/column.
    out: Vec<u32>,
    store: Store,
    /// Per patch: Σ_j s_ij before dividing by A_i.
    patch_s: Vec<f64>,
    samples: Vec<u32>,
    pairs: u64,
    /// Scratch for the current row: dense cells plus the columns touched.
    fold: Vec<Fold>,
    touched: Vec<u32>,
}

impl<'a> Sink<'a> {
    pub(crate) fn new(scene: &'a Scene, level: Level, symmetric: bool) -> Self {
        let out: Vec<u32> = match level {
            Level::Surface => scene.patches.iter().map(|p| p.surface as u32).collect(),
            Level::Patch => (0..scene.patches.len() as u32).collect(),
        };
        let n_out = match level {
            Level::Surface => scene.surfaces.len(),
            Level::Patch => scene.patches.len(),
        };
        let store = if n_out <= DENSE_MAX_OUT {
            Store::Dense { n: n_out, cells: vec![Acc::default(); n_out * n_out] }
        } else {
            Store::Sparse(vec![BTreeMap::new(); n_out])
        };
        Self {
            scene,
            level,
            symmetric,
            out,
            store,
            patch_s: vec![0.0; scene.patches.len()],
            samples: vec![0; scene.patches.len()],
            pairs: 0,
            fold: vec![Fold::default(); n_out],
            touched: Vec::new(),
        }
    }

    /// Folds row `i` in.
    pub(crate) fn accept(&mut self, i: usize, row: &Row) {
        self.samples[i] = row.shared_samples;
        self.pairs += row.pairs;
        let oi = self.out[i];
        // Fold the row to output columns: Σ s, Σ var, Σ s² (for the multinomial union rule).
        let mut row_s = 0.0;
        for e in &row.entries {
            let j = e.j as usize;
            let oj = self.out[j];
            row_s += e.s;
            if self.symmetric {
                self.patch_s[j] += e.s;
            }
            let t = &mut self.fold[oj as usize];
            if !t.hit {
                t.hit = true;
                self.touched.push(oj);
            }
            t.s += e.s;
            t.var += e.var;
            t.s2 += e.s * e.s;
            t.method = t.method.union(e.method);
        }
        self.patch_s[i] += row_s;
        let n = row.shared_samples as f64;
        for oj in self.touched.drain(..) {
            let t = std::mem::take(&mut self.fold[oj as usize]);
            if self.symmetric {
                // Reciprocity s_ji = s_ij: the row's entries in column J, mirrored into row J.
                let a = self.store.cell(oj, oi);
                a.s += t.s;
                a.var += t.var;
                a.method = a.method.union(t.method);
            }
            // Multinomial union: Var(Σ s_j) = Σ var_j + (Σ s_j² − (Σ s_j)²)/n.
            let var = if n > 0.0 { (t.var + (t.s2 - t.s * t.s) / n).max(0.0) } else { t.var };
            let a = self.store.cell(oi, oj);
            a.s += t.s;
            a.var += var;
            a.method = a.method.union(t.method);
        }
    }

    pub(crate) fn finish(self, wall: Duration) -> ViewFactors {
        let (names, areas): (Vec<String>, Vec<f64>) = match self.level {
            Level::Surface => self.scene.surfaces.iter().map(|s| (s.name.clone(), s.area)).unzip(),
            Level::Patch => (0..self.scene.patches.len())
                .map(|p| (self.scene.patch_name(p), self.scene.patches[p].polygon.area()))
                .unzip(),
        };
        let entry = |i: usize, j: u32, a: &Acc| Entry {
            to: j,
            factor: a.s / areas[i],
            std_error: a.var.sqrt() / areas[i],
            method: a.method,
        };
        let rows: Vec<Vec<Entry>> = match self.store {
            Store::Dense { n, cells } => (0..n)
                .map(|i| {
                    (0..n)
                        .filter(|&j| cells[i * n + j].s > 0.0 || cells[i * n + j].var > 0.0)
                        .map(|j| entry(i, j as u32, &cells[i * n + j]))
                        .collect()
                })
                .collect(),
            Store::Sparse(maps) => maps
                .into_iter()
                .enumerate()
                .map(|(i, row)| {
                    row.iter()
                        .filter(|(_, a)| a.s > 0.0 || a.var > 0.0)
                        .map(|(&j, a)| entry(i, j, a))
                        .collect()
                })
                .collect(),
        };
        let patch_row_sums =
            self.patch_s.iter().zip(&self.scene.patches).map(|(s, p)| s / p.polygon.area()).collect();
        ViewFactors {
            level: self.level,
            names,
            areas,
            rows,
            patch_row_sums,
            patch_samples: self.samples,
            pairs: self.pairs,
            wall,
            warnings: Vec::new(),
            flags: Vec::new(),
        }
    }
}
