//! Reads one column of a `solve` CSV (per surface or `--patches`) and spreads it onto the
//! scene's patches: a surface row paints every patch of the surface, a patch row its patch.
//! Every mismatch (missing column, unknown or repeated name, missing row, bad number) is an
//! input error naming the file and line.
use crate::error::InputError;
use crate::scene::Scene;
use crate::{Error, Result};
use std::collections::HashMap;
use std::path::Path;

/// The columns of a `solve` CSV that can be shown (named in [`crate::choice`]: the column
/// names).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
#[value(rename_all = "snake_case")]
pub enum Field {
    /// Temperature, K.
    Temperature,
    /// Net outgoing heat flux, W/m².
    HeatFlux,
    /// Net outgoing heat rate, W.
    HeatRate,
    /// Radiosity, W/m².
    Radiosity,
    /// Irradiation, W/m².
    Irradiation,
    /// Emissivity.
    Emissivity,
    /// Area, m².
    Area,
}

impl Field {
    /// The unit of the column.
    pub fn unit(self) -> &'static str {
        match self {
            Field::Temperature => "K",
            Field::HeatFlux | Field::Radiosity | Field::Irradiation => "W/m²",
            Field::HeatRate => "W",
            Field::Emissivity => "–",
            Field::Area => "m²",
        }
    }
}

impl std::fmt::Display for Field {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        crate::choice::write(self, f)
    }
}

impl std::str::FromStr for Field {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        crate::choice::parse_or("field", s)
    }
}

/// One value per patch, and whether the file was per patch.
#[derive(Debug, Clone, PartialEq)]
pub struct PatchValues {
    /// Value of each patch, in patch order.
    pub values: Vec<f64>,
    /// True when the rows were patches (`surface#k`), false when surfaces.
    pub per_patch: bool,
}

/// Reads `field` from the `solve` CSV at `path` for the patches of `scene`.
pub fn read(path: &Path, scene: &Scene, field: Field) -> Result<PatchValues> {
    let field = field.to_string();
    let err = |line: Option<u64>, msg: String| {
        let e = InputError::file(path, msg);
        Error::Input(match line {
            Some(l) => e.at_line(l as usize),
            None => e,
        })
    };
    let file =
        std::fs::File::open(path).map_err(|e| err(None, format!("cannot read the result file: {e}")))?;
    let mut rdr = csv::ReaderBuilder::new().has_headers(true).from_reader(std::io::BufReader::new(file));
    let headers = rdr.headers().map_err(|e| err(Some(1), format!("not a CSV file: {e}")))?.clone();
    let name_col = headers
        .iter()
        .position(|h| h == "surface")
        .ok_or_else(|| err(Some(1), "not a `solve` result: the header has no 'surface' column".into()))?;
    let col = headers.iter().position(|h| h == field).ok_or_else(|| {
        err(
            Some(1),
            format!("no column '{field}'; the header has: {}", headers.iter().collect::<Vec<_>>().join(", ")),
        )
    })?;
    let surfaces: HashMap<&str, usize> =
        scene.surfaces.iter().enumerate().map(|(k, s)| (s.name.as_str(), k)).collect();
    let patches: HashMap<String, usize> =
        (0..scene.patches.len()).map(|p| (scene.patch_name(p), p)).collect();
    let mut values = vec![f64::NAN; scene.patches.len()];
    let mut seen = vec![false; scene.patches.len()];
    let mut per_patch: Option<bool> = None;
    for rec in rdr.records() {
        let rec = rec.map_err(|e| err(e.position().map(|p| p.line()), format!("malformed CSV: {e}")))?;
        let line = rec.position().map(|p| p.line());
        let name = rec.get(name_col).unwrap_or("");
        if name == crate::solve::AMBIENT {
            continue;
        }
        let (is_patch, range) = match (surfaces.get(name), patches.get(name)) {
            (Some(&s), _) => (false, scene.surfaces[s].patches.clone()),
            (None, Some(&p)) => (true, p..p + 1),
            (None, None) => {
                return Err(err(
                    line,
                    format!("'{name}' is neither a surface nor a patch of {}", scene.source.display()),
                ))
            }
        };
        match per_patch {
            None => per_patch = Some(is_patch),
            Some(pp) if pp != is_patch => {
                return Err(err(line, format!("'{name}' mixes surface and patch rows in one file")));
            }
            _ => {}
        }
        let text = rec.get(col).unwrap_or("").trim();
        let v: f64 = text
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .ok_or_else(|| err(line, format!("'{name}': {field} is not a finite number: '{text}'")))?;
        for p in range {
            if seen[p] {
                return Err(err(line, format!("'{name}' appears twice")));
            }
            seen[p] = true;
            values[p] = v;
        }
    }
    let per_patch = per_patch.ok_or_else(|| err(None, "the result file has no rows".into()))?;
    if let Some(p) = seen.iter().position(|s| !s) {
        let missing = if per_patch {
            scene.patch_name(p)
        } else {
            scene.surfaces[scene.patches[p].surface].name.clone()
        };
        return Err(err(
            None,
            format!(
                "no row for '{missing}' of {}: the file does not match the scene",
                scene.source.display()
            ),
        ));
    }
    Ok(PatchValues { values, per_patch })
}
