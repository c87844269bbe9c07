//! The `viewfactors` CSV (`from,to,factor,std_error,method,geometry`, docs/SPEC.md) streamed from the lean
//! packed triangle: rows are formatted in parallel, a block at a time, and written in order,
//! so the output never exists as a second matrix. Byte for byte the records of [`super::csv`]
//! (names are CSV-encoded once; numbers by [`super::push_f64`]).
use crate::viewfactor::packed::PackedTriangular;
use crate::viewfactor::MethodSet;
use crate::{Error, Result};
use rayon::prelude::*;
use std::io::Write;
use std::path::Path;

/// Rows formatted per block (bounds the text and the gathered columns held at once).
const BLOCK_ROWS: usize = 64;

/// A field as the csv crate writes it (quoted only when necessary).
fn encode(field: &str) -> Result<String> {
    let mut w = csv::WriterBuilder::new().has_headers(false).from_writer(Vec::new());
    w.write_record([field, "x"]).map_err(|e| Error::Compute(e.to_string()))?;
    let bytes = w.into_inner().map_err(|e| Error::Compute(e.to_string()))?;
    let text = String::from_utf8(bytes).map_err(|e| Error::Compute(e.to_string()))?;
    Ok(text.strip_suffix(",x\n").unwrap_or(&text).to_string())
}

/// Writes the view factors F_ij = s̄_ij / A_i of `t` (zeros skipped); open scenes get a
/// `to = ambient` row with the rest of each row, and the first row the fingerprint
/// `geometry`, as [`super::csv::write_viewfactors`].
pub fn write_triangle<W: Write>(
    mut out: W,
    t: &PackedTriangular,
    names: &[String],
    open: bool,
    geometry: &str,
    path: &Path,
) -> Result<()> {
    crate::viewfactor::range::check_triangle(t, names)?;
    let io = |e: std::io::Error| Error::Io { path: path.to_path_buf(), source: e };
    out.write_all(super::csv::HEADER.join(",").as_bytes()).map_err(io)?;
    out.write_all(b"\n").map_err(io)?;
    // The first record carries the fingerprint (rows end in an empty `geometry` field).
    let mut stamp = Some(encode(geometry)?);
    let mut write = |out: &mut W, text: &str| -> std::io::Result<()> {
        match (stamp.as_ref(), text.find('\n')) {
            (Some(g), Some(k)) => {
                out.write_all(&text.as_bytes()[..k])?;
                out.write_all(g.as_bytes())?;
                stamp = None;
                out.write_all(&text.as_bytes()[k..])
            }
            _ => out.write_all(text.as_bytes()),
        }
    };
    let names: Vec<String> = names.iter().map(|s| encode(s)).collect::<Result<_>>()?;
    let ambient = encode(crate::solve::AMBIENT)?;
    let n = t.n;
    let block = |lo: usize| -> Vec<String> {
        let hi = (lo + BLOCK_ROWS).min(n);
        // Column parts of the block's rows (s̄_ji = s̄_ij for j < lo), gathered row by row.
        let cols: Vec<Vec<f64>> =
            (lo..hi).into_par_iter().map(|i| (0..lo).map(|j| t.get(j, i)).collect()).collect();
        (lo..hi).into_par_iter().map(|i| row_text(t, &names, &ambient, open, i, &cols[i - lo])).collect()
    };
    // Pipeline: while this thread writes block k, the pool formats block k + 1.
    let mut pending = block(0);
    let mut lo = BLOCK_ROWS;
    while !pending.is_empty() {
        let next = std::thread::scope(|sc| {
            let job = sc.spawn(|| if lo < n { block(lo) } else { Vec::new() });
            let written = pending.iter().try_for_each(|text| write(&mut out, text));
            (job.join(), written)
        });
        next.1.map_err(io)?;
        pending = next.0.map_err(|_| Error::Compute("CSV formatting thread panicked".into()))?;
        lo += BLOCK_ROWS;
    }
    out.flush().map_err(io)
}

/// The records of row i; `col[j]` = s̄_ji for the columns j before the block.
fn row_text(
    t: &PackedTriangular,
    names: &[String],
    ambient: &str,
    open: bool,
    i: usize,
    col: &[f64],
) -> String {
    let mut out = String::with_capacity(64 * t.n);
    let a = t.areas[i];
    let (mut sum, mut var_sum, mut methods) = (0.0, 0.0, MethodSet::default());
    let mut last: Option<(MethodSet, String)> = None;
    for j in 0..t.n {
        let s = if j < col.len() { col[j] } else { t.get(i, j) };
        let (method, var) = t.meta(i, j);
        // A zero estimate with an error (Monte Carlo: every sample blocked) is still reported.
        if s == 0.0 && var == 0.0 {
            continue;
        }
        let f = s / a;
        let se = var.sqrt() / a;
        sum += f;
        var_sum += se * se;
        methods = methods.union(method);
        out.push_str(&names[i]);
        out.push(',');
        out.push_str(&names[j]);
        out.push(',');
        super::push_f64(&mut out, f);
        out.push(',');
        if !super::csv::unestimated(method) {
            super::push_f64(&mut out, se);
        }
        out.push(',');
        if last.as_ref().is_none_or(|l| l.0 != method) {
            last = Some((method, method.to_string()));
        }
        out.push_str(last.as_ref().map_or("", |l| l.1.as_str()));
        out.push_str(",\n");
    }
    let rest = (1.0 - sum).max(0.0);
    if open && rest > 0.0 {
        out.push_str(&names[i]);
        out.push(',');
        out.push_str(ambient);
        out.push(',');
        super::push_f64(&mut out, rest);
        out.push(',');
        if !super::csv::unestimated(methods) {
            super::push_f64(&mut out, var_sum.sqrt());
        }
        out.push(',');
        out.push_str(&methods.to_string());
        out.push_str(",\n");
    }
    out
}
