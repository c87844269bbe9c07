//! Sinks: fold patch rows into the output matrix at surface or patch level, plus patch-level
//! row-sum diagnostics. Symmetric rows (j > i only) are mirrored with reciprocity
//! s_ji = s_ij. Storage is sparse: only non-zero entries are kept.
use super::engine::Row;
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

/// Accumulates rows in patch order.
pub(crate) struct Sink<'a> {
    scene: &'a Scene,
    level: Level,
    symmetric: bool,
    /// Output rows keyed by column; BTreeMap keeps sums in a fixed order.
    acc: Vec<BTreeMap<u32, Acc>>,
    patch_sums: Vec<f64>,
    samples: Vec<u32>,
    pairs: u64,
    /// Scratch: the current row folded to output columns.
    scratch: BTreeMap<u32, (f64, f64, f64, MethodSet)>,
}

impl<'a> Sink<'a> {
    pub(crate) fn new(scene: &'a Scene, level: Level, symmetric: bool) -> Self {
        let n_out = match level {
            Level::Surface => scene.surfaces.len(),
            Level::Patch => scene.patches.len(),
        };
        Self {
            scene,
            level,
            symmetric,
            acc: vec![BTreeMap::new(); n_out],
            patch_sums: vec![0.0; scene.patches.len()],
            samples: vec![0; scene.patches.len()],
            pairs: 0,
            scratch: BTreeMap::new(),
        }
    }

    fn out_index(&self, patch: usize) -> u32 {
        match self.level {
            Level::Surface => self.scene.patches[patch].surface as u32,
            Level::Patch => patch as u32,
        }
    }

    /// Folds row `i` in.
    pub(crate) fn accept(&mut self, i: usize, row: &Row) {
        let area_i = self.scene.patches[i].polygon.area();
        self.samples[i] = row.shared_samples;
        self.pairs += row.pairs;
        let oi = self.out_index(i);
        // Fold the row to output columns: Σ s, Σ var, Σ s² (for the multinomial union rule).
        self.scratch.clear();
        for e in &row.entries {
            let j = e.j as usize;
            self.patch_sums[i] += e.s / area_i;
            if self.symmetric {
                self.patch_sums[j] += e.s / self.scene.patches[j].polygon.area();
                let oj = self.out_index(j);
                let a = self.acc[oj as usize].entry(oi).or_default();
                a.s += e.s;
                a.var += e.var;
                a.method = a.method.union(e.method);
            }
            let oj = self.out_index(j);
            let t = self.scratch.entry(oj).or_insert((0.0, 0.0, 0.0, MethodSet::default()));
            t.0 += e.s;
            t.1 += e.var;
            t.2 += e.s * e.s;
            t.3 = t.3.union(e.method);
        }
        let n = row.shared_samples as f64;
        for (&oj, &(s, var, s2, method)) in &self.scratch {
            // Multinomial union: Var(Σ s_j) = Σ var_j + (Σ s_j² − (Σ s_j)²)/n.
            let var = if n > 0.0 { (var + (s2 - s * s) / n).max(0.0) } else { var };
            let a = self.acc[oi as usize].entry(oj).or_default();
            a.s += s;
            a.var += var;
            a.method = a.method.union(method);
        }
    }

    pub(crate) fn finish(self, wall: Duration) -> ViewFactors {
        let (names, areas): (Vec<String>, Vec<f64>) = match self.level {
            Level::Surface => self.scene.surfaces.iter().map(|s| (s.name.clone(), s.area)).unzip(),
            Level::Patch => (0..self.scene.patches.len())
                .map(|p| (self.scene.patch_name(p), self.scene.patches[p].polygon.area()))
                .unzip(),
        };
        let rows = self
            .acc
            .into_iter()
            .enumerate()
            .map(|(i, row)| {
                row.into_iter()
                    .filter(|(_, a)| a.s > 0.0)
                    .map(|(j, a)| Entry {
                        to: j,
                        factor: a.s / areas[i],
                        std_error: a.var.sqrt() / areas[i],
                        method: a.method,
                    })
                    .collect()
            })
            .collect();
        ViewFactors {
            level: self.level,
            names,
            areas,
            rows,
            patch_row_sums: self.patch_sums,
            patch_samples: self.samples,
            pairs: self.pairs,
            wall,
        }
    }
}
