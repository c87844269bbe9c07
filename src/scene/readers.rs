//! The file formats lambert reads, one [`Reader`] each, found by extension: the model formats
//! here (glTF/GLB, STL, OBJ, View3D `.vs3`, listed in [`MODELS`]), and the TOML scene, which
//! holds models and so sits above them ([`super::READERS`]). A scene file on the command line
//! ([`super::load_with`]) and a `[[model]]` of a TOML scene go through the same rows, so a new
//! format is its own reader plus one line in a table.
use super::assemble::{self, ModelEntry};
use super::mesh_model::{self, MeshOptions, Split, Unit};
use super::props::Layer;
use super::{gltf_scene, obj_scene, stl_scene, vs3, LoadOptions, RunDefaults, Scene};
use crate::error::InputError;
use crate::Result;
use std::path::Path;

/// A file format lambert reads.
pub trait Reader: Sync {
    /// The format's name in messages.
    fn name(&self) -> &'static str;
    /// Its lower-case file extensions.
    fn extensions(&self) -> &'static [&'static str];
    /// True when the mesh options (`unit`, `weld`, `split`, `repair`) apply to its files.
    fn takes_mesh_options(&self) -> bool {
        false
    }
    /// True when `unit` and `split` apply (STL and OBJ; glTF is in metres and split by nodes).
    fn takes_unit_and_split(&self) -> bool {
        false
    }
    /// The file as a whole scene (`options.bare` holds the mesh options of a bare mesh file).
    fn scene(&self, path: &Path, options: &LoadOptions) -> Result<Scene> {
        let layer = Layer::new("the mesh file", path, None);
        let (entry, warnings) = self.model(path, &options.bare, layer, options)?;
        let mut scene = assemble::assemble(path, None, None, &Layer::default(), Vec::new(), vec![entry])?;
        scene.warnings.extend(warnings);
        Ok(scene)
    }
    /// The file as one model of a scene, with `layer`'s properties, and the warnings it adds to
    /// the scene.
    fn model(
        &self,
        path: &Path,
        opts: &MeshOptions,
        layer: Layer,
        options: &LoadOptions,
    ) -> Result<(ModelEntry, Vec<String>)>;
}

/// The formats a `[[model]]` may be, in the order the messages list them.
pub static MODELS: [&dyn Reader; 4] = [&Gltf, &STL, &OBJ, &Vs3];

/// The reader among `readers` of `path`'s extension (case-insensitive), if any.
pub fn find(readers: &[&'static dyn Reader], path: &Path) -> Option<&'static dyn Reader> {
    let ext = path.extension().and_then(|e| e.to_str())?.to_ascii_lowercase();
    readers.iter().copied().find(|r| r.extensions().contains(&ext.as_str()))
}

/// "a .gltf, … or .vs3 file" over the `readers` that `keep` accepts.
pub fn expected(readers: &[&dyn Reader], keep: impl Fn(&dyn Reader) -> bool) -> String {
    let exts: Vec<String> = readers
        .iter()
        .filter(|r| keep(**r))
        .flat_map(|r| r.extensions().iter().map(|e| format!(".{e}")))
        .collect();
    match exts.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("a {} or {last} file", rest.join(", ")),
        Some((last, _)) => format!("a {last} file"),
        None => "no file".into(),
    }
}

/// glTF 2.0, JSON or binary: metres, one surface per mesh node, with the mesh checks.
pub struct Gltf;

impl Reader for Gltf {
    fn name(&self) -> &'static str {
        "glTF"
    }
    fn extensions(&self) -> &'static [&'static str] {
        &["gltf", "glb"]
    }
    fn takes_mesh_options(&self) -> bool {
        true
    }
    fn model(
        &self,
        path: &Path,
        opts: &MeshOptions,
        layer: Layer,
        options: &LoadOptions,
    ) -> Result<(ModelEntry, Vec<String>)> {
        if opts.unit != Unit::M {
            return Err(InputError::file(
                path,
                "glTF coordinates are metres by the glTF specification; `unit` applies to STL and OBJ files",
            )
            .into());
        }
        if opts.split.is_some() {
            return Err(InputError::file(
                path,
                "a glTF model is split by its nodes (one surface per mesh node); `split` applies to STL and \
                 OBJ files",
            )
            .into());
        }
        let mut model = gltf_scene::load_model_with(path, options)?;
        let report = mesh_model::check_model(&mut model, opts)?;
        Ok((ModelEntry { model, layer, report: Some(report), notes: Vec::new() }, Vec::new()))
    }
}

/// A triangle-soup format read into groups (STL, OBJ) and built into surfaces by
/// [`mesh_model::build`]: unit, weld, split and repair all apply.
pub struct TriangleFile {
    name: &'static str,
    extensions: &'static [&'static str],
    read: fn(&Path) -> std::result::Result<mesh_model::RawMesh, InputError>,
    default_split: Split,
}

/// STL, ASCII or binary: one surface per file unless split.
pub static STL: TriangleFile =
    TriangleFile { name: "STL", extensions: &["stl"], read: stl_scene::read, default_split: Split::File };

/// Wavefront OBJ: one surface per group or object unless split.
pub static OBJ: TriangleFile =
    TriangleFile { name: "OBJ", extensions: &["obj"], read: obj_scene::read, default_split: Split::Group };

impl Reader for TriangleFile {
    fn name(&self) -> &'static str {
        self.name
    }
    fn extensions(&self) -> &'static [&'static str] {
        self.extensions
    }
    fn takes_mesh_options(&self) -> bool {
        true
    }
    fn takes_unit_and_split(&self) -> bool {
        true
    }
    fn model(
        &self,
        path: &Path,
        opts: &MeshOptions,
        layer: Layer,
        _: &LoadOptions,
    ) -> Result<(ModelEntry, Vec<String>)> {
        let c = mesh_model::build(path, (self.read)(path)?, opts, self.default_split)?;
        Ok((ModelEntry { model: c.model, layer, report: Some(c.report), notes: c.notes }, Vec::new()))
    }
}

/// View3D 3.x input files: surfaces, obstructions and the run's controls.
pub struct Vs3;

impl Reader for Vs3 {
    fn name(&self) -> &'static str {
        "View3D file"
    }
    fn extensions(&self) -> &'static [&'static str] {
        &["vs3"]
    }
    fn scene(&self, path: &Path, _: &LoadOptions) -> Result<Scene> {
        // encl = 1: a closed enclosure whose rows View3D normalises (closure here);
        // otherwise open to a black environment at 0 K, which takes what leaves the scene.
        let v = vs3::load(path)?;
        let c = v.controls;
        let entry = ModelEntry {
            model: v.model,
            layer: Layer::new("the View3D file", path, None),
            report: None,
            notes: Vec::new(),
        };
        let ambient = (!c.enclosure).then_some(0.0);
        let mut scene =
            assemble::assemble(path, v.title, ambient, &Layer::default(), Vec::new(), vec![entry])?;
        scene.warnings.extend(v.warnings);
        if c.emittances {
            scene.warnings.push(format!(
                "{}: emit = 1 asks View3D for script-F exchange factors; lambert writes view factors \
                 here, and `solve` with {} writes RADK_ij = A_i ε_i B_ij = A_i 𝓕_ij",
                path.display(),
                crate::error::opt("conductances")
            ));
        }
        scene.run_defaults = RunDefaults { tolerance: c.eps, closure: c.enclosure };
        Ok(scene)
    }
    fn model(
        &self,
        path: &Path,
        _: &MeshOptions,
        layer: Layer,
        _: &LoadOptions,
    ) -> Result<(ModelEntry, Vec<String>)> {
        let v = vs3::load(path)?;
        let mut warnings = v.warnings;
        if v.controls != vs3::Controls::default() {
            warnings.push(format!(
                "{}: the View3D control values (encl, emit, eps) of a [[model]] are ignored: the scene file \
                 decides [ambient], and {} and {} set the run",
                path.display(),
                crate::error::opt("tolerance"),
                crate::error::opt("enforce")
            ));
        }
        Ok((ModelEntry { model: v.model, layer, report: None, notes: Vec::new() }, warnings))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Extensions are found case-insensitively, each by one model reader.
    #[test]
    fn every_extension_has_one_reader() {
        for r in MODELS {
            for e in r.extensions() {
                let hits = MODELS.iter().filter(|q| q.extensions().contains(e)).count();
                assert_eq!(hits, 1, "{e}");
                let upper = format!("part.{}", e.to_uppercase());
                assert_eq!(find(&MODELS, Path::new(&upper)).map(|q| q.name()), Some(r.name()));
            }
        }
        assert!(find(&MODELS, Path::new("part.ply")).is_none());
        assert!(find(&MODELS, Path::new("part.toml")).is_none());
        assert!(find(&MODELS, Path::new("part")).is_none());
        assert_eq!(expected(&MODELS, |_| true), "a .gltf, .glb, .stl, .obj or .vs3 file");
        assert_eq!(expected(&MODELS, |r| r.takes_mesh_options()), "a .gltf, .glb, .stl or .obj file");
    }
}
