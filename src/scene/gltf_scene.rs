//! glTF 2.0 models (.gltf with embedded or external buffers, .glb) as triangle-mesh surfaces.
//!
//! - The default scene is used, else the first; a file without scenes is an error.
//! - Nodes are walked depth-first in file order; world matrices are composed in f64 (TRS
//!   quaternions renormalised in f64). A node that is reached twice (a cycle or a shared child)
//!   is an error.
//! - Each node with a mesh is one surface; all its triangle primitives (TRIANGLES, STRIP, FAN)
//!   are merged. Points and lines are an error. When the world matrix mirrors (negative
//!   determinant) the winding is reversed, as glTF prescribes, so front faces stay front faces.
//! - Names: the node's name; else the mesh's name when no other node uses that mesh; else
//!   `<mesh>_node<i>`; else `node<i>` (i = the node's index in the file, so names are stable).
//!   Two surfaces with one name are an error.
//! - Degenerate triangles (zero area in f64 after the transform) are dropped and counted; a
//!   surface with none left is an error. A missing POSITION accessor, an index past the end
//!   of the positions, TRIANGLES indices not in threes, or a non-finite or out-of-range
//!   position is an error.
//! - Node `extras` may set `emissivity`, `temperature`, `heat_flux` and `role`; other extras keys
//!   belong to other tools and are ignored.
//! - The reader is strict (glTF 2.0): every accessor, buffer view and buffer a surface uses is
//!   checked before a byte is read (`accessor`), buffers are loaded under the rules of
//!   `buffers` (files under the glTF file's folder, read up to `byteLength`), a GLB file is split
//!   by `container`, and JSON fields are read with type and index checks by `json`. Each
//!   violation names the node, the mesh, the primitive, the accessor and the rule. A node with
//!   both `matrix` and TRS, and any required extension, are errors. The `gltf` crate's own
//!   validation then runs on the whole document, so malformed parts lambert does not read are
//!   refused as before.
use super::props::{Layer, Role};
use super::{validate, LoadOptions};
use crate::error::InputError;
use crate::geometry::{DVec3, Polygon};
use glam::{DMat4, DQuat};
use serde_json::Value;
use std::path::{Path, PathBuf};

mod accessor;
mod buffers;
mod container;
mod json;

/// One mesh node of a model.
#[derive(Debug, Clone)]
pub struct MeshSurface {
    /// Surface name (see the module docs).
    pub name: String,
    /// Its world-space polygons, front faces counter-clockwise: triangles (glTF), or one
    /// polygon per View3D record.
    pub triangles: Vec<Polygon>,
    /// Degenerate triangles dropped.
    pub dropped: usize,
    /// Properties from the node's `extras`.
    pub extras: Layer,
}

/// A loaded glTF file.
#[derive(Debug, Clone)]
pub struct Model {
    /// The file.
    pub file: PathBuf,
    /// Its mesh nodes in traversal order.
    pub surfaces: Vec<MeshSurface>,
    /// Other files read for it (glTF external buffers); [`Scene::inputs`](super::Scene::inputs)
    /// collects them with `file`.
    pub extra_files: Vec<PathBuf>,
}

/// Loads the mesh surfaces of a .gltf or .glb file.
pub fn load_model_with(path: &Path, options: &LoadOptions) -> Result<Model, InputError> {
    let meta = std::fs::metadata(path)
        .map_err(|e| InputError::file(path, format!("cannot read the glTF file: {e}")))?;
    if !meta.is_file() {
        return Err(InputError::file(path, "the glTF file is not a regular file (a folder, device or FIFO)"));
    }
    let bytes =
        std::fs::read(path).map_err(|e| InputError::file(path, format!("cannot read the glTF file: {e}")))?;
    parse(path, &bytes, options)
}

/// glTF primitive modes by number (glTF 2.0 mesh.primitive.mode).
const MODES: [&str; 7] =
    ["Points", "Lines", "LineLoop", "LineStrip", "Triangles", "TriangleStrip", "TriangleFan"];
/// The modes that make triangles: TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN.
const TRIANGLES: u64 = 4;
const STRIP: u64 = 5;
const FAN: u64 = 6;

/// The top-level arrays of a glTF document.
struct Doc<'a> {
    nodes: &'a [Value],
    meshes: &'a [Value],
    arrays: accessor::Arrays<'a>,
}

fn parse(path: &Path, bytes: &[u8], options: &LoadOptions) -> Result<Model, InputError> {
    let bad = |what: String| InputError::file(path, what);
    let c = container::split(bytes).map_err(&bad)?;
    let root_value: Value = serde_json::from_slice(c.json)
        .map_err(|e| bad(format!("malformed glTF: the JSON is not valid: {e}")))?;
    let root = json::object(&root_value, "malformed glTF: the document").map_err(&bad)?;
    check_asset(root).map_err(&bad)?;
    let arr = |key: &str| json::array(root, key, "malformed glTF").map_err(&bad);
    let doc = Doc {
        nodes: arr("nodes")?,
        meshes: arr("meshes")?,
        arrays: accessor::Arrays { accessors: arr("accessors")?, views: arr("bufferViews")? },
    };
    let scenes = arr("scenes")?;
    let buffer_list = arr("buffers")?;

    let scene =
        match json::opt_index(root, "scene", scenes.len(), "scenes", "malformed glTF").map_err(&bad)? {
            Some(s) => s,
            None if scenes.is_empty() => return Err(bad("the glTF file has no scene".into())),
            None => 0,
        };
    let scene_what = format!("malformed glTF: scene {scene}");
    let scene_obj = json::object(&scenes[scene], &scene_what).map_err(&bad)?;
    let roots = json::array(scene_obj, "nodes", &scene_what).map_err(&bad)?;

    // Depth-first, pre-order, children in file order; explicit stack (deep hierarchies).
    let mut visited = vec![false; doc.nodes.len()];
    let mut stack: Vec<(usize, DMat4)> = Vec::with_capacity(roots.len());
    for (k, r) in roots.iter().enumerate().rev() {
        let what = format!("malformed glTF: scene {scene}: `nodes[{k}]`");
        stack.push((json::index_value(r, doc.nodes.len(), "nodes", &what).map_err(&bad)?, DMat4::IDENTITY));
    }
    let mut mesh_nodes: Vec<(usize, usize, DMat4)> = Vec::new();
    while let Some((n, parent)) = stack.pop() {
        if std::mem::replace(&mut visited[n], true) {
            return Err(bad(format!(
                "node {n} is reached twice (a cycle or a shared child); glTF nodes must form trees"
            )));
        }
        let at = |p: String| bad(format!("node {n}: {p}"));
        let node = json::object(&doc.nodes[n], "the node").map_err(at)?;
        let world = parent * local_matrix(node).map_err(at)?;
        if let Some(m) = json::opt_index(node, "mesh", doc.meshes.len(), "meshes", "the node").map_err(at)? {
            mesh_nodes.push((n, m, world));
        }
        let children = json::array(node, "children", "the node").map_err(at)?;
        for (k, ch) in children.iter().enumerate().rev() {
            let what = format!("`children[{k}]`");
            stack.push((json::index_value(ch, doc.nodes.len(), "nodes", &what).map_err(at)?, world));
        }
    }

    let mut uses = vec![0usize; doc.meshes.len()];
    for &(_, m, _) in &mesh_nodes {
        uses[m] += 1;
    }
    let folder = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let mut buffers = buffers::Buffers::new(buffer_list, c.bin, c.glb, folder, options.allow_outside_paths);
    let mut surfaces: Vec<MeshSurface> = Vec::with_capacity(mesh_nodes.len());
    for (n, m, world) in &mesh_nodes {
        let (n, m) = (*n, *m);
        let node = json::object(&doc.nodes[n], "the node").map_err(&bad)?;
        let mesh =
            json::object(&doc.meshes[m], &format!("mesh {m}")).map_err(|p| bad(format!("node {n}: {p}")))?;
        let name =
            surface_name(node, mesh, n, uses[m]).map_err(|p| bad(format!("node {n}, mesh {m}: {p}")))?;
        if let Some(other) = surfaces.iter().find(|s| s.name == name) {
            return Err(InputError::surface(
                path,
                &name,
                format!("two glTF nodes give the surface name '{}'; names must be unique", other.name),
            ));
        }
        let at = |p: String| InputError::surface(path, &name, p);
        let (triangles, dropped) = mesh_triangles(&doc, mesh, world, &mut buffers)
            .map_err(|p| at(format!("{p} (mesh {m}, node {n})")))?;
        if triangles.is_empty() {
            return Err(at(format!(
                "the mesh has no usable triangles ({dropped} degenerate triangle(s) dropped); a surface needs area"
            )));
        }
        let extras = extras_layer(node, path).map_err(|p| at(format!("node extras: {p}")))?;
        surfaces.push(MeshSurface { name, triangles, dropped, extras });
    }
    crate_validation(&doc, c.json).map_err(bad)?;
    let extra_files = buffers.external_files();
    Ok(Model { file: path.to_path_buf(), surfaces, extra_files })
}

/// `asset.version` must be 2.x, and no extension lambert does not read may be required.
fn check_asset(root: &json::Obj) -> Result<(), String> {
    let asset = json::object(root.get("asset").unwrap_or(&Value::Null), "malformed glTF: `asset`")?;
    let version = json::opt_str(asset, "version", "malformed glTF: `asset`")?
        .ok_or("malformed glTF: `asset` has no `version`, which glTF requires")?;
    if !version.starts_with("2.") {
        return Err(format!("unsupported glTF version \"{version}\"; lambert reads glTF 2.0"));
    }
    if let Some(ext) = json::array(root, "extensionsRequired", "malformed glTF")?.first() {
        return Err(format!(
            "the file requires the glTF extension {}, which lambert does not read (the geometry \
             could not be read correctly without it)",
            json::short(ext)
        ));
    }
    Ok(())
}

/// The `gltf` crate's validation of the whole document (materials, textures, animations, …),
/// after lambert's own checks of what it reads. Its POSITION check indexes the accessors
/// without a bounds check, so every mesh's POSITION index is checked first.
fn crate_validation(doc: &Doc, text: &[u8]) -> Result<(), String> {
    use gltf::json::validation::Validate;
    let n = doc.arrays.accessors.len() as u64;
    for (m, mesh) in doc.meshes.iter().enumerate() {
        let prims = mesh.get("primitives").and_then(Value::as_array).map_or(&[][..], |a| a);
        for (k, p) in prims.iter().enumerate() {
            if let Some(i) = p.get("attributes").and_then(|a| a.get("POSITION")).and_then(Value::as_u64) {
                if i >= n {
                    return Err(format!(
                        "malformed glTF: mesh {m}, primitive {k}: POSITION accessor {i} is past the {n} accessors"
                    ));
                }
            }
        }
    }
    let parsed: gltf::json::Root =
        gltf::json::deserialize::from_slice(text).map_err(|e| format!("malformed glTF: {e}"))?;
    let mut errors = Vec::new();
    parsed.validate(&parsed, gltf::json::Path::new, &mut |path: &dyn Fn() -> gltf::json::Path, e| {
        errors.push(format!("{}: {e}", path()))
    });
    match errors.first() {
        None => Ok(()),
        Some(first) => Err(format!("malformed glTF: {first}")),
    }
}

/// The node's local matrix in f64 (`matrix`, or translation · rotation · scale).
fn local_matrix(node: &json::Obj) -> Result<DMat4, String> {
    let what = "the node";
    let matrix = json::opt_floats::<16>(node, "matrix", what)?;
    let t = json::opt_floats::<3>(node, "translation", what)?;
    let r = json::opt_floats::<4>(node, "rotation", what)?;
    let s = json::opt_floats::<3>(node, "scale", what)?;
    let m = match matrix {
        Some(_) if t.is_some() || r.is_some() || s.is_some() => {
            return Err(
                "it has both `matrix` and translation/rotation/scale; glTF allows one or the other".into()
            )
        }
        Some(m) => DMat4::from_cols_array(&m),
        None => {
            let q = DQuat::from_array(r.unwrap_or([0.0, 0.0, 0.0, 1.0]));
            if !(q.length() > 0.0) {
                return Err("the rotation quaternion is zero or not finite".into());
            }
            DMat4::from_scale_rotation_translation(
                DVec3::from_array(s.unwrap_or([1.0; 3])),
                q.normalize(),
                DVec3::from_array(t.unwrap_or([0.0; 3])),
            )
        }
    };
    if m.is_finite() {
        Ok(m)
    } else {
        Err("the transform has NaN or infinite entries".into())
    }
}

fn surface_name(node: &json::Obj, mesh: &json::Obj, n: usize, mesh_uses: usize) -> Result<String, String> {
    let named = |s: Option<&str>| s.filter(|s| !s.is_empty()).map(str::to_string);
    let node_name = named(json::opt_str(node, "name", "the node")?);
    let mesh_name = named(json::opt_str(mesh, "name", "the mesh")?);
    Ok(node_name
        .or_else(|| mesh_name.map(|m| if mesh_uses == 1 { m } else { format!("{m}_node{n}") }))
        .unwrap_or_else(|| format!("node{n}")))
}

/// World-space triangles of every primitive, and the number of degenerate ones dropped.
fn mesh_triangles(
    doc: &Doc,
    mesh: &json::Obj,
    world: &DMat4,
    buffers: &mut buffers::Buffers,
) -> Result<(Vec<Polygon>, usize), String> {
    let mirrored = world.determinant() < 0.0;
    let (mut out, mut dropped) = (Vec::new(), 0);
    let prims = json::array(mesh, "primitives", "the mesh")?;
    if prims.is_empty() {
        return Err("the mesh has no primitives; glTF requires at least one".into());
    }
    let n_acc = doc.arrays.accessors.len();
    for (k, prim) in prims.iter().enumerate() {
        let what = format!("primitive {k}");
        let prim = json::object(prim, &what)?;
        let mode = json::opt_uint(prim, "mode", &what)?.unwrap_or(TRIANGLES);
        let Some(mode_name) = MODES.get(mode as usize).filter(|_| mode <= FAN) else {
            return Err(format!("{what}: `mode` {mode} is not a glTF primitive mode (0 to 6)"));
        };
        if !matches!(mode, TRIANGLES | STRIP | FAN) {
            return Err(format!("{what} draws {mode_name}; only triangle primitives can be surfaces"));
        }
        let attributes =
            json::object(prim.get("attributes").unwrap_or(&Value::Null), &format!("{what}: `attributes`"))?;
        let Some(pos) = attributes.get("POSITION") else {
            return Err(format!("{what} has no POSITION attribute"));
        };
        let pos = json::index_value(pos, n_acc, "accessors", &format!("{what}: POSITION accessor"))?;
        let what = what.as_str();
        let at = |role: String, a: usize| move |e: String| format!("{what}, {role} accessor {a}: {e}");
        let vertices = accessor::positions(&doc.arrays, buffers, pos).map_err(at("POSITION".into(), pos))?;
        // glTF: every attribute of a primitive has the same count.
        for (key, v) in attributes {
            let a = json::index_value(v, n_acc, "accessors", &format!("{what}: {key} accessor"))?;
            let count = json::object(&doc.arrays.accessors[a], "the accessor")
                .and_then(|o| json::uint(o, "count", ""))
                .map_err(at(key.clone(), a))?;
            if count != vertices.len() as u64 {
                return Err(format!(
                    "{what}, {key} accessor {a}: `count` is {count} but POSITION has {}; glTF requires \
                     one count for all attributes of a primitive",
                    vertices.len()
                ));
            }
        }
        let positions: Vec<DVec3> =
            vertices.iter().map(|p| world.transform_point3(DVec3::from_array(p.map(f64::from)))).collect();
        for (i, p) in positions.iter().enumerate() {
            validate::vector(p.to_array(), "a vertex position")
                .map_err(|e| format!("{what}, vertex {i}: {e}"))?;
        }
        let indices: Vec<u32> = match json::opt_index(prim, "indices", n_acc, "accessors", what)? {
            Some(a) => accessor::indices(&doc.arrays, buffers, a, positions.len())
                .map_err(at("indices".into(), a))?,
            None => (0..positions.len() as u32).collect(),
        };
        if mode == TRIANGLES && !indices.len().is_multiple_of(3) {
            return Err(format!(
                "{what} has {} vertex indices, not a multiple of 3 as TRIANGLES requires",
                indices.len()
            ));
        }
        for [a, b, c] in triangle_indices(mode, &indices) {
            let (a, b, c) = (positions[a as usize], positions[b as usize], positions[c as usize]);
            let tri = if mirrored { Polygon::triangle(a, c, b) } else { Polygon::triangle(a, b, c) };
            match tri {
                Some(t) => out.push(t),
                None => dropped += 1,
            }
        }
    }
    Ok((out, dropped))
}

/// Vertex index triples of a triangle primitive, counter-clockwise (glTF 2.0 §3.7.2.1).
fn triangle_indices(mode: u64, ix: &[u32]) -> Vec<[u32; 3]> {
    match mode {
        STRIP => (0..ix.len().saturating_sub(2))
            .map(|i| if i % 2 == 0 { [ix[i], ix[i + 1], ix[i + 2]] } else { [ix[i + 1], ix[i], ix[i + 2]] })
            .collect(),
        FAN => (1..ix.len().saturating_sub(1)).map(|i| [ix[i], ix[i + 1], ix[0]]).collect(),
        _ => ix.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
    }
}

/// The node's `extras` as a property layer.
fn extras_layer(node: &json::Obj, path: &Path) -> Result<Layer, String> {
    let mut layer = Layer::new("the node's extras", path, None);
    let Some(map) = node.get("extras").and_then(Value::as_object) else { return Ok(layer) };
    let number = |key: &str| -> Result<Option<f64>, String> {
        match map.get(key) {
            None | Some(serde_json::Value::Null) => Ok(None),
            Some(v) => v.as_f64().map(Some).ok_or_else(|| format!("{key} must be a number, got {v}")),
        }
    };
    layer.emissivity = number("emissivity")?.map(validate::emissivity).transpose()?;
    layer.temperature =
        number("temperature")?.map(|t| validate::temperature(t, "temperature")).transpose()?;
    layer.heat_flux = number("heat_flux")?.map(validate::heat_flux).transpose()?;
    layer.role = match map.get("role") {
        None | Some(serde_json::Value::Null) => None,
        Some(serde_json::Value::String(s)) => Some(Role::parse(s)?),
        Some(v) => return Err(format!("role must be a string, got {v}")),
    };
    layer.check_role()?;
    Ok(layer)
}
