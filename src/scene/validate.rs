//! Value checks shared by the TOML and glTF loaders. Each check returns the problem in plain
//! words; the caller adds file, surface and line.
use crate::geometry::{DVec3, PolygonError};

/// Largest coordinate or length accepted, m: beyond any engineering scene, and it keeps squared
/// distances and areas (≤ 1e24) far from f64 overflow.
pub const MAX_COORD: f64 = 1e12;

/// Highest temperature accepted, K: σT⁴ is then 5.7e16 W/m², far past any gray-body model;
/// larger values are typos (or overflow σT⁴ altogether).
pub const MAX_TEMPERATURE: f64 = 1e6;

/// Largest `subdivide` count per direction: 1e4 × 1e4 already exceeds the patch limit.
pub const MAX_SUBDIVISION: i64 = 10_000;

/// Most patches one surface may be split into: the N² view-factor pass cannot finish beyond
/// this; it catches typos such as a `max_patch_size` in millimetres.
pub const MAX_PATCHES_PER_SURFACE: usize = 1 << 18;

/// Most polygon segments for a disk: the equal-area 4096-gon is already within 1e-6 of the
/// circle everywhere, and validation stays O(n²)-cheap.
pub const MAX_SEGMENTS: i64 = 4096;

/// Most vertices of a TOML polygon: beyond hand-written outlines (use a glTF mesh), and it
/// bounds the O(n²) simplicity check and ear clipping.
pub const MAX_POLYGON_VERTICES: usize = 1024;

/// Default number of segments of a disk's regular polygon (docs/SPEC.md: `segments = 64`); its
/// circumradius is chosen so the polygon has the disk's area.
pub const DEFAULT_SEGMENTS: usize = 64;

/// Default emissivity when neither the surface, its model nor `[defaults]` gives one: black.
pub const DEFAULT_EMISSIVITY: f64 = 1.0;

/// A finite number.
pub fn finite(x: f64, what: &str) -> Result<f64, String> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(format!("{what} is {x}; it must be a finite number"))
    }
}

/// A finite point or vector with every coordinate within ±[`MAX_COORD`].
pub fn vector(p: [f64; 3], what: &str) -> Result<DVec3, String> {
    for x in p {
        finite(x, what)?;
        if x.abs() > MAX_COORD {
            return Err(format!("{what} has coordinate {x:e}, beyond ±{MAX_COORD:e} m"));
        }
    }
    Ok(DVec3::from_array(p))
}

/// A length in (0, [`MAX_COORD`]].
pub fn length(x: f64, what: &str) -> Result<f64, String> {
    finite(x, what)?;
    if x > 0.0 && x <= MAX_COORD {
        Ok(x)
    } else {
        Err(format!("{what} is {x}; it must be positive and at most {MAX_COORD:e} m"))
    }
}

/// Gray emissivity in (0, 1].
pub fn emissivity(e: f64) -> Result<f64, String> {
    finite(e, "emissivity")?;
    if e > 0.0 && e <= 1.0 {
        Ok(e)
    } else {
        Err(format!("emissivity is {e}; it must be in (0, 1] (0 < ε ≤ 1)"))
    }
}

/// Absolute temperature in (0, [`MAX_TEMPERATURE`]] K; a value that is a plausible °C one
/// (above absolute zero in °C) gets the °C hint.
pub fn temperature(t: f64, what: &str) -> Result<f64, String> {
    finite(t, what)?;
    if t > 0.0 && t <= MAX_TEMPERATURE {
        Ok(t)
    } else {
        Err(format!(
            "{what} is {t} K; it must be positive (kelvin) and at most {MAX_TEMPERATURE:e} K{}",
            celsius_hint(t)
        ))
    }
}

/// Absolute zero in °C.
const ZERO_CELSIUS_IN_KELVIN: f64 = 273.15;

/// `t` °C in kelvin, rounded to 1e-6 K so that −20 °C prints as 253.15 K, not 253.14999999999998.
fn kelvin_of_celsius(t: f64) -> f64 {
    ((t + ZERO_CELSIUS_IN_KELVIN) * 1e6).round() / 1e6
}

/// "; was t °C (… K) meant?" for a refused temperature that is a possible °C value (above
/// −273.15 and at most 0), else nothing.
fn celsius_hint(t: f64) -> String {
    if t > -ZERO_CELSIUS_IN_KELVIN && t <= 0.0 {
        format!("; temperatures are in kelvin: was {t} °C ({} K) meant?", kelvin_of_celsius(t))
    } else {
        String::new()
    }
}

/// Ambient (environment) temperature in [0, [`MAX_TEMPERATURE`]] K: deep space at 0 K is the
/// usual sink of a spacecraft radiator, and every net-radiation formula stays finite there
/// (E_b∞ = 0).
pub fn ambient_temperature(t: f64) -> Result<f64, String> {
    finite(t, "the ambient temperature")?;
    if (0.0..=MAX_TEMPERATURE).contains(&t) {
        Ok(t)
    } else {
        Err(format!(
            "the ambient temperature is {t} K; it must be at least 0 (kelvin) and at most {MAX_TEMPERATURE:e} K{}",
            celsius_hint(t)
        ))
    }
}

/// A temperature below this in a scene that reaches [`CELSIUS_HOT`] was probably given in
/// °C: 100 K (−173 °C) is colder than liquid oxygen, and 0–100 are everyday °C values.
pub const CELSIUS_COLD: f64 = 100.0;
/// See [`CELSIUS_COLD`]: 150 K (−123 °C) is colder than any heated, inhabited or sunlit
/// surface, so a scene that reaches it is at kelvin values where a 20 K entry reads as 20 °C
/// (300 K / 20 K and 200 K / 20 K both warn); a cryogenic scene that stays below it (20 K
/// hydrogen inside a 77 K nitrogen shield) does not.
pub const CELSIUS_HOT: f64 = 150.0;

/// Warnings for temperatures (surfaces, and an ambient above 0 K) below [`CELSIUS_COLD`] K
/// in a scene whose surfaces or ambient reach [`CELSIUS_HOT`] K: °C written where kelvin is
/// meant. The run goes on. An ambient at 0 K is deep space, never a suspect.
pub fn celsius_suspects(scene: &super::Scene) -> Vec<String> {
    use super::BoundaryCondition::Temperature;
    let given = |s: &super::Surface| match s.condition {
        Some(Temperature(t)) => Some(t),
        _ => None,
    };
    let ambient = scene.ambient.map(|a| a.temperature);
    let hottest = scene.surfaces.iter().filter_map(given).chain(ambient).fold(0.0, f64::max);
    if hottest < CELSIUS_HOT {
        return Vec::new();
    }
    let cold = |t: f64| t > 0.0 && t < CELSIUS_COLD;
    let surfaces = scene
        .surfaces
        .iter()
        .filter_map(|s| given(s).filter(|&t| cold(t)).map(|t| (format!("surface '{}'", s.name), t)));
    let ambient = ambient.filter(|&t| cold(t)).map(|t| ("the ambient".to_string(), t));
    surfaces
        .chain(ambient)
        .map(|(who, t)| {
            format!(
                "{}: {who}: temperature {t} K is below {CELSIUS_COLD} K while the scene reaches \
                 {hottest} K; temperatures are in kelvin: was {t} °C ({} K) meant?",
                scene.source.display(),
                kelvin_of_celsius(t)
            )
        })
        .collect()
}

/// Net outgoing flux, any finite value, W/m².
pub fn heat_flux(q: f64) -> Result<f64, String> {
    finite(q, "heat_flux")
}

/// An integer count in [min, max].
pub fn count(n: i64, what: &str, min: i64, max: i64) -> Result<usize, String> {
    if (min..=max).contains(&n) {
        Ok(n as usize)
    } else {
        Err(format!("{what} is {n}; it must be between {min} and {max}"))
    }
}

/// A polygon error in words.
pub fn polygon_problem(e: &PolygonError) -> String {
    match e {
        PolygonError::TooFewVertices(n) => format!("a polygon needs at least 3 distinct vertices, got {n}"),
        PolygonError::Degenerate => {
            "the polygon has zero area (its vertices are collinear or coincide)".into()
        }
        other => other.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges() {
        assert!(emissivity(1.0).is_ok() && emissivity(1e-9).is_ok());
        for bad in [0.0, -0.1, 1.0 + 1e-12, f64::NAN, f64::INFINITY] {
            assert!(emissivity(bad).unwrap_err().contains("emissivity"), "{bad}");
        }
        assert!(temperature(0.0, "temperature").is_err() && temperature(-3.0, "t").is_err());
        assert!(temperature(1e7, "temperature").is_err() && temperature(300.0, "t").is_ok());
        assert!(vector([0.0, f64::NAN, 0.0], "origin").unwrap_err().contains("finite"));
        assert!(vector([0.0, 1e308, 0.0], "origin").is_err());
        assert!(count(0, "subdivide", 1, 10).unwrap_err().contains("between 1 and 10"));
        assert!(length(-0.0, "radius").is_err());
    }

    #[test]
    fn negative_temperatures_near_celsius_get_the_hint() {
        let e = temperature(-20.0, "temperature").unwrap_err();
        assert!(e.contains("must be positive (kelvin)") && e.contains("was -20 °C (253.15 K) meant?"), "{e}");
        assert!(temperature(0.0, "temperature").unwrap_err().contains("was 0 °C (273.15 K) meant?"));
        let e = ambient_temperature(-40.0).unwrap_err();
        assert!(e.contains("at least 0 (kelvin)") && e.contains("was -40 °C (233.15 K) meant?"), "{e}");
        // Below absolute zero in °C: no hint, only the refusal.
        assert!(!temperature(-300.0, "temperature").unwrap_err().contains("°C"));
        assert!(!temperature(2e9, "temperature").unwrap_err().contains("°C"));
    }
}
