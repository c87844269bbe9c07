//! CSV writers for `solve` (docs/SPEC.md): the per-surface / per-patch results table and the
//! radiative conductances `from,to,radk`.
use crate::solve::conductance::Conductances;
use crate::solve::Solution;
use crate::{Error, Result};
use std::io::Write;
use std::path::Path;

fn csv_err(path: &Path) -> impl Fn(csv::Error) -> Error + '_ {
    move |e| Error::Io { path: path.to_path_buf(), source: std::io::Error::other(e) }
}

/// Writes `surface,area,emissivity,temperature,heat_flux,heat_rate,radiosity,irradiation`;
/// open scenes end with an `ambient` row whose heat_rate makes the column sum to zero.
pub fn write_solution<W: Write>(out: W, sol: &Solution, path: &Path) -> Result<()> {
    let mut w = csv::Writer::from_writer(out);
    let err = csv_err(path);
    let mut header = vec![
        "surface",
        "area",
        "emissivity",
        "temperature",
        "heat_flux",
        "heat_rate",
        "radiosity",
        "irradiation",
    ];
    if sol.heat_rate_error.is_some() {
        header.push("heat_rate_error");
    }
    w.write_record(&header).map_err(&err)?;
    for (k, r) in sol.results.iter().enumerate() {
        let f = [
            sol.areas[k],
            sol.emissivity[k],
            r.temperature,
            r.heat_flux,
            r.heat_rate,
            r.radiosity,
            r.irradiation,
        ];
        let mut rec = vec![sol.names[k].clone()];
        rec.extend(f.iter().map(|v| super::fmt_f64(*v)));
        if let Some(e) = &sol.heat_rate_error {
            rec.push(super::fmt_f64(e[k]));
        }
        w.write_record(&rec).map_err(&err)?;
    }
    if let Some((t, q)) = sol.ambient {
        let e = crate::SIGMA * t.powi(4);
        // The ambient is black: emissivity 1, radiosity = emission; area and flux are undefined.
        let rec = [
            crate::solve::AMBIENT,
            "",
            "1",
            &super::fmt_f64(t),
            "",
            &super::fmt_f64(q),
            &super::fmt_f64(e),
            "",
            "",
        ];
        w.write_record(if sol.heat_rate_error.is_some() { &rec[..] } else { &rec[..8] }).map_err(&err)?;
    }
    w.flush().map_err(|e| Error::Io { path: path.to_path_buf(), source: e })
}

/// Writes `from,to,radk` for every non-zero conductance (ambient included).
pub fn write_conductances<W: Write>(out: W, c: &Conductances, path: &Path) -> Result<()> {
    let mut w = csv::Writer::from_writer(out);
    let err = csv_err(path);
    w.write_record(["from", "to", "radk"]).map_err(&err)?;
    for (i, row) in c.radk.iter().enumerate() {
        for (j, v) in row.iter().enumerate() {
            if *v != 0.0 {
                w.write_record([c.names[i].as_str(), c.names[j].as_str(), &super::fmt_f64(*v)])
                    .map_err(&err)?;
            }
        }
    }
    w.flush().map_err(|e| Error::Io { path: path.to_path_buf(), source: e })
}
