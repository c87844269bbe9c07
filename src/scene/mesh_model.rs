//! Mesh models from triangle groups (STL solids, OBJ groups and objects) and the mesh checks of
//! every model file (glTF too): length unit, vertex welding, one surface per file, group or
//! connected component, hygiene (`super::hygiene`) and `repair`.
//!
//! Surface names: `<stem>` for one surface per file; `<stem>/<group>` per group (a file with a
//! single unnamed group gives `<stem>`); `<stem>/<k>` per connected component, k from 0 in
//! order of each component's first triangle in the file.
use super::gltf_scene::{MeshSurface, Model};
use super::hygiene::{self, MeshReport, WELD_REL};
use super::mesh::{weld, Tag, TriMesh};
use super::props::Layer;
use super::validate;
use crate::error::InputError;
use crate::geometry::{DVec3, Polygon};
use std::path::Path;

/// A length unit of model coordinates (named in [`crate::choice`]).
#[derive(Debug, Clone, Copy, PartialEq, Default, clap::ValueEnum)]
pub enum Unit {
    /// Metres (the default).
    #[default]
    M,
    /// Millimetres.
    Mm,
    /// Centimetres.
    Cm,
    /// Inches.
    In,
    /// Feet.
    Ft,
}

impl std::fmt::Display for Unit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        crate::choice::write(self, f)
    }
}

impl Unit {
    /// Parses `m`, `mm`, `cm`, `in` or `ft`.
    pub fn parse(s: &str) -> Result<Unit, String> {
        crate::choice::parse(s).ok_or_else(|| {
            let names: Vec<String> =
                crate::choice::names::<Unit>().iter().map(|n| format!("\"{n}\"")).collect();
            let (last, rest) = names.split_last().expect("units exist");
            format!("unknown unit '{s}'; expected {} or {last}", rest.join(", "))
        })
    }
    /// Metres per unit.
    pub fn metres(self) -> f64 {
        match self {
            Unit::M => 1.0,
            Unit::Mm => 1e-3,
            Unit::Cm => 1e-2,
            Unit::In => 0.0254,
            Unit::Ft => 0.3048,
        }
    }
}

/// How a mesh file becomes surfaces.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Split {
    /// One surface for the whole file.
    File,
    /// One surface per OBJ group/object or STL solid.
    Group,
    /// One surface per connected component of the welded mesh.
    Component,
}

impl Split {
    /// Parses `file`, `group` or `component`.
    pub fn parse(s: &str) -> Result<Split, String> {
        match s {
            "file" => Ok(Split::File),
            "group" => Ok(Split::Group),
            "component" => Ok(Split::Component),
            _ => Err(format!("unknown split '{s}'; expected \"file\", \"group\" or \"component\"")),
        }
    }
}

/// Options of a mesh model: `[[model]]` keys or the bare-scene flags.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MeshOptions {
    /// Unit of the file's coordinates.
    pub unit: Unit,
    /// Weld tolerance, m (`None`: `WELD_REL` × the bounding-box diagonal).
    pub weld: Option<f64>,
    /// Surfaces per file, group or component (`None`: the format's default).
    pub split: Option<Split>,
    /// Weld, orient and drop duplicates and slivers.
    pub repair: bool,
}

/// Triangles of one group as read, in file units, with what the reader dropped.
#[derive(Debug, Clone, Default)]
pub struct Group {
    /// Group name (empty: unnamed).
    pub name: String,
    /// Its triangles.
    pub triangles: Vec<[DVec3; 3]>,
}

/// A mesh file as read: its groups and the reader's notes.
#[derive(Debug, Clone, Default)]
pub struct RawMesh {
    /// Groups in file order.
    pub groups: Vec<Group>,
    /// Notes for the user (e.g. faces the reader could not use).
    pub notes: Vec<String>,
}

/// A model with its mesh report.
#[derive(Debug, Clone)]
pub struct Checked {
    /// The surfaces.
    pub model: Model,
    /// The checks' findings.
    pub report: MeshReport,
    /// Notes from reading.
    pub notes: Vec<String>,
}

/// Builds the surfaces of an STL or OBJ file (`default_split` when the options give none).
pub fn build(
    path: &Path,
    raw: RawMesh,
    opts: &MeshOptions,
    default_split: Split,
) -> Result<Checked, InputError> {
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("mesh").to_string();
    // Groups of one name are one group (an OBJ `g` line may return to an earlier group).
    let mut groups: Vec<Group> = Vec::new();
    for g in raw.groups.into_iter().filter(|g| !g.triangles.is_empty()) {
        match groups.iter_mut().find(|h| h.name == g.name) {
            Some(h) => h.triangles.extend(g.triangles),
            None => groups.push(g),
        }
    }
    if groups.is_empty() {
        return Err(InputError::file(path, "the mesh has no triangles; a surface needs area"));
    }
    let scale = opts.unit.metres();
    let mut soup = Vec::new();
    let mut tags = Vec::new();
    for (g, group) in groups.iter().enumerate() {
        for (k, t) in group.triangles.iter().enumerate() {
            let mut tri = [DVec3::ZERO; 3];
            for (c, p) in t.iter().enumerate() {
                tri[c] = validate::vector((*p * scale).to_array(), "a vertex position").map_err(|e| {
                    InputError::file(path, format!("{} triangle {k}, corner {c}: {e}", group_label(group, g)))
                })?;
            }
            soup.push(tri);
            tags.push(Tag { surface: g as u32, index: k as u32 });
        }
    }
    let tol = weld_tolerance(path, &soup, opts.weld)?;
    let (mut mesh, info) = weld(&soup, &tags, tol);
    let split = opts.split.unwrap_or(default_split);
    let names: Vec<String> = match split {
        Split::Group if groups.len() == 1 && groups[0].name.is_empty() => vec![stem.clone()],
        Split::Group => groups.iter().enumerate().map(|(g, gr)| group_name(&stem, gr, g)).collect(),
        Split::File => {
            retag(&mut mesh, |_| 0);
            vec![stem.clone()]
        }
        Split::Component => {
            let (ids, n) = mesh.components(&mesh.edges());
            retag(&mut mesh, |t| ids[t]);
            (0..n).map(|k| format!("{stem}/{k}")).collect()
        }
    };
    for n in &names {
        check_name(n).map_err(|p| InputError::surface(path, n, p))?;
    }
    let checked = finish(path, names, mesh, tol, info, opts.repair)?;
    Ok(Checked { notes: raw.notes, ..checked })
}

/// Runs the checks (and repair) on a loaded glTF model, whose geometry changes only under
/// repair.
pub fn check_model(model: &mut Model, opts: &MeshOptions) -> Result<MeshReport, InputError> {
    let mut soup = Vec::new();
    let mut tags = Vec::new();
    for (s, ms) in model.surfaces.iter().enumerate() {
        for (k, t) in ms.triangles.iter().enumerate() {
            let v = t.vertices();
            soup.push([v[0], v[1], v[2]]);
            tags.push(Tag { surface: s as u32, index: k as u32 });
        }
    }
    let tol = weld_tolerance(&model.file, &soup, opts.weld)?;
    let (mesh, info) = weld(&soup, &tags, tol);
    let names: Vec<String> = model.surfaces.iter().map(|s| s.name.clone()).collect();
    if !opts.repair {
        return Ok(hygiene::check(model.file.clone(), &names, &mesh, tol, info));
    }
    let checked = finish(&model.file, names, mesh, tol, info, true)?;
    for (old, new) in model.surfaces.iter_mut().zip(checked.model.surfaces) {
        old.triangles = new.triangles;
        old.dropped += new.dropped;
    }
    Ok(checked.report)
}

/// Checks, repairs when asked, and turns the welded mesh into surfaces.
fn finish(
    path: &Path,
    names: Vec<String>,
    mut mesh: TriMesh,
    tol: f64,
    info: super::mesh::WeldInfo,
    repair: bool,
) -> Result<Checked, InputError> {
    let log = repair.then(|| hygiene::repair::repair(&mut mesh));
    let mut report = hygiene::check(path.to_path_buf(), &names, &mesh, tol, info);
    report.repair = log;
    // Triangles per surface in the order read.
    let mut order: Vec<usize> = (0..mesh.triangles.len()).collect();
    order.sort_by_key(|&t| mesh.tags[t]);
    let mut surfaces: Vec<MeshSurface> = names
        .iter()
        .map(|n| MeshSurface {
            name: n.clone(),
            triangles: Vec::new(),
            dropped: 0,
            extras: Layer::new("the mesh file", path, None),
        })
        .collect();
    for t in order {
        let [a, b, c] = mesh.corners(t);
        let s = &mut surfaces[mesh.tags[t].surface as usize];
        match Polygon::triangle(a, b, c) {
            Some(p) => s.triangles.push(p),
            None => s.dropped += 1,
        }
    }
    if let Some(s) = surfaces.iter().find(|s| s.triangles.is_empty()) {
        return Err(InputError::surface(
            path,
            &s.name,
            "the mesh has no usable triangles left (all degenerate, welded away or dropped by repair); \
             a surface needs area",
        ));
    }
    Ok(Checked {
        model: Model { file: path.to_path_buf(), surfaces, extra_files: Vec::new() },
        report,
        notes: Vec::new(),
    })
}

/// The weld tolerance: the given one, or [`WELD_REL`] × the bounding-box diagonal.
fn weld_tolerance(path: &Path, soup: &[[DVec3; 3]], given: Option<f64>) -> Result<f64, InputError> {
    if let Some(w) = given {
        return Ok(w);
    }
    let lo = soup.iter().flatten().fold(DVec3::INFINITY, |a, &b| a.min(b));
    let hi = soup.iter().flatten().fold(DVec3::NEG_INFINITY, |a, &b| a.max(b));
    let diag = (hi - lo).length();
    if !diag.is_finite() {
        return Err(InputError::file(path, "the mesh's bounding box is not finite"));
    }
    Ok(WELD_REL * diag)
}

fn retag(mesh: &mut TriMesh, surface: impl Fn(usize) -> u32) {
    let mut next: std::collections::HashMap<u32, u32> = std::collections::HashMap::new();
    for t in 0..mesh.tags.len() {
        let s = surface(t);
        let k = next.entry(s).or_insert(0);
        mesh.tags[t] = Tag { surface: s, index: *k };
        *k += 1;
    }
}

fn group_label(g: &Group, k: usize) -> String {
    if g.name.is_empty() {
        format!("group {k}")
    } else {
        format!("group '{}'", g.name)
    }
}

fn group_name(stem: &str, g: &Group, k: usize) -> String {
    if g.name.is_empty() {
        format!("{stem}/group{k}")
    } else {
        format!("{stem}/{}", g.name)
    }
}

/// A generated surface name must be usable in every output.
fn check_name(name: &str) -> Result<(), String> {
    if name.contains('#') {
        Err(format!(
            "the name contains '#', which separates patch numbers in `{}` output; rename the group",
            crate::error::opt("patches")
        ))
    } else if name.chars().any(char::is_control) {
        Err("the name contains control characters; rename the group".into())
    } else if name == "ambient" {
        Err("'ambient' is reserved for the environment row of open scenes; rename the file".into())
    } else {
        Ok(())
    }
}
