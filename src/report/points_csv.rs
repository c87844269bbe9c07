//! Points in, point factors out (`lambert viewfactors SCENE --points points.csv`).
//!
//! **Input.** A CSV with a header naming the columns `x,y,z,nx,ny,nz` in any order, and an
//! optional `name`: one point per row, metres in the scene's frame (after a bare mesh's
//! `--unit`), the normal of any non-zero length. Points without a `name` column are
//! `point#k` (k from 0 in file order). Strict like the scene files: an unknown or repeated
//! column, a missing one, an empty file or one without points, a field that is not a number,
//! NaN or infinite values, a zero normal, and a repeated or empty name are input errors naming
//! the file, the line and the column.
//!
//! **Output.** The `viewfactors` CSV's own columns, `from,to,factor,std_error,method,geometry`:
//! `from` is the point, `to` a surface (or `surface#k` with `--patches`), one row per non-zero
//! factor, then in an open scene a `to = ambient` row with the rest of the hemisphere.
//! `std_error` is 0 (the factors are exact) and `geometry` holds the scene's fingerprint on the
//! first row, as in the matrix file.
use super::csv::{write_rows, Rows};
use crate::error::InputError;
use crate::viewfactor::points::{PointFactors, ViewPoint};
use crate::{Error, Result};
use std::collections::HashMap;
use std::io::Write;
use std::path::Path;

/// The coordinate columns, in the order [`ViewPoint::new`] takes them.
pub const COLUMNS: [&str; 6] = ["x", "y", "z", "nx", "ny", "nz"];
/// The optional name column.
pub const NAME: &str = "name";

/// Points read from a file, with their names.
#[derive(Debug, Clone, PartialEq)]
pub struct NamedPoints {
    /// The points, in file order.
    pub points: Vec<ViewPoint>,
    /// Their names (the `name` column, or `point#k`).
    pub names: Vec<String>,
}

/// Reads the points file at `path`.
pub fn read_points(path: &Path) -> Result<NamedPoints> {
    let text = std::fs::read(path)
        .map_err(|e| InputError::file(path, format!("cannot read the points file: {e}")))?;
    parse_points(&text, path)
}

/// Parses the points file `text` (named `path` in messages).
pub fn parse_points(text: &[u8], path: &Path) -> Result<NamedPoints> {
    let bad =
        |line: usize, problem: String| -> Error { InputError::file(path, problem).at_line(line).into() };
    let mut rdr = csv::ReaderBuilder::new().trim(csv::Trim::All).from_reader(text);
    let headers = rdr.headers().map_err(|e| bad(1, format!("cannot read the header: {e}")))?.clone();
    if headers.iter().all(str::is_empty) {
        return Err(bad(
            1,
            "the file is empty; expected a header x,y,z,nx,ny,nz (and optionally name)".into(),
        ));
    }
    let mut cols = [usize::MAX; 6];
    let mut name_col = None;
    for (k, h) in headers.iter().enumerate() {
        let slot = match COLUMNS.iter().position(|c| *c == h) {
            Some(c) => &mut cols[c],
            None if h == NAME => name_col.get_or_insert(usize::MAX),
            None => {
                return Err(bad(
                    1,
                    format!("unknown column '{h}'; expected x,y,z,nx,ny,nz and optionally name"),
                ))
            }
        };
        if *slot != usize::MAX {
            return Err(bad(1, format!("column '{h}' appears twice")));
        }
        *slot = k;
    }
    let missing: Vec<&str> =
        COLUMNS.iter().zip(cols).filter(|(_, c)| *c == usize::MAX).map(|(n, _)| *n).collect();
    if !missing.is_empty() {
        return Err(bad(
            1,
            format!("missing column(s) {}; the header must name x,y,z,nx,ny,nz", missing.join(",")),
        ));
    }
    let mut out = NamedPoints { points: Vec::new(), names: Vec::new() };
    let mut seen: HashMap<String, usize> = HashMap::new();
    for rec in rdr.records() {
        let rec = rec.map_err(|e| {
            let line = e.position().map_or(0, |p| p.line() as usize);
            bad(line, format!("malformed row: {}", csv_problem(&e)))
        })?;
        let line = rec.position().map_or(0, |p| p.line() as usize);
        let name = match name_col {
            Some(c) => rec.get(c).unwrap_or("").to_string(),
            None => format!("point#{}", out.points.len()),
        };
        if name.is_empty() {
            return Err(bad(line, "column name: the point's name is empty".into()));
        }
        if let Some(first) = seen.insert(name.clone(), line) {
            return Err(bad(line, format!("column name: point '{name}' is already named on line {first}")));
        }
        let mut v = [0.0; 6];
        for (k, &c) in cols.iter().enumerate() {
            let field = rec.get(c).unwrap_or("");
            v[k] = field.parse::<f64>().map_err(|_| {
                bad(line, format!("point '{name}', column {}: '{field}' is not a number", COLUMNS[k]))
            })?;
        }
        let p = ViewPoint::new([v[0], v[1], v[2]], [v[3], v[4], v[5]])
            .map_err(|problem| bad(line, format!("point '{name}': {problem}")))?;
        out.points.push(p);
        out.names.push(name);
    }
    if out.points.is_empty() {
        return Err(bad(1, "no points: the file has a header but no rows".into()));
    }
    Ok(out)
}

/// The reason of a CSV error without the csv crate's position prefix.
fn csv_problem(e: &csv::Error) -> String {
    match e.kind() {
        csv::ErrorKind::UnequalLengths { expected_len, len, .. } => {
            format!("{len} fields where the header has {expected_len}")
        }
        csv::ErrorKind::Utf8 { .. } => "not valid UTF-8".into(),
        _ => e.to_string(),
    }
}

/// Writes `from,to,factor,std_error,method,geometry` for the point factors `pf` of the points
/// `names` ([`super::csv::write_rows`]); open scenes get a `to = ambient` row per point with
/// the rest of its hemisphere.
pub fn write_point_factors<W: Write>(
    out: W,
    pf: &PointFactors,
    names: &[String],
    open: bool,
    geometry: &str,
    path: &Path,
) -> Result<()> {
    write_rows(out, &Rows { from: names, to: &pf.names, rows: &pf.rows }, open, geometry, path)
}
