//! Scene level: named surfaces (what the engineer sees), their patches (the unknowns) and
//! obstructions (blockers only), with emissivities and boundary conditions.
//!
//! - this file: the in-memory model, [`SceneBuilder`] for programmatic scenes, [`load`] and
//!   [`Scene::check_boundary_conditions`];
//! - `schema`: the TOML format as serde types; [`toml_scene`]: the TOML loader;
//!   `toml_errors`: TOML errors with line and surface;
//! - `gltf_scene`: glTF 2.0 models as mesh surfaces;
//! - `stl_scene`, `obj_scene`: STL and OBJ files as triangle groups; [`mesh_model`]: their
//!   surfaces (unit, welding, split) and the checks of every model file; `mesh`: indexed
//!   meshes and welding; `hygiene`: the mesh checks, their warnings and `repair`;
//! - [`props`]: property layers (surface → node extras → model → defaults) and their resolution;
//! - [`validate`]: value checks and limits; [`patching`]: `subdivide` / `max_patch_size`;
//! - `assemble`: names, overrides, patches and obstructions into a [`Scene`];
//! - `orientation`: closed mesh surfaces whose normals face outward (leak hints);
//! - [`hints`]: facts behind other hints (obstructions in an enclosure, panels facing away);
//! - [`fingerprint`]: the geometry hash that saved view factors carry;
//! - [`vs3`]: View3D `.vs3` input files (F 3, F 3a) as a model or a whole scene;
//! - `bands`: the `[[band]]` table and `emissivity_bands` (semi-gray solves).
use crate::error::InputError;
use crate::geometry::tolerance::SURFACE_COPLANAR_TOL;
use crate::geometry::Polygon;
use glam::DVec3;
use std::ops::Range;
use std::path::PathBuf;

pub(crate) mod assemble;
pub(crate) mod bands;
pub mod fingerprint;
pub(crate) mod gltf_scene;
pub mod hints;
pub(crate) mod hygiene;
pub(crate) mod mesh;
pub mod mesh_model;
pub(crate) mod obj_scene;
pub(crate) mod orientation;
pub mod patching;
pub mod props;
pub(crate) mod readers;
pub(crate) mod schema;
pub(crate) mod stl_scene;
pub(crate) mod text;
pub(crate) mod toml_errors;
pub mod toml_scene;
pub mod validate;
pub mod vs3;

/// Boundary condition of an exchanging surface (used by `solve`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BoundaryCondition {
    /// Prescribed temperature, K.
    Temperature(f64),
    /// Prescribed net outgoing radiative flux, W/m² (0 = adiabatic).
    HeatFlux(f64),
}

/// How a surface was described; exact shapes are kept for closed-form checks.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// A planar polygon.
    Polygon,
    /// A parallelogram o, o+u, o+u+v, o+v.
    Rectangle {
        /// Corner.
        origin: DVec3,
        /// First edge.
        u: DVec3,
        /// Second edge.
        v: DVec3,
    },
    /// A disk, tessellated into a regular polygon for every method but the closed forms.
    Disk(Disk),
    /// A triangle mesh from glTF; may be non-planar.
    Mesh,
}

/// An exact disk. Every method but the closed forms sees its regular `segments`-gon whose
/// circumradius is r·√(2π / (n·sin(2π/n))), so the polygon keeps the disk's area πr².
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Disk {
    /// Centre.
    pub center: DVec3,
    /// Unit normal of the emitting side.
    pub normal: DVec3,
    /// Radius, m.
    pub radius: f64,
    /// Number of polygon segments used to tessellate it.
    pub segments: usize,
}

/// A named exchanging surface.
#[derive(Debug, Clone, PartialEq)]
pub struct Surface {
    /// Unique name, used in every output.
    pub name: String,
    /// Gray hemispherical emissivity, 0 < ε ≤ 1.
    pub emissivity: f64,
    /// Temperature or flux; `None` is allowed for `viewfactors`, refused by `solve`.
    pub condition: Option<BoundaryCondition>,
    /// How it was described.
    pub shape: Shape,
    /// Its patches, as a range into [`Scene::patches`].
    pub patches: Range<usize>,
    /// Total area, m².
    pub area: f64,
    /// True when every patch lies in one plane with one normal (then F_II = 0).
    pub planar: bool,
}

/// A patch: one planar polygon, the unit of the radiosity unknowns.
#[derive(Debug, Clone, PartialEq)]
pub struct Patch {
    /// The polygon.
    pub polygon: Polygon,
    /// Index of the owning surface in [`Scene::surfaces`].
    pub surface: usize,
}

/// A blocker: it casts shadows but takes no part in the exchange.
#[derive(Debug, Clone, PartialEq)]
pub struct Obstruction {
    /// Name from the scene file.
    pub name: String,
    /// Its one-sided polygons.
    pub polygons: Vec<Polygon>,
}

/// Open scenes see a black environment at this temperature.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ambient {
    /// Temperature, K.
    pub temperature: f64,
}

/// A loaded, validated scene.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Scene {
    /// Optional title.
    pub title: Option<String>,
    /// The file it came from (for messages); empty for programmatic scenes.
    pub source: PathBuf,
    /// Present for open scenes.
    pub ambient: Option<Ambient>,
    /// Exchanging surfaces in file order.
    pub surfaces: Vec<Surface>,
    /// All patches, grouped by surface in surface order.
    pub patches: Vec<Patch>,
    /// Obstruction-only geometry.
    pub obstructions: Vec<Obstruction>,
    /// Boundary-condition conflicts found at load time (both temperature and heat_flux);
    /// reported by [`Scene::check_boundary_conditions`], ignored by `viewfactors`.
    pub condition_errors: Vec<InputError>,
    /// Notes for the user from loading (e.g. dropped degenerate glTF triangles).
    pub warnings: Vec<String>,
    /// `[[band]]` table and per-surface band emissivities (semi-gray solve), when given.
    pub spectral: Option<bands::Spectral>,
    /// Run settings the scene file asks for where the command line is silent (View3D's
    /// `eps` and `encl`).
    pub run_defaults: RunDefaults,
    /// Every file read to build the scene: the scene file first, then model files and their
    /// buffers (so that no output of a run overwrites one of them).
    pub inputs: Vec<PathBuf>,
    /// The mesh checks of every glTF, STL and OBJ model file (leak hints read them).
    pub meshes: Vec<hygiene::MeshReport>,
}

/// Run settings a scene file may suggest; command-line options win.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RunDefaults {
    /// The `auto` tolerance.
    pub tolerance: Option<f64>,
    /// Enforce closure in `viewfactors` by default (a View3D `encl = 1` model).
    pub closure: bool,
}

impl Scene {
    /// Starts a programmatic scene.
    pub fn builder() -> SceneBuilder {
        SceneBuilder::default()
    }
    /// True when there is no `[ambient]`: a closed enclosure.
    pub fn is_closed(&self) -> bool {
        self.ambient.is_none()
    }
    /// Output name of patch `p`: `surface#k`, k counting from 0 within the surface.
    pub fn patch_name(&self, p: usize) -> String {
        let s = &self.surfaces[self.patches[p].surface];
        format!("{}#{}", s.name, p - s.patches.start)
    }
    /// Patch areas in patch order.
    pub fn patch_areas(&self) -> Vec<f64> {
        self.patches.iter().map(|p| p.polygon.area()).collect()
    }
    /// `solve`'s requirement: every exchanging surface has exactly one of temperature or
    /// heat_flux. Errors name the file and the first offending surface.
    pub fn check_boundary_conditions(&self) -> crate::Result<()> {
        if let Some(e) = self.condition_errors.first() {
            return Err(e.clone().into());
        }
        let missing: Vec<&Surface> = self.surfaces.iter().filter(|s| s.condition.is_none()).collect();
        if let Some(first) = missing.first() {
            let more = match missing.len() {
                1 => String::new(),
                n => format!(" ({} more surfaces lack one too)", n - 1),
            };
            let file = if self.source.as_os_str().is_empty() {
                PathBuf::from("<scene>")
            } else {
                self.source.clone()
            };
            return Err(InputError::surface(
                file,
                &first.name,
                format!(
                    "no boundary condition: `solve` needs exactly one of temperature (K) or heat_flux \
                     (W/m², 0 = adiabatic){more}"
                ),
            )
            .into());
        }
        Ok(())
    }
    /// Index of the surface called `name`.
    pub fn surface_index(&self, name: &str) -> Option<usize> {
        self.surfaces.iter().position(|s| s.name == name)
    }
}

/// Builds scenes in code (tests, benchmarks, generators).
#[derive(Debug, Default)]
pub struct SceneBuilder {
    scene: Scene,
}

impl SceneBuilder {
    /// Adds an exchanging surface made of the given patches.
    pub fn surface(
        mut self,
        name: &str,
        patches: Vec<Polygon>,
        emissivity: f64,
        condition: Option<BoundaryCondition>,
    ) -> Self {
        self.push_surface(name, Shape::Polygon, patches, emissivity, condition);
        self
    }
    /// Adds an exchanging surface with a known exact shape.
    pub fn shaped_surface(
        mut self,
        name: &str,
        shape: Shape,
        patches: Vec<Polygon>,
        emissivity: f64,
        condition: Option<BoundaryCondition>,
    ) -> Self {
        self.push_surface(name, shape, patches, emissivity, condition);
        self
    }
    /// Adds an obstruction.
    pub fn obstruction(mut self, name: &str, polygons: Vec<Polygon>) -> Self {
        self.scene.obstructions.push(Obstruction { name: name.to_string(), polygons });
        self
    }
    /// Makes the scene open to a black ambient at `temperature`.
    pub fn ambient(mut self, temperature: f64) -> Self {
        self.scene.ambient = Some(Ambient { temperature });
        self
    }
    /// Sets the title.
    pub fn title(mut self, title: &str) -> Self {
        self.scene.title = Some(title.to_string());
        self
    }
    /// Sets the source path used in messages.
    pub fn source(mut self, path: impl Into<PathBuf>) -> Self {
        self.scene.source = path.into();
        self
    }
    /// Finishes the scene.
    pub fn build(self) -> Scene {
        self.scene
    }

    /// Appends a surface and its patches; shared by the loaders.
    pub fn push_surface(
        &mut self,
        name: &str,
        shape: Shape,
        patches: Vec<Polygon>,
        emissivity: f64,
        condition: Option<BoundaryCondition>,
    ) -> usize {
        let index = self.scene.surfaces.len();
        let start = self.scene.patches.len();
        let area = patches.iter().map(Polygon::area).sum();
        let planar = is_planar_set(&patches);
        self.scene.patches.extend(patches.into_iter().map(|polygon| Patch { polygon, surface: index }));
        self.scene.surfaces.push(Surface {
            name: name.to_string(),
            emissivity,
            condition,
            shape,
            patches: start..self.scene.patches.len(),
            area,
            planar,
        });
        index
    }
}

/// True when all polygons share one plane and one facing.
fn is_planar_set(polys: &[Polygon]) -> bool {
    let Some(first) = polys.first() else { return true };
    let scale = polys.iter().map(|p| p.bounding_radius()).fold(0.0, f64::max).max(1e-300);
    polys.iter().all(|p| {
        p.normal().dot(first.normal()) > 1.0 - SURFACE_COPLANAR_TOL
            && p.vertices()
                .iter()
                .all(|v| first.plane_distance(*v).abs() <= SURFACE_COPLANAR_TOL * scale * 1e3)
    })
}

/// How a scene file is read: how it may reach other files, and the unit and repair options of
/// a bare STL, OBJ or glTF scene.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LoadOptions {
    /// Let glTF buffer files be absolute paths or lie outside the glTF file's folder
    /// (`--allow-outside-paths`).
    pub allow_outside_paths: bool,
    /// `--unit` and `--repair` of a bare mesh scene; a TOML scene sets them per `[[model]]`
    /// and refuses them here.
    pub bare: mesh_model::MeshOptions,
}

/// Loads a scene file (.toml, .gltf, .glb, .stl, .obj, .vs3) with strict validation. A bare
/// mesh file makes every mesh surface a surface with the built-in defaults (emissivity 1, no
/// boundary condition), glTF node `extras` applied.
pub fn load(path: &std::path::Path) -> crate::Result<Scene> {
    load_with(path, &LoadOptions::default())
}

/// [`load`] with explicit [`LoadOptions`].
pub fn load_with(path: &std::path::Path, options: &LoadOptions) -> crate::Result<Scene> {
    let mut scene = load_file(path, options)?;
    let suspects = validate::celsius_suspects(&scene);
    scene.warnings.extend(suspects);
    Ok(scene)
}

/// Every scene format, in the order the messages list them: the TOML scene, then the model
/// formats (`readers::MODELS`), each of which is a scene by itself too.
pub static READERS: [&dyn readers::Reader; 5] =
    [&TomlScene, &readers::Gltf, &readers::STL, &readers::OBJ, &readers::Vs3];

/// The TOML scene format (SPEC's): surfaces, `[[model]]` files, defaults and the ambient.
struct TomlScene;

impl readers::Reader for TomlScene {
    fn name(&self) -> &'static str {
        "TOML scene"
    }
    fn extensions(&self) -> &'static [&'static str] {
        &["toml"]
    }
    fn scene(&self, path: &std::path::Path, options: &LoadOptions) -> crate::Result<Scene> {
        toml_scene::load_with(path, options)
    }
    fn model(
        &self,
        path: &std::path::Path,
        _: &mesh_model::MeshOptions,
        _: props::Layer,
        _: &LoadOptions,
    ) -> crate::Result<(assemble::ModelEntry, Vec<String>)> {
        let models = readers::expected(&readers::MODELS, |_| true);
        Err(InputError::file(
            path,
            format!("a TOML scene cannot be a model of another scene; a model is {models}"),
        )
        .into())
    }
}

fn load_file(path: &std::path::Path, options: &LoadOptions) -> crate::Result<Scene> {
    let Some(reader) = readers::find(&READERS, path) else {
        let what = readers::expected(&READERS, |_| true);
        return Err(InputError::file(path, format!("unknown scene file type; expected {what}")).into());
    };
    if !reader.takes_mesh_options() && options.bare != mesh_model::MeshOptions::default() {
        return Err(crate::Error::Usage(format!(
            "{} and {} apply to {}; {} sets `unit` and `repair` per [[model]]",
            crate::error::opt("unit"),
            crate::error::opt("repair"),
            readers::expected(&READERS, |r| r.takes_mesh_options()).replacen("a ", "a bare ", 1),
            path.display()
        )));
    }
    reader.scene(path, options)
}

#[cfg(test)]
mod tests {
    use super::readers::Reader;
    use super::*;

    /// Every scene extension has one reader, TOML first, and a TOML scene is never a model.
    #[test]
    fn scene_readers_cover_every_format_once() {
        assert_eq!(readers::expected(&READERS, |_| true), "a .toml, .gltf, .glb, .stl, .obj or .vs3 file");
        for r in READERS {
            for e in r.extensions() {
                assert_eq!(READERS.iter().filter(|q| q.extensions().contains(e)).count(), 1, "{e}");
            }
        }
        let path = std::path::Path::new("room.toml");
        let e = TomlScene
            .model(
                path,
                &mesh_model::MeshOptions::default(),
                props::Layer::default(),
                &LoadOptions::default(),
            )
            .unwrap_err()
            .to_string();
        assert!(e.contains("room.toml") && e.contains("cannot be a model"), "{e}");
    }
}
