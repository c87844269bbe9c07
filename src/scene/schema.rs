//! The TOML scene schema of docs/SPEC.md as serde types. Every table denies unknown keys; values
//! carry their byte span so later checks can name the line. Numbers are read as f64 / i64 and
//! range-checked afterwards (validate.rs), so messages say what is wrong in words.
use serde::Deserialize;
use toml::Spanned;

/// A number with its span.
pub type Num = Option<Spanned<f64>>;

/// A point or vector `[x, y, z]`: exactly three numbers (serde's `[f64; 3]` would drop a
/// fourth or fifth one silently).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Vec3(pub [f64; 3]);

impl<'de> Deserialize<'de> for Vec3 {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = Vec::<f64>::deserialize(d)?;
        <[f64; 3]>::try_from(v.as_slice())
            .map(Vec3)
            .map_err(|_| serde::de::Error::invalid_length(v.len(), &"3 numbers [x, y, z]"))
    }
}

/// The whole file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawScene {
    /// Optional title.
    pub title: Option<Spanned<String>>,
    /// Present = open scene.
    pub ambient: Option<Spanned<RawAmbient>>,
    /// Defaults for every surface and model.
    pub defaults: Option<Spanned<RawDefaults>>,
    /// `[[surface]]` entries in file order.
    #[serde(default)]
    pub surface: Vec<Spanned<RawSurface>>,
    /// `[[model]]` glTF references.
    #[serde(default)]
    pub model: Vec<Spanned<RawModel>>,
    /// `[[band]]` wavelength bands for semi-gray solves (bands.rs).
    #[serde(default)]
    pub band: Vec<Spanned<RawBand>>,
}

/// One `[[band]]`: wavelengths in µm; the last band may omit `upper` (∞).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawBand {
    /// Band name (e.g. "solar").
    pub name: Option<String>,
    /// Lower wavelength limit, µm.
    pub lower: Spanned<f64>,
    /// Upper wavelength limit, µm (absent = ∞).
    pub upper: Option<Spanned<f64>>,
}

/// `[ambient]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawAmbient {
    /// Black environment temperature, K.
    pub temperature: Spanned<f64>,
}

/// `[defaults]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawDefaults {
    /// Gray emissivity.
    pub emissivity: Num,
    /// Temperature, K.
    pub temperature: Num,
    /// Net outgoing flux, W/m².
    pub heat_flux: Num,
    /// Largest patch width, m.
    pub max_patch_size: Num,
}

/// One `[[surface]]`: a shaped surface, or (without a shape key) an override of a model surface.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSurface {
    /// Unique, non-empty name.
    pub name: Option<Spanned<String>>,
    /// Planar simple polygon, ≥ 3 vertices.
    pub polygon: Option<Spanned<Vec<Vec3>>>,
    /// Parallelogram o, o+u, o+u+v, o+v.
    pub rectangle: Option<Spanned<RawRectangle>>,
    /// Disk.
    pub disk: Option<Spanned<RawDisk>>,
    /// Gray emissivity.
    pub emissivity: Num,
    /// Temperature, K.
    pub temperature: Num,
    /// Net outgoing flux, W/m².
    pub heat_flux: Num,
    /// `"surface"` (default) or `"obstruction"`.
    pub role: Option<Spanned<String>>,
    /// `[nu, nv]`, or `[rings, sectors]` for a disk.
    pub subdivide: Option<Spanned<[i64; 2]>>,
    /// Largest patch width, m.
    pub max_patch_size: Num,
    /// Band emissivities, one per `[[band]]` (bands.rs).
    pub emissivity_bands: Option<Spanned<Vec<f64>>>,
}

/// `rectangle = { origin, u, v }`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawRectangle {
    /// Corner.
    pub origin: Vec3,
    /// First edge.
    pub u: Vec3,
    /// Second edge.
    pub v: Vec3,
}

/// `disk = { center, normal, radius, segments }`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawDisk {
    /// Centre.
    pub center: Vec3,
    /// Normal of the emitting side (any length > 0).
    pub normal: Vec3,
    /// Radius, m.
    pub radius: f64,
    /// Polygon segments (default 64).
    pub segments: Option<i64>,
}

/// One `[[model]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawModel {
    /// glTF, STL, OBJ or View3D file, relative to the scene file.
    pub file: Spanned<String>,
    /// Length unit of an STL or OBJ file's coordinates: m, mm, cm, in or ft.
    pub unit: Option<Spanned<String>>,
    /// Weld tolerance, m.
    pub weld: Num,
    /// Surfaces per `file`, `group` or `component`.
    pub split: Option<Spanned<String>>,
    /// Weld, orient and drop duplicates and slivers.
    pub repair: Option<Spanned<bool>>,
    /// Default emissivity for its surfaces.
    pub emissivity: Num,
    /// Default temperature, K.
    pub temperature: Num,
    /// Default net outgoing flux, W/m².
    pub heat_flux: Num,
    /// Default role of its surfaces.
    pub role: Option<Spanned<String>>,
    /// Largest patch width for its surfaces, m.
    pub max_patch_size: Num,
}
