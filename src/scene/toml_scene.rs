//! The TOML scene loader: read, deserialize strictly (schema.rs), validate every value with
//! its line, load the `[[model]]` glTF files, then hand over to assemble.rs.
use super::assemble::{self, ShapeSpec, TomlSurface};
use super::mesh_model::{MeshOptions, Split, Unit};
use super::props::{Layer, Role};
use super::schema::{Num, RawDisk, RawModel, RawRectangle, RawScene, RawSurface, Vec3};
use super::toml_errors::{from_toml, Lines};
use super::validate::{self as v, DEFAULT_SEGMENTS, MAX_SEGMENTS, MAX_SUBDIVISION};
use super::{Disk, LoadOptions, Scene};
use crate::error::InputError;
use crate::geometry::subdivide::regular_polygon;
use crate::geometry::{Polygon, DEGENERACY_TOL};
use crate::Result;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// Loads and validates a TOML scene.
pub fn load(path: &Path) -> Result<Scene> {
    load_with(path, &LoadOptions::default())
}

/// [`load`] with explicit [`LoadOptions`] (passed on to the glTF models).
pub fn load_with(path: &Path, options: &LoadOptions) -> Result<Scene> {
    from_str_with(path, &super::text::read_text(path)?, options)
}

/// Validates TOML scene `text` as if read from `path` (model files resolve beside `path`).
pub fn from_str(path: &Path, text: &str) -> Result<Scene> {
    from_str_with(path, text, &LoadOptions::default())
}

/// [`from_str`] with explicit [`LoadOptions`].
pub fn from_str_with(path: &Path, text: &str, options: &LoadOptions) -> Result<Scene> {
    let text = text.to_string();
    let raw: RawScene = toml::from_str(&text).map_err(|e| from_toml(path, &text, &e))?;
    let lines = Lines::new(&text);
    let at = |offset: usize| lines.line(offset);
    let err = |surface: Option<&str>, offset: usize, problem: String| {
        let mut e = InputError::file(path, problem).at_line(at(offset));
        e.surface = surface.map(str::to_string);
        e
    };

    let ambient = match &raw.ambient {
        Some(a) => {
            let t = &a.get_ref().temperature;
            Some(v::ambient_temperature(*t.get_ref()).map_err(|p| err(None, t.span().start, p))?)
        }
        None => None,
    };
    let defaults = match &raw.defaults {
        Some(d) => {
            let d = d.get_ref();
            let mut layer = Layer::new("[defaults]", path, None);
            fill(&mut layer, &d.emissivity, &d.temperature, &d.heat_flux, &d.max_patch_size)
                .map_err(|(o, p)| err(None, o, format!("[defaults]: {p}")))?;
            layer.line = raw.defaults.as_ref().map(|d| at(d.span().start));
            layer
        }
        None => Layer::new("[defaults]", path, None),
    };

    let dir = path.parent().unwrap_or(Path::new(""));
    let mut models = Vec::with_capacity(raw.model.len());
    let mut model_warnings = Vec::new();
    for m in &raw.model {
        let (m, start) = (m.get_ref(), m.span().start);
        let file = m.file.get_ref();
        let where_ = format!("[[model]] '{file}'");
        let mut layer = Layer::new(where_.clone(), path, Some(at(start)));
        fill(&mut layer, &m.emissivity, &m.temperature, &m.heat_flux, &m.max_patch_size)
            .map_err(|(o, p)| err(None, o, format!("{where_}: {p}")))?;
        layer.role = role(&m.role).map_err(|(o, p)| err(None, o, format!("{where_}: {p}")))?;
        layer.check_role().map_err(|p| err(None, start, format!("{where_}: {p}")))?;
        let full: PathBuf = dir.join(file);
        if !full.is_file() {
            return Err(err(
                None,
                m.file.span().start,
                format!("model file '{}' does not exist", full.display()),
            )
            .into());
        }
        let opts = mesh_options(m).map_err(|(o, p)| err(None, o, format!("{where_}: {p}")))?;
        let Some(reader) = super::readers::find(&super::readers::MODELS, &full) else {
            let models = super::readers::expected(&super::readers::MODELS, |_| true);
            return Err(err(
                None,
                m.file.span().start,
                format!("{where_}: unknown model file type; a model is {models}"),
            )
            .into());
        };
        if reader.takes_mesh_options() && !reader.takes_unit_and_split() {
            let key = |k: &Option<Spanned<String>>| k.as_ref().map(|s| s.span().start);
            if let (Some(at), true) = (key(&m.unit), opts.unit != Unit::M) {
                return Err(err(None, at, format!("{where_}: glTF is in metres by its specification; unit applies to STL and OBJ models")).into());
            }
            if let Some(at) = key(&m.split) {
                return Err(err(None, at, format!("{where_}: a glTF model is split by its nodes (one surface per mesh node); split applies to STL and OBJ models")).into());
            }
        }
        if !reader.takes_mesh_options() && opts != MeshOptions::default() {
            return Err(err(
                None,
                start,
                format!("{where_}: unit, weld, split and repair apply to glTF, STL and OBJ models, not .vs3"),
            )
            .into());
        }
        let (entry, warnings) = reader.model(&full, &opts, layer, options)?;
        model_warnings.extend(warnings);
        models.push(entry);
    }

    let mut surfaces = Vec::with_capacity(raw.surface.len());
    for (k, s) in raw.surface.iter().enumerate() {
        surfaces.push(surface(path, &lines, k, s)?);
    }
    let title = raw.title.map(|t| t.into_inner());
    let mut scene = assemble::assemble(path, title, ambient, &defaults, surfaces, models)?;
    scene.warnings.extend(model_warnings);
    let mut band_warnings = Vec::new();
    scene.spectral =
        super::bands::from_raw(path, &text, &raw.band, &raw.surface, &scene, &mut band_warnings)?;
    scene.warnings.extend(band_warnings);
    Ok(scene)
}

type Located<T> = Result<T, (usize, String)>;

/// Fills a layer's numeric properties, each validated; errors carry the value's offset.
fn fill(layer: &mut Layer, e: &Num, t: &Num, q: &Num, l: &Num) -> Located<()> {
    let check = |n: &Num, f: &dyn Fn(f64) -> Result<f64, String>| -> Located<Option<f64>> {
        n.as_ref().map(|x| f(*x.get_ref()).map_err(|p| (x.span().start, p))).transpose()
    };
    layer.emissivity = check(e, &v::emissivity)?;
    layer.temperature = check(t, &|x| v::temperature(x, "temperature"))?;
    layer.heat_flux = check(q, &v::heat_flux)?;
    layer.max_patch_size = check(l, &|x| v::length(x, "max_patch_size"))?;
    Ok(())
}

/// The mesh keys of a `[[model]]`: unit, weld, split, repair.
fn mesh_options(m: &RawModel) -> Located<MeshOptions> {
    fn word(w: &Option<Spanned<String>>) -> Option<(usize, &str)> {
        w.as_ref().map(|s| (s.span().start, s.get_ref().as_str()))
    }
    let mut o = MeshOptions::default();
    if let Some((at, u)) = word(&m.unit) {
        o.unit = Unit::parse(u).map_err(|p| (at, p))?;
    }
    if let Some((at, s)) = word(&m.split) {
        o.split = Some(Split::parse(s).map_err(|p| (at, p))?);
    }
    if let Some(w) = &m.weld {
        let x = *w.get_ref();
        if !(x.is_finite() && (0.0..=v::MAX_COORD).contains(&x)) {
            return Err((w.span().start, format!("weld is {x}; give a tolerance in metres, 0 or more")));
        }
        o.weld = Some(x);
    }
    o.repair = m.repair.as_ref().is_some_and(|r| *r.get_ref());
    Ok(o)
}

fn role(r: &Option<Spanned<String>>) -> Located<Option<Role>> {
    r.as_ref().map(|s| Role::parse(s.get_ref()).map_err(|p| (s.span().start, p))).transpose()
}

/// Validates a surface name: non-empty, no '#', not "ambient", no control characters.
fn check_name(name: &str) -> Result<(), String> {
    if name.trim().is_empty() {
        Err("the name is empty; every surface needs a unique, non-empty name".into())
    } else if name.contains('#') {
        Err(format!(
            "names may not contain '#', which separates patch numbers in `{}` output",
            crate::error::opt("patches")
        ))
    } else if name == "ambient" {
        Err("'ambient' is reserved for the environment row of open scenes".into())
    } else if name.chars().any(char::is_control) {
        Err("the name contains control characters".into())
    } else {
        Ok(())
    }
}

/// Validates one `[[surface]]` entry (number k from 0).
fn surface(path: &Path, lines: &Lines, k: usize, s: &Spanned<RawSurface>) -> Result<TomlSurface, InputError> {
    let line = lines.line(s.span().start);
    let raw = s.get_ref();
    let Some(name_s) = &raw.name else {
        return Err(
            InputError::file(path, format!("[[surface]] number {} has no `name`", k + 1)).at_line(line)
        );
    };
    let name = name_s.get_ref().clone();
    let err = |offset: usize, p: String| InputError::surface(path, &name, p).at_line(lines.line(offset));
    check_name(&name).map_err(|p| {
        let mut e = err(name_s.span().start, p);
        if name.trim().is_empty() {
            e.surface = None;
            e.problem = format!("[[surface]] number {}: {}", k + 1, e.problem);
        }
        e
    })?;

    let keys: Vec<&str> = [
        ("polygon", raw.polygon.is_some()),
        ("rectangle", raw.rectangle.is_some()),
        ("disk", raw.disk.is_some()),
    ]
    .iter()
    .filter(|(_, on)| *on)
    .map(|(k, _)| *k)
    .collect();
    if keys.len() > 1 {
        return Err(err(s.span().start, format!("has {}; give exactly one shape key", keys.join(" and "))));
    }
    let shape = if let Some(p) = &raw.polygon {
        Some(polygon(p.get_ref()).map_err(|m| err(p.span().start, m))?)
    } else if let Some(r) = &raw.rectangle {
        Some(rectangle(r.get_ref()).map_err(|m| err(r.span().start, m))?)
    } else if let Some(d) = &raw.disk {
        Some(disk(d.get_ref()).map_err(|m| err(d.span().start, m))?)
    } else {
        None
    };

    let mut layer = Layer::new("this [[surface]]", path, Some(line));
    fill(&mut layer, &raw.emissivity, &raw.temperature, &raw.heat_flux, &raw.max_patch_size)
        .map_err(|(o, p)| err(o, p))?;
    layer.role = role(&raw.role).map_err(|(o, p)| err(o, p))?;
    layer.check_role().map_err(|p| err(s.span().start, p))?;
    let subdivide = match &raw.subdivide {
        Some(sd) => {
            let [a, b] = *sd.get_ref();
            let n =
                |x| v::count(x, "a subdivide count", 1, MAX_SUBDIVISION).map_err(|p| err(sd.span().start, p));
            if layer.max_patch_size.is_some() {
                return Err(err(sd.span().start, "give either subdivide or max_patch_size, not both".into()));
            }
            if layer.role == Some(Role::Obstruction) {
                return Err(err(
                    sd.span().start,
                    "an obstruction is not split into patches; remove subdivide".into(),
                ));
            }
            if shape.is_none() {
                return Err(err(
                    sd.span().start,
                    "subdivide needs a shape key; a model surface is split with max_patch_size".into(),
                ));
            }
            Some((n(a)?, n(b)?))
        }
        None => None,
    };
    Ok(TomlSurface { name, line, shape, layer, subdivide })
}

fn polygon(pts: &[Vec3]) -> Result<ShapeSpec, String> {
    if pts.len() > v::MAX_POLYGON_VERTICES {
        return Err(format!(
            "the polygon has {} vertices, more than the limit of {}; bring large outlines in as a glTF mesh",
            pts.len(),
            v::MAX_POLYGON_VERTICES
        ));
    }
    let vs = pts
        .iter()
        .enumerate()
        .map(|(k, p)| v::vector(p.0, &format!("polygon vertex {k}")))
        .collect::<Result<Vec<_>, _>>()?;
    Polygon::new(vs).map(ShapeSpec::Polygon).map_err(|e| v::polygon_problem(&e))
}

fn rectangle(r: &RawRectangle) -> Result<ShapeSpec, String> {
    let o = v::vector(r.origin.0, "rectangle origin")?;
    let u = v::vector(r.u.0, "rectangle u")?;
    let w = v::vector(r.v.0, "rectangle v")?;
    if !(u.cross(w).length() > DEGENERACY_TOL * u.length() * w.length())
        || u.length() == 0.0
        || w.length() == 0.0
    {
        return Err("rectangle u and v are parallel or zero: it has no area".into());
    }
    let poly = Polygon::new(vec![o, o + u, o + u + w, o + w]).map_err(|e| v::polygon_problem(&e))?;
    Ok(ShapeSpec::Rectangle { origin: o, u, v: w, polygon: poly })
}

fn disk(d: &RawDisk) -> Result<ShapeSpec, String> {
    let center = v::vector(d.center.0, "disk center")?;
    let normal = v::vector(d.normal.0, "disk normal")?;
    if !(normal.length() > 0.0) {
        return Err("disk normal is zero; give the direction the emitting side faces".into());
    }
    let radius = v::length(d.radius, "disk radius")?;
    let segments = v::count(d.segments.unwrap_or(DEFAULT_SEGMENTS as i64), "disk segments", 3, MAX_SEGMENTS)?;
    let disk = Disk { center, normal: normal.normalize(), radius, segments };
    let polygon = Polygon::new(regular_polygon(center, disk.normal, radius, segments)).map_err(|e| {
        format!(
            "the disk's polygon is degenerate (radius too small for its position?): {}",
            v::polygon_problem(&e)
        )
    })?;
    Ok(ShapeSpec::Disk { disk, polygon })
}
