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
//!   of the positions, or a non-finite or out-of-range position is an error.
//! - Node `extras` may set `emissivity`, `temperature`, `heat_flux` and `role`; other extras keys
//!   belong to other tools and are ignored.
use super::props::{Layer, Role};
use super::validate;
use crate::error::InputError;
use crate::geometry::{DVec3, Polygon};
use glam::{DMat4, DQuat};
use gltf::mesh::Mode;
use std::path::{Path, PathBuf};

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
pub fn load_model(path: &Path) -> Result<Model, InputError> {
    let bytes =
        std::fs::read(path).map_err(|e| InputError::file(path, format!("cannot read the glTF file: {e}")))?;
    // The glTF reader is not hardened against every malformed file; a panic inside it must
    // still end as an input error.
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| parse(path, bytes))).unwrap_or_else(|_| {
        Err(InputError::file(path, "malformed glTF: the glTF reader failed on this file"))
    })
}

fn parse(path: &Path, bytes: Vec<u8>) -> Result<Model, InputError> {
    let bad = |what: String| InputError::file(path, what);
    check_glb_header(&bytes).map_err(&bad)?;
    let gltf = gltf::Gltf::from_slice(&bytes).map_err(|e| bad(format!("malformed glTF: {e}")))?;
    let base = path.parent().unwrap_or(Path::new("."));
    let buffers = gltf::import_buffers(&gltf.document, Some(base), gltf.blob.clone())
        .map_err(|e| bad(format!("cannot load the glTF buffers: {e}")))?;
    let doc = &gltf.document;
    let scene = doc
        .default_scene()
        .or_else(|| doc.scenes().next())
        .ok_or_else(|| bad("the glTF file has no scene".into()))?;

    // Depth-first, pre-order, children in file order; explicit stack (deep hierarchies).
    let mut visited = vec![false; doc.nodes().count()];
    let mut stack: Vec<(gltf::Node, DMat4)> = scene.nodes().map(|n| (n, DMat4::IDENTITY)).collect();
    stack.reverse();
    let mut mesh_nodes = Vec::new();
    while let Some((node, parent)) = stack.pop() {
        if std::mem::replace(&mut visited[node.index()], true) {
            return Err(bad(format!(
                "node {} is reached twice (a cycle or a shared child); glTF nodes must form trees",
                node.index()
            )));
        }
        let world = parent * local_matrix(&node).map_err(|p| bad(format!("node {}: {p}", node.index())))?;
        if node.mesh().is_some() {
            mesh_nodes.push((node.clone(), world));
        }
        let children: Vec<_> = node.children().collect();
        stack.extend(children.into_iter().rev().map(|c| (c, world)));
    }

    let mut uses = vec![0usize; doc.meshes().count()];
    for (n, _) in &mesh_nodes {
        uses[n.mesh().map_or(0, |m| m.index())] += 1;
    }
    let mut surfaces: Vec<MeshSurface> = Vec::with_capacity(mesh_nodes.len());
    for (node, world) in &mesh_nodes {
        let Some(mesh) = node.mesh() else { continue };
        let name = surface_name(node, &mesh, uses[mesh.index()]);
        if let Some(other) = surfaces.iter().find(|s| s.name == name) {
            return Err(InputError::surface(
                path,
                &name,
                format!("two glTF nodes give the surface name '{}'; names must be unique", other.name),
            ));
        }
        let at = |p: String| InputError::surface(path, &name, p);
        let (triangles, dropped) = mesh_triangles(&mesh, world, &buffers).map_err(at)?;
        if triangles.is_empty() {
            return Err(at(format!(
                "the mesh has no usable triangles ({dropped} degenerate triangle(s) dropped); a surface needs area"
            )));
        }
        let extras = extras_layer(node, path).map_err(|p| at(format!("node extras: {p}")))?;
        surfaces.push(MeshSurface { name, triangles, dropped, extras });
    }
    let extra_files = external_buffers(doc, base);
    Ok(Model { file: path.to_path_buf(), surfaces, extra_files })
}

/// The files behind the external buffer URIs (relative and `file:` URIs, as the glTF reader
/// resolves them; `data:` URIs are inside the file).
fn external_buffers(doc: &gltf::Document, base: &Path) -> Vec<PathBuf> {
    doc.buffers()
        .filter_map(|b| match b.source() {
            gltf::buffer::Source::Uri(uri) if !uri.starts_with("data:") => {
                let file = uri.strip_prefix("file://").or_else(|| uri.strip_prefix("file:"));
                Some(match file {
                    Some(f) => PathBuf::from(f),
                    None => base.join(percent_decode(uri)),
                })
            }
            _ => None,
        })
        .collect()
}

/// `%XX` escapes of a relative URI decoded (invalid escapes kept as written).
fn percent_decode(uri: &str) -> String {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut k = 0;
    while k < b.len() {
        let hex = b.get(k + 1..k + 3).and_then(|h| std::str::from_utf8(h).ok());
        match (b[k], hex.and_then(|h| u8::from_str_radix(h, 16).ok())) {
            (b'%', Some(v)) => {
                out.push(v);
                k += 3;
            }
            (c, _) => {
                out.push(c);
                k += 1;
            }
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Refuses GLB headers the glTF reader would mis-handle (length below the header size).
fn check_glb_header(bytes: &[u8]) -> Result<(), String> {
    if !bytes.starts_with(b"glTF") {
        return Ok(());
    }
    if bytes.len() < 20 {
        return Err("malformed GLB: the file is shorter than its header".into());
    }
    let word = |k: usize| u32::from_le_bytes([bytes[k], bytes[k + 1], bytes[k + 2], bytes[k + 3]]) as usize;
    if word(4) != 2 {
        return Err(format!("unsupported GLB version {}; lambert reads glTF 2.0", word(4)));
    }
    if word(8) < 20 || word(8) > bytes.len() {
        return Err(format!(
            "malformed GLB: header length {} but the file has {} bytes",
            word(8),
            bytes.len()
        ));
    }
    Ok(())
}

/// The node's local matrix in f64.
fn local_matrix(node: &gltf::Node) -> Result<DMat4, String> {
    let m = match node.transform() {
        gltf::scene::Transform::Matrix { matrix } => {
            DMat4::from_cols_array_2d(&matrix.map(|c| c.map(f64::from)))
        }
        gltf::scene::Transform::Decomposed { translation, rotation, scale } => {
            let q = DQuat::from_array(rotation.map(f64::from));
            if !(q.length() > 0.0) {
                return Err("the rotation quaternion is zero or not finite".into());
            }
            DMat4::from_scale_rotation_translation(
                DVec3::from_array(scale.map(f64::from)),
                q.normalize(),
                DVec3::from_array(translation.map(f64::from)),
            )
        }
    };
    if m.is_finite() {
        Ok(m)
    } else {
        Err("the transform has NaN or infinite entries".into())
    }
}

fn surface_name(node: &gltf::Node, mesh: &gltf::Mesh, mesh_uses: usize) -> String {
    let named = |s: Option<&str>| s.filter(|s| !s.is_empty()).map(str::to_string);
    named(node.name())
        .or_else(|| {
            named(mesh.name()).map(|m| if mesh_uses == 1 { m } else { format!("{m}_node{}", node.index()) })
        })
        .unwrap_or_else(|| format!("node{}", node.index()))
}

/// World-space triangles of every primitive, and the number of degenerate ones dropped.
fn mesh_triangles(
    mesh: &gltf::Mesh,
    world: &DMat4,
    buffers: &[gltf::buffer::Data],
) -> Result<(Vec<Polygon>, usize), String> {
    let mirrored = world.determinant() < 0.0;
    let (mut out, mut dropped) = (Vec::new(), 0);
    for (k, prim) in mesh.primitives().enumerate() {
        let mode = prim.mode();
        if !matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
            return Err(format!("primitive {k} draws {mode:?}; only triangle primitives can be surfaces"));
        }
        let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
        let positions: Vec<DVec3> = reader
            .read_positions()
            .ok_or_else(|| format!("primitive {k} has no readable POSITION attribute"))?
            .map(|p| world.transform_point3(DVec3::from_array(p.map(f64::from))))
            .collect();
        for (i, p) in positions.iter().enumerate() {
            validate::vector(p.to_array(), "a vertex position")
                .map_err(|e| format!("primitive {k}, vertex {i}: {e}"))?;
        }
        let indices: Vec<u32> = match reader.read_indices() {
            Some(ix) => ix.into_u32().collect(),
            None => (0..positions.len() as u32).collect(),
        };
        if let Some(bad) = indices.iter().find(|&&i| i as usize >= positions.len()) {
            return Err(format!("primitive {k}: index {bad} is past the {} vertices", positions.len()));
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
fn triangle_indices(mode: Mode, ix: &[u32]) -> Vec<[u32; 3]> {
    match mode {
        Mode::TriangleStrip => (0..ix.len().saturating_sub(2))
            .map(|i| if i % 2 == 0 { [ix[i], ix[i + 1], ix[i + 2]] } else { [ix[i + 1], ix[i], ix[i + 2]] })
            .collect(),
        Mode::TriangleFan => (1..ix.len().saturating_sub(1)).map(|i| [ix[i], ix[i + 1], ix[0]]).collect(),
        _ => ix.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
    }
}

/// The node's `extras` as a property layer.
fn extras_layer(node: &gltf::Node, path: &Path) -> Result<Layer, String> {
    let mut layer = Layer::new("the node's extras", path, None);
    let Some(raw) = node.extras() else { return Ok(layer) };
    let value: serde_json::Value =
        serde_json::from_str(raw.get()).map_err(|e| format!("not valid JSON: {e}"))?;
    let Some(map) = value.as_object() else { return Ok(layer) };
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
