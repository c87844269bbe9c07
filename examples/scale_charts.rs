//! Charts of validation/scale.md from validation/scale_results.csv (written by hand from
//! bench_scale.sh output): wall time, peak memory and stored entries against the patch count
//! for both exchange paths, and the hierarchical path's heat-rate error against wall time.
//! Writes `scale_*.{svg,png,csv}` beside the results with the validation charts' style.
//!
//! Run: `cargo run --release --example scale_charts [-- FOLDER]` (default `validation`).
use lambert::report::charts::{self, okabe_ito, Chart, Series, Style};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// One row of scale_results.csv, by column name.
type Row = BTreeMap<String, String>;

fn num(r: &Row, key: &str) -> Option<f64> {
    r.get(key).and_then(|v| v.parse().ok())
}

/// The seven Okabe–Ito colours, then grey: eight distinct colours for the eight scaling series.
const PALETTE: [(u8, u8, u8); 8] = [
    okabe_ito::ALL[0],
    okabe_ito::ALL[1],
    okabe_ito::ALL[2],
    okabe_ito::ALL[3],
    okabe_ito::ALL[4],
    okabe_ito::ALL[5],
    okabe_ito::ALL[6],
    okabe_ito::GREY,
];

/// Series in first-seen order of their names, coloured from [`PALETTE`].
fn series(groups: Vec<(String, Vec<(f64, f64)>)>) -> Vec<Series> {
    groups
        .into_iter()
        .filter(|g| !g.1.is_empty())
        .enumerate()
        .map(|(k, (name, points))| Series {
            name,
            points,
            color: PALETTE[k % PALETTE.len()],
            style: Style::LinePoints,
        })
        .collect()
}

/// Groups rows by `key`, keeping first-seen order, with (x, y) from `xy`.
fn grouped(
    rows: &[&Row],
    key: impl Fn(&Row) -> String,
    xy: impl Fn(&Row) -> Option<(f64, f64)>,
) -> Vec<(String, Vec<(f64, f64)>)> {
    let mut out: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for r in rows {
        let k = key(r);
        let at = match out.iter().position(|g| g.0 == k) {
            Some(i) => i,
            None => {
                out.push((k, Vec::new()));
                out.len() - 1
            }
        };
        out[at].1.extend(xy(r));
    }
    out
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| "validation".into()));
    let mut rdr = csv::Reader::from_path(dir.join("scale_results.csv"))?;
    let rows: Vec<Row> = rdr.deserialize().collect::<Result<_, _>>()?;
    let scaling: Vec<&Row> = rows.iter().filter(|r| r["study"] == "scaling").collect();
    let name = |r: &Row| {
        let tol = if r["path"] == "hierarchical" { format!(" {}", r["tolerance"]) } else { String::new() };
        format!("{}, {}{tol}", r["scene"], r["path"])
    };
    for (key, y_label, stem, title) in [
        ("wall_s", "wall time [s]", "scale_time", "solve wall time (2 cores)"),
        ("rss_mb", "peak RSS [MB]", "scale_memory", "solve peak memory"),
        ("stored", "stored links + patch pairs", "scale_links", "exchange entries stored"),
    ] {
        let mut s = series(grouped(&scaling, name, |r| Some((num(r, "patches")?, num(r, key)?))));
        if key == "stored" {
            let n: Vec<f64> = s.iter().flat_map(|s| s.points.iter().map(|p| p.0)).collect();
            let (lo, hi) = n.iter().fold((f64::INFINITY, 0.0f64), |(l, h), &x| (l.min(x), h.max(x)));
            s.push(Series {
                name: "N²/2".into(),
                points: vec![(lo, lo * lo / 2.0), (hi, hi * hi / 2.0)],
                color: okabe_ito::GREY,
                style: Style::Dashed,
            });
        }
        let chart =
            Chart { title: title.into(), x_label: "patches N".into(), y_label: y_label.into(), series: s };
        charts::write(&chart, &dir, stem)?;
    }
    let tradeoff: Vec<&Row> = rows.iter().filter(|r| r["study"] == "tolerance").collect();
    let s =
        series(grouped(&tradeoff, |r| r["scene"].clone(), |r| Some((num(r, "wall_s")?, num(r, "error")?))));
    let chart = Chart {
        title: "hierarchical: heat-rate error against wall time".into(),
        x_label: "wall time [s]".into(),
        y_label: "max |ΔQ| / max |Q| (against dense)".into(),
        series: s,
    };
    charts::write(&chart, &dir, "scale_error_time")?;
    Ok(())
}
