//! Turns validated TOML surfaces and loaded models into a [`Scene`]: name checks, property
//! resolution (props.rs), patching (patching.rs), obstructions.
//!
//! Surface order: the shaped `[[surface]]` entries in file order, then each model's surfaces
//! in `[[model]]` order and glTF traversal order. Obstructions keep their whole shape (a disk as
//! its regular polygon, a mesh as its triangles).
use super::gltf_scene::Model;
use super::patching::{self, Split};
use super::props::{resolve, Layer, Role};
use super::{Ambient, Disk, Scene, SceneBuilder, Shape};
use crate::error::InputError;
use crate::geometry::{DVec3, Polygon};
use crate::Result;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// A validated shape.
#[derive(Debug, Clone)]
pub enum ShapeSpec {
    /// A planar simple polygon.
    Polygon(Polygon),
    /// A parallelogram and its polygon.
    Rectangle {
        /// Corner.
        origin: DVec3,
        /// First edge.
        u: DVec3,
        /// Second edge.
        v: DVec3,
        /// o, o+u, o+u+v, o+v.
        polygon: Polygon,
    },
    /// A disk (unit normal) and its equal-area regular polygon.
    Disk {
        /// The exact disk.
        disk: Disk,
        /// Its regular polygon.
        polygon: Polygon,
    },
}

/// A validated `[[surface]]` entry; no shape = an override of a model surface.
#[derive(Debug, Clone)]
pub struct TomlSurface {
    /// Name.
    pub name: String,
    /// Line of its `[[surface]]` header.
    pub line: usize,
    /// Shape, or `None` for an override.
    pub shape: Option<ShapeSpec>,
    /// Its own properties.
    pub layer: Layer,
    /// `subdivide = [nu, nv]`.
    pub subdivide: Option<(usize, usize)>,
}

/// A loaded `[[model]]` with its property defaults.
#[derive(Debug, Clone)]
pub struct ModelEntry {
    /// The glTF surfaces.
    pub model: Model,
    /// The `[[model]]` entry's properties.
    pub layer: Layer,
    /// The mesh checks of a glTF, STL or OBJ file.
    pub report: Option<super::hygiene::MeshReport>,
    /// Notes from reading the file.
    pub notes: Vec<String>,
}

/// Builds the scene; `defaults` is the `[defaults]` layer (empty when absent).
pub fn assemble(
    path: &Path,
    title: Option<String>,
    ambient: Option<f64>,
    defaults: &Layer,
    surfaces: Vec<TomlSurface>,
    models: Vec<ModelEntry>,
) -> Result<Scene> {
    // Names: model surfaces first, then every [[surface]] is new, or an override of one.
    let mut model_names: HashMap<&str, (usize, usize)> = HashMap::new();
    for (m, entry) in models.iter().enumerate() {
        for (k, s) in entry.model.surfaces.iter().enumerate() {
            if let Some(&(m0, _)) = model_names.get(s.name.as_str()) {
                return Err(InputError::surface(
                    &entry.model.file,
                    &s.name,
                    format!(
                        "the name is also used by a surface of '{}'; names must be unique",
                        models[m0].model.file.display()
                    ),
                )
                .into());
            }
            model_names.insert(&s.name, (m, k));
        }
    }
    let mut seen: HashMap<&str, usize> = HashMap::new();
    let mut overrides: HashMap<(usize, usize), &TomlSurface> = HashMap::new();
    for s in &surfaces {
        let at = |p: String| InputError::surface(path, &s.name, p).at_line(s.line);
        if let Some(first) = seen.insert(&s.name, s.line) {
            return Err(at(format!(
                "duplicate name: line {first} already has a surface called '{}'",
                s.name
            ))
            .into());
        }
        match (&s.shape, model_names.get(s.name.as_str())) {
            (Some(_), Some(&(m, _))) => {
                return Err(at(format!(
                    "a surface of model '{}' has the same name; rename one, or drop the shape key to override its properties",
                    models[m].model.file.display()
                ))
                .into())
            }
            (None, Some(&mk)) => {
                overrides.insert(mk, s);
            }
            (None, None) => {
                return Err(at(
                    "no shape key: give exactly one of polygon, rectangle or disk (no [[model]] has a surface of this name to override)".into(),
                )
                .into())
            }
            (Some(_), None) => {}
        }
    }

    let mut b = SceneBuilder::default().source(path);
    if let Some(t) = &title {
        b = b.title(t);
    }
    let mut conflicts = Vec::new();
    let mut warnings = Vec::new();
    for s in surfaces.iter().filter(|s| s.shape.is_some()) {
        let r = resolve(&s.name, &[&s.layer, defaults]);
        let Some(shape) = &s.shape else { continue };
        if s.layer.role == Some(Role::Obstruction) {
            b = b.obstruction(&s.name, vec![whole(shape)]);
            continue;
        }
        let split = match (s.subdivide, r.max_patch_size) {
            (Some((nu, nv)), _) => Split::Grid(nu, nv),
            (None, Some(l)) => Split::MaxSize(l),
            (None, None) => Split::Whole,
        };
        let patches = match shape {
            ShapeSpec::Polygon(p) => patching::polygon(p, split),
            ShapeSpec::Rectangle { origin, u, v, .. } => patching::rectangle(*origin, *u, *v, split),
            ShapeSpec::Disk { disk, .. } => patching::disk(disk, split),
        }
        .map_err(|p| InputError::surface(path, &s.name, p).at_line(s.line))?;
        let shape = match shape {
            ShapeSpec::Polygon(_) => Shape::Polygon,
            ShapeSpec::Rectangle { origin, u, v, .. } => Shape::Rectangle { origin: *origin, u: *u, v: *v },
            ShapeSpec::Disk { disk, .. } => Shape::Disk(*disk),
        };
        conflicts.extend(r.conflict);
        b.push_surface(&s.name, shape, patches, r.emissivity, r.condition);
    }
    for (m, entry) in models.iter().enumerate() {
        for (k, ms) in entry.model.surfaces.iter().enumerate() {
            let own = overrides.get(&(m, k)).map(|s| &s.layer);
            let layers: Vec<&Layer> = own.into_iter().chain([&ms.extras, &entry.layer, defaults]).collect();
            let r = resolve(&ms.name, &layers);
            if ms.dropped > 0 {
                warnings.push(format!(
                    "{}: surface '{}': dropped {} degenerate triangle(s) of zero area",
                    entry.model.file.display(),
                    ms.name,
                    ms.dropped
                ));
            }
            if r.role == Role::Obstruction {
                b = b.obstruction(&ms.name, ms.triangles.clone());
                continue;
            }
            let patches = patching::mesh(&ms.triangles, r.max_patch_size).map_err(|p| {
                let e = InputError::surface(&entry.model.file, &ms.name, p);
                match overrides.get(&(m, k)) {
                    Some(o) => InputError { file: path.to_path_buf(), line: Some(o.line), ..e },
                    None => e,
                }
            })?;
            conflicts.extend(r.conflict);
            b.push_surface(&ms.name, Shape::Mesh, patches, r.emissivity, r.condition);
        }
    }
    let mut scene = b.build();
    scene.ambient = ambient.map(|temperature| Ambient { temperature });
    if scene.surfaces.is_empty() {
        return Err(InputError::file(path, "the scene has no exchanging surfaces").into());
    }
    scene.condition_errors = conflicts;
    scene.warnings = warnings;
    let files = models.iter().flat_map(|m| std::iter::once(&m.model.file).chain(&m.model.extra_files));
    for f in std::iter::once(path).chain(files.map(PathBuf::as_path)) {
        if !scene.inputs.iter().any(|i| i == f) {
            scene.inputs.push(f.to_path_buf());
        }
    }
    for entry in models {
        scene.warnings.extend(entry.notes);
        if let Some(r) = entry.report {
            let lines = super::hygiene::warnings(&r, &scene);
            scene.warnings.extend(lines);
            scene.meshes.push(r);
        }
    }
    Ok(scene)
}

/// The unsplit polygon of a shape (obstructions).
fn whole(shape: &ShapeSpec) -> Polygon {
    match shape {
        ShapeSpec::Polygon(p)
        | ShapeSpec::Rectangle { polygon: p, .. }
        | ShapeSpec::Disk { polygon: p, .. } => p.clone(),
    }
}
