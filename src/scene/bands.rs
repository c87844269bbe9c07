//! Semi-gray bands in the scene file (a SPEC extension):
//!
//! ```toml
//! [[band]]
//! name = "solar"
//! lower = 0.0          # µm
//! upper = 4.0          # µm
//! [[band]]
//! name = "infrared"
//! lower = 4.0          # the last band may omit `upper`: it extends to ∞
//!
//! [[surface]]
//! name = "radiator"
//! emissivity_bands = [0.2, 0.9]   # one value per band, each in (0, 1]
//! ```
//!
//! Bands must start at 0 µm, be contiguous and end at ∞ so that every emitted watt belongs to a
//! band. A surface without `emissivity_bands` uses its gray emissivity in every band.
//! `emissivity_bands` without any `[[band]]` is an error. A surface entry that gives both
//! `emissivity` and `emissivity_bands` draws a warning: the solve uses the bands, and the gray
//! value only decides whether a gray `--conductances` deck is refused.
use super::schema::{RawBand, RawSurface};
use super::toml_errors::line_of;
use super::Scene;
use crate::error::InputError;
use crate::Result;
use std::path::Path;
use toml::Spanned;

/// One wavelength band, µm.
#[derive(Debug, Clone, PartialEq)]
pub struct SpectralBand {
    /// Name (defaults to `band#k`).
    pub name: String,
    /// Lower limit, µm.
    pub lower: f64,
    /// Upper limit, µm (∞ for the last band).
    pub upper: f64,
}

/// The band table and ε per surface and band.
#[derive(Debug, Clone, PartialEq)]
pub struct Spectral {
    /// Contiguous bands from 0 to ∞.
    pub bands: Vec<SpectralBand>,
    /// `emissivity[surface][band]`.
    pub emissivity: Vec<Vec<f64>>,
}

/// Builds the spectral table from the raw TOML, naming file, line and surface on errors;
/// warnings (a gray `emissivity` beside `emissivity_bands`) go to `warnings`.
pub fn from_raw(
    path: &Path,
    text: &str,
    raw: &[Spanned<RawBand>],
    surfaces: &[Spanned<RawSurface>],
    scene: &Scene,
    warnings: &mut Vec<String>,
) -> Result<Option<Spectral>> {
    let err = |offset: usize, surface: Option<&str>, p: String| {
        let mut e = InputError::file(path, p).at_line(line_of(text, offset));
        e.surface = surface.map(str::to_string);
        e
    };
    if raw.is_empty() {
        if let Some(s) = surfaces.iter().find(|s| s.get_ref().emissivity_bands.is_some()) {
            let name = s.get_ref().name.as_ref().map(|n| n.get_ref().as_str());
            return Err(err(s.span().start, name, "emissivity_bands needs a [[band]] table".into()).into());
        }
        return Ok(None);
    }
    let mut bands = Vec::with_capacity(raw.len());
    for (k, b) in raw.iter().enumerate() {
        let r = b.get_ref();
        let lower = *r.lower.get_ref();
        let upper = r.upper.as_ref().map_or(f64::INFINITY, |u| *u.get_ref());
        let name = r.name.clone().unwrap_or_else(|| format!("band#{k}"));
        let at = b.span().start;
        if k == 0 && lower != 0.0 {
            return Err(
                err(at, None, format!("[[band]] '{name}': the first band must start at lower = 0")).into()
            );
        }
        if let Some(prev) = bands.last().map(|p: &SpectralBand| p.upper) {
            if prev != lower {
                return Err(err(
                    at,
                    None,
                    format!(
                        "[[band]] '{name}': lower = {lower} must equal the previous band's upper = {prev}"
                    ),
                )
                .into());
            }
        }
        if !(lower.is_finite() && lower >= 0.0 && upper > lower) {
            return Err(err(
                at,
                None,
                format!("[[band]] '{name}': need 0 <= lower < upper (got {lower}, {upper})"),
            )
            .into());
        }
        if k + 1 == raw.len() && upper != f64::INFINITY {
            return Err(err(
                at,
                None,
                format!("[[band]] '{name}': the last band must omit `upper` (it extends to infinity)"),
            )
            .into());
        }
        bands.push(SpectralBand { name, lower, upper });
    }
    let mut emissivity: Vec<Vec<f64>> =
        scene.surfaces.iter().map(|s| vec![s.emissivity; bands.len()]).collect();
    for s in surfaces {
        let r = s.get_ref();
        let Some(eb) = &r.emissivity_bands else { continue };
        let name = r.name.as_ref().map(|n| n.get_ref().clone()).unwrap_or_default();
        let at = eb.span().start;
        let values = eb.get_ref();
        if values.len() != bands.len() {
            let p = format!("emissivity_bands has {} values for {} bands", values.len(), bands.len());
            return Err(err(at, Some(&name), p).into());
        }
        if let Some(v) = values.iter().find(|v| !(v.is_finite() && **v > 0.0 && **v <= 1.0)) {
            return Err(err(at, Some(&name), format!("band emissivity {v} is outside (0, 1]")).into());
        }
        if let Some(gray) = &r.emissivity {
            warnings.push(format!(
                "{}: line {}: surface '{name}': emissivity = {} is not used by the solve, which takes \
                 emissivity_bands = {values:?} in its bands; give only emissivity_bands (a gray \
                 {} deck is refused while the two differ)",
                path.display(),
                line_of(text, gray.span().start),
                gray.get_ref(),
                crate::error::opt("conductances"),
            ));
        }
        // Obstructions have no surface entry: their band emissivities are not used.
        if let Some(i) = scene.surface_index(&name) {
            emissivity[i] = values.clone();
        }
    }
    Ok(Some(Spectral { bands, emissivity }))
}
