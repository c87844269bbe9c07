//! Wavefront OBJ files as triangle groups, read with `tobj` (f64 positions).
//!
//! - Each `o` (object) or `g` (group) line starts a group named by it; faces before the
//!   first one form an unnamed group; a name that comes back continues its group. An object
//!   with groups inside gives one group per `g` (the innermost name wins).
//! - Faces with more than three corners are triangulated: planar simple polygons by ear
//!   clipping (convex ones as fans), others (non-planar or self-crossing) as fans from the
//!   first corner, counted in a note. Faces with fewer than three corners are skipped and
//!   counted.
//! - Materials, texture coordinates and normals are not used (the front is the side from which
//!   a face's corners run counter-clockwise).
//! - Errors name the file and, for bad numbers and face indices, the line.
use super::mesh_model::{Group, RawMesh};
use crate::error::InputError;
use crate::geometry::{DVec3, Polygon};
use std::path::Path;

/// tobj's name for faces before any `o` or `g` line.
const TOBJ_UNNAMED: &str = "unnamed_object";

/// Reads an OBJ file.
pub fn read(path: &Path) -> Result<RawMesh, InputError> {
    let text = super::text::read_text(path)?;
    let options = tobj::LoadOptions {
        single_index: false,
        triangulate: false,
        ignore_points: false,
        ignore_lines: false,
    };
    // tobj indexes with unchecked arithmetic on absurd indices; a panic there is an input error.
    let loaded = std::panic::catch_unwind(|| {
        tobj::load_obj_buf(&mut text.as_bytes(), &options, |_| Err(tobj::LoadError::OpenFileFailed))
    })
    .unwrap_or(Err(tobj::LoadError::GenericFailure));
    let (models, _materials) = loaded.map_err(|e| {
        let err = InputError::file(path, format!("malformed OBJ: {e}"));
        match locate(&text, &e) {
            Some((line, why)) => InputError { problem: format!("malformed OBJ: {why}"), ..err }.at_line(line),
            None => err,
        }
    })?;
    let mut raw = RawMesh::default();
    let (mut short, mut fans) = (0, 0);
    for m in models {
        let name = if m.name == TOBJ_UNNAMED { String::new() } else { m.name.clone() };
        let mesh = &m.mesh;
        let pos = |i: u32| {
            let k = 3 * i as usize;
            DVec3::new(mesh.positions[k], mesh.positions[k + 1], mesh.positions[k + 2])
        };
        let arities: Vec<u32> = if mesh.face_arities.is_empty() {
            vec![3; mesh.indices.len() / 3]
        } else {
            mesh.face_arities.clone()
        };
        let mut group = Group { name, triangles: Vec::new() };
        let mut at = 0usize;
        for n in arities {
            let corners: Vec<DVec3> = mesh.indices[at..at + n as usize].iter().map(|&i| pos(i)).collect();
            at += n as usize;
            match corners.len() {
                0..=2 => short += 1,
                3 => group.triangles.push([corners[0], corners[1], corners[2]]),
                _ => {
                    let tris = match Polygon::new(corners.clone()) {
                        Ok(p) => p.triangulate(),
                        Err(_) => {
                            fans += 1;
                            (1..corners.len() - 1).map(|k| [corners[0], corners[k], corners[k + 1]]).collect()
                        }
                    };
                    group.triangles.extend(tris);
                }
            }
        }
        raw.groups.push(group);
    }
    if short > 0 {
        raw.notes.push(format!("{}: skipped {short} faces with fewer than 3 corners", path.display()));
    }
    if fans > 0 {
        raw.notes.push(format!(
            "{}: {fans} faces are not planar simple polygons; each was split as a fan from its first corner",
            path.display()
        ));
    }
    Ok(raw)
}

/// The line of the first `v` with a bad coordinate or `f` with a bad or out-of-range index,
/// for the errors tobj reports without one.
fn locate(text: &str, e: &tobj::LoadError) -> Option<(usize, String)> {
    use tobj::LoadError as L;
    let total = text.lines().filter(|l| l.split_whitespace().next() == Some("v")).count() as i64;
    let mut seen = 0i64;
    for (k, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                seen += 1;
                let ok = words.clone().take(3).filter(|w| w.parse::<f64>().is_ok()).count() == 3;
                if matches!(e, L::PositionParseError) && !ok {
                    return Some((k + 1, format!("vertex {seen} needs three numbers: '{}'", line.trim())));
                }
            }
            Some("f") => {
                for w in words {
                    let Ok(i) = w.split('/').next().unwrap_or("").parse::<i64>() else {
                        if matches!(e, L::FaceParseError) {
                            return Some((k + 1, format!("face corner '{w}' is not a vertex index")));
                        }
                        continue;
                    };
                    let resolved = if i < 0 { seen + i + 1 } else { i };
                    if matches!(e, L::FaceVertexOutOfBounds) && !(1..=total).contains(&resolved) {
                        return Some((
                            k + 1,
                            format!("face index {i} is out of range: the file has {total} vertices (1 to {total})"),
                        ));
                    }
                }
            }
            _ => {}
        }
    }
    None
}
