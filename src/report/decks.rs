//! Thermal-network decks of the radiative conductances RADK_ij = A_i ε_i B_ij, for the network
//! solvers engineers already use:
//! - CSV `from,to,radk` (both directions, as before; [`super::solve_csv`]);
//! - SINDA/FLUINT: a `HEADER CONDUCTOR DATA` block of radiation conductors (negative conductor
//!   ids), `-id, node_a, node_b, G` with G = RADK in m²; SINDA multiplies by its `SIGMA`;
//! - ESATAN: a `$CONDUCTORS` block of `GR(node_a, node_b) = RADK;` in m²; ESATAN multiplies by
//!   its `STEFAN` constant.
//!
//! Network decks hold one conductor per unordered pair, ½(RADK_ij + RADK_ji) (equal to
//! round-off), and no self terms. Node numbers: the nodes in output order (scene order of
//! the surfaces, or of the patches with `--patches`) from 1; the ambient (space) node is
//! [`SPACE_NODE`]. Each file starts with comments giving σ, units, the scene and the node map.
use crate::solve::conductance::Conductances;
use crate::solve::AMBIENT;
use crate::{Error, Result};
use std::io::Write;
use std::path::Path;

/// Node number of the ambient / deep-space node (a boundary node in both solvers).
pub const SPACE_NODE: usize = 99999;

/// The conductance file formats (named in [`crate::choice`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum DeckFormat {
    /// `from,to,radk`, both directions.
    Csv,
    /// SINDA/FLUINT `HEADER CONDUCTOR DATA` block.
    Sinda,
    /// ESATAN `$CONDUCTORS` GR block.
    Esatan,
}

impl std::str::FromStr for DeckFormat {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        crate::choice::parse_or("conductance format", s)
    }
}

impl std::fmt::Display for DeckFormat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        crate::choice::write(self, f)
    }
}

impl DeckFormat {
    /// The format implied by the file extension: `.csv`; `.sin`, `.sinda`, `.inp` (SINDA);
    /// `.d`, `.esa`, `.esatan` (ESATAN). Stdout (`-`) is CSV.
    pub fn from_path(p: &Path) -> Result<Self> {
        if p.as_os_str() == "-" {
            return Ok(DeckFormat::Csv);
        }
        let ext = p.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("csv") => Ok(DeckFormat::Csv),
            Some("sin" | "sinda" | "inp") => Ok(DeckFormat::Sinda),
            Some("d" | "esa" | "esatan") => Ok(DeckFormat::Esatan),
            _ => Err(Error::Usage(format!(
                "{}: cannot tell the conductance format from the extension; use .csv, .sin/.sinda/.inp \
                 (SINDA/FLUINT) or .d/.esa/.esatan (ESATAN), or give {} csv|sinda|esatan",
                p.display(),
                crate::error::opt("format")
            ))),
        }
    }
}

/// What the deck header says about the run.
#[derive(Debug, Clone, PartialEq)]
pub struct DeckInfo {
    /// The scene file.
    pub scene: String,
    /// Its title, if any.
    pub title: Option<String>,
}

/// Node numbers in output order: 1, 2, … and [`SPACE_NODE`] for the ambient.
pub fn node_numbers(names: &[String]) -> Vec<usize> {
    names.iter().enumerate().map(|(i, n)| if n == AMBIENT { SPACE_NODE } else { i + 1 }).collect()
}

/// One conductor per unordered pair with a non-zero value: (i, j, ½(RADK_ij + RADK_ji)), i < j.
pub fn pairs(c: &Conductances) -> Vec<(usize, usize, f64)> {
    let n = c.names.len();
    let mut out = Vec::new();
    for i in 0..n {
        for j in i + 1..n {
            let g = 0.5 * (c.radk[i][j] + c.radk[j][i]);
            if g != 0.0 {
                out.push((i, j, g));
            }
        }
    }
    out
}

/// A value in the shortest round-trip exponent form Fortran readers accept (`1.25E-3`).
fn fortran(x: f64) -> String {
    format!("{x:E}")
}

/// Writes `c` in `format`.
pub fn write<W: Write>(
    format: DeckFormat,
    out: W,
    c: &Conductances,
    info: &DeckInfo,
    path: &Path,
) -> Result<()> {
    match format {
        DeckFormat::Csv => super::solve_csv::write_conductances(out, c, path),
        DeckFormat::Sinda => write_deck(out, c, info, path, &SINDA),
        DeckFormat::Esatan => write_deck(out, c, info, path, &ESATAN),
    }
}

/// The syntax of one network solver.
struct Dialect {
    comment: &'static str,
    stefan: &'static str,
    open: &'static str,
    conductor: fn(k: usize, a: usize, b: usize, g: &str) -> String,
}

const SINDA: Dialect = Dialect {
    comment: "C ",
    stefan: "SIGMA (CONTROL DATA)",
    open: "HEADER CONDUCTOR DATA, LAMBERT",
    conductor: |k, a, b, g| format!("-{k}, {a}, {b}, {g}"),
};

const ESATAN: Dialect = Dialect {
    comment: "# ",
    stefan: "STEFAN ($CONSTANTS)",
    open: "$CONDUCTORS",
    conductor: |_, a, b, g| format!("GR({a}, {b}) = {g};"),
};

fn write_deck<W: Write>(
    mut out: W,
    c: &Conductances,
    info: &DeckInfo,
    path: &Path,
    d: &Dialect,
) -> Result<()> {
    let io = |e| Error::Io { path: path.to_path_buf(), source: e };
    let nodes = node_numbers(&c.names);
    let cm = d.comment;
    let mut head = vec![
        format!("radiative conductors written by lambert {}", env!("CARGO_PKG_VERSION")),
        format!("scene: {}", info.scene),
    ];
    if let Some(t) = &info.title {
        head.push(format!("title: {t}"));
    }
    head.extend([
        "values: RADK = A_i eps_i B_ij (Gebhart), m^2; one conductor per node pair, no self terms"
            .to_string(),
        format!(
            "heat flow: Q = sigma * RADK * (T_a^4 - T_b^4), T in K, sigma = {:E} W/m^2/K^4",
            crate::SIGMA
        ),
        format!("set {} to that sigma (or the model's units' value)", d.stefan),
        "node map:".to_string(),
    ]);
    head.extend(c.names.iter().zip(&nodes).map(|(name, k)| format!("  {k} = {name}")));
    for line in head {
        writeln!(out, "{cm}{line}").map_err(io)?;
    }
    writeln!(out, "{}", d.open).map_err(io)?;
    for (k, (i, j, g)) in pairs(c).into_iter().enumerate() {
        writeln!(out, "{}", (d.conductor)(k + 1, nodes[i], nodes[j], &fortran(g))).map_err(io)?;
    }
    out.flush().map_err(io)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Conductances {
        Conductances {
            names: vec!["floor".into(), "wall".into(), AMBIENT.into()],
            emitting_area: vec![1.0, 2.0, f64::NAN],
            radk: vec![vec![0.1, 0.25, 0.4], vec![0.25 + 1e-17, 0.0, 0.5], vec![0.4, 0.5, 0.0]],
        }
    }

    #[test]
    fn formats_follow_extension_and_name() {
        for (p, f) in [("a.csv", DeckFormat::Csv), ("a.SIN", DeckFormat::Sinda), ("m.inp", DeckFormat::Sinda)]
        {
            assert_eq!(DeckFormat::from_path(Path::new(p)).unwrap(), f);
        }
        assert_eq!(DeckFormat::from_path(Path::new("m.d")).unwrap(), DeckFormat::Esatan);
        assert!(DeckFormat::from_path(Path::new("m.txt")).is_err());
        assert!("nastran".parse::<DeckFormat>().is_err());
        assert_eq!("esatan".parse::<DeckFormat>().unwrap(), DeckFormat::Esatan);
    }

    #[test]
    fn one_conductor_per_pair_without_self_terms() {
        let c = sample();
        let p = pairs(&c);
        assert_eq!(p.len(), 3);
        assert_eq!((p[0].0, p[0].1), (0, 1));
        assert_eq!(p[0].2, 0.5 * (0.25 + (0.25 + 1e-17)));
        assert_eq!(node_numbers(&c.names), vec![1, 2, SPACE_NODE]);
    }

    #[test]
    fn decks_carry_header_and_parse_back() {
        let c = sample();
        let info = DeckInfo { scene: "room.toml".into(), title: Some("Room".into()) };
        for (f, open) in [(DeckFormat::Sinda, "HEADER CONDUCTOR DATA"), (DeckFormat::Esatan, "$CONDUCTORS")] {
            let mut buf = Vec::new();
            write(f, &mut buf, &c, &info, Path::new("x")).unwrap();
            let text = String::from_utf8(buf).unwrap();
            assert!(
                text.contains("room.toml")
                    && text.contains("5.670374419E-8")
                    && text.contains("99999 = ambient")
            );
            let body: Vec<&str> = text.lines().skip_while(|l| !l.starts_with(open)).skip(1).collect();
            assert_eq!(body.len(), 3, "{text}");
            let last: Vec<String> = body[2]
                .replace(['(', ')', ';', '='], " ")
                .replace(',', " ")
                .split_whitespace()
                .map(String::from)
                .collect();
            let g: f64 = last.last().unwrap().parse().unwrap();
            assert_eq!(g, 0.5);
            assert!(last.contains(&"2".to_string()) && last.contains(&"99999".to_string()), "{text}");
        }
    }
}
