//! CSV writers for docs/SPEC.md outputs. Numbers use Rust's shortest round-trip f64 formatting.
//!
//! The `viewfactors` file is `from,to,factor,std_error,method,geometry`. `geometry` holds the
//! scene's geometry fingerprint ([`crate::scene::fingerprint`]) on the first data row and is
//! empty on the others: `solve --viewfactors` then refuses a file written for another
//! geometry. An extra column keeps SPEC's header row first and every row the same width, so
//! plain CSV readers (pandas, the csv module, spreadsheets) read the file unchanged; a comment
//! line would push the header down, a sidecar file gets lost, and the value on every row would
//! add ~25 bytes per entry. Files without the column still load.
//!
//! `std_error` is empty where a projection method (hemicube, single-plane) took part: their
//! error is a bias they do not estimate, and a 0 would read as exact ([`std_error_field`]).
use crate::solve::AMBIENT;
use crate::viewfactor::{Entry, MethodSet, ViewFactors};
use crate::{Error, Result};
use std::io::Write;
use std::path::Path;

fn csv_err(path: &Path, e: csv::Error) -> Error {
    Error::Io { path: path.to_path_buf(), source: std::io::Error::other(e) }
}

/// Header of the `viewfactors` file.
pub const HEADER: [&str; 6] = ["from", "to", "factor", "std_error", "method", GEOMETRY];
/// Name of the column that carries the geometry fingerprint (first data row only).
pub const GEOMETRY: &str = "geometry";

/// True when `method` includes a projection method, whose entries carry no error estimate.
pub fn unestimated(method: MethodSet) -> bool {
    method.union(MethodSet::HEMICUBE) == method || method.union(MethodSet::SINGLE_PLANE) == method
}

/// The `std_error` field of an entry: empty when [`unestimated`], else the number.
pub fn std_error_field(method: MethodSet, std_error: f64) -> String {
    if unestimated(method) {
        String::new()
    } else {
        super::fmt_f64(std_error)
    }
}

/// Writes `from,to,factor,std_error,method,geometry` with the fingerprint `geometry` on the
/// first row; open scenes get a `to = ambient` row per source.
pub fn write_viewfactors<W: Write>(
    out: W,
    vf: &ViewFactors,
    open: bool,
    geometry: &str,
    path: &Path,
) -> Result<()> {
    crate::viewfactor::range::check(vf)?;
    write_rows(out, &Rows { from: &vf.names, to: &vf.names, rows: &vf.rows }, open, geometry, path)
}

/// Sparse factor rows with their names: row `i` is `from[i]`, an entry's column `to[e.to]`.
#[derive(Debug, Clone, Copy)]
pub struct Rows<'a> {
    /// Row names (surfaces, patches or points).
    pub from: &'a [String],
    /// Column names (surfaces or patches).
    pub to: &'a [String],
    /// The non-zero entries of each row, sorted by column.
    pub rows: &'a [Vec<Entry>],
}

/// The one writer of the `viewfactors` columns `from,to,factor,std_error,method,geometry`
/// (the matrix and the point factors): the fingerprint `geometry` on the first data row, and in
/// an open scene a `to = ambient` row per source with the rest of its hemisphere, whose
/// standard error is the root sum of squares of the row's.
pub fn write_rows<W: Write>(out: W, t: &Rows<'_>, open: bool, geometry: &str, path: &Path) -> Result<()> {
    debug_assert_eq!(t.from.len(), t.rows.len(), "one name per row");
    let mut w = csv::Writer::from_writer(out);
    let err = |e| csv_err(path, e);
    w.write_record(HEADER).map_err(err)?;
    let mut stamp = Some(geometry);
    let mut stamp = move || stamp.take().unwrap_or("");
    for (from, row) in t.from.iter().zip(t.rows) {
        for e in row {
            w.write_record([
                from.as_str(),
                t.to[e.to as usize].as_str(),
                &super::fmt_f64(e.factor),
                &std_error_field(e.method, e.std_error),
                &e.method.to_string(),
                stamp(),
            ])
            .map_err(err)?;
        }
        if open {
            let rest = (1.0 - row.iter().map(|e| e.factor).sum::<f64>()).max(0.0);
            let var: f64 = row.iter().map(|e| e.std_error * e.std_error).sum();
            let method = row.iter().fold(MethodSet::default(), |m, e| m.union(e.method));
            if rest > 0.0 {
                w.write_record([
                    from.as_str(),
                    AMBIENT,
                    &super::fmt_f64(rest),
                    &std_error_field(method, var.sqrt()),
                    &method.to_string(),
                    stamp(),
                ])
                .map_err(err)?;
            }
        }
    }
    w.flush().map_err(|e| Error::Io { path: path.to_path_buf(), source: e })
}
