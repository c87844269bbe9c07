//! STL files (binary and ASCII) as triangle groups, read with `stl_io`.
//!
//! - Binary when the size is exactly 84 + 50·n bytes for the n triangles its header announces
//!   (whatever the first bytes say: many exporters start binary headers with "solid");
//!   otherwise ASCII when the text starts with `solid`; otherwise an error that gives both
//!   readings.
//! - ASCII files may hold several `solid … endsolid` blocks: each is a group named after its
//!   solid (`split = "group"` makes one surface of each). Text after the last `endsolid` is
//!   an error, never ignored.
//! - The front of a facet is the side from which its vertices run counter-clockwise. Stored
//!   facet normals are not used; facets whose non-zero stored normal points against their
//!   vertex order are counted in a note.
//! - Coordinates are f32 in the file and f64 from here on.
use super::mesh_model::{Group, RawMesh};
use crate::error::InputError;
use crate::geometry::DVec3;
use std::io::Cursor;
use std::path::Path;

/// Bytes of the binary header and triangle count, and of one binary triangle record.
const BINARY_HEADER: usize = 84;
const BINARY_RECORD: usize = 50;

/// Reads an STL file.
pub fn read(path: &Path) -> Result<RawMesh, InputError> {
    let bytes =
        std::fs::read(path).map_err(|e| InputError::file(path, format!("cannot read the STL file: {e}")))?;
    if bytes.is_empty() {
        return Err(InputError::file(path, "the STL file is empty"));
    }
    let announced = (bytes.len() >= BINARY_HEADER)
        .then(|| u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize);
    if announced.is_some_and(|n| {
        n.checked_mul(BINARY_RECORD).and_then(|b| b.checked_add(BINARY_HEADER)) == Some(bytes.len())
    }) {
        return binary(path, bytes);
    }
    let text_start = bytes.iter().position(|b| !b.is_ascii_whitespace()).unwrap_or(0);
    if bytes[text_start..].starts_with(b"solid") {
        let text = String::from_utf8(bytes).map_err(|e| {
            InputError::file(
                path,
                format!("an ASCII STL must be text; invalid byte at offset {}", e.utf8_error().valid_up_to()),
            )
        })?;
        return ascii(path, &text);
    }
    Err(InputError::file(
        path,
        match announced {
            Some(n) => format!(
                "not an STL file: it does not start with 'solid' (ASCII), and as binary STL its header announces \
                 {n} triangles ({} bytes) but the file has {} bytes",
                BINARY_HEADER as u128 + BINARY_RECORD as u128 * n as u128,
                bytes.len()
            ),
            None => format!("not an STL file: {} bytes, no 'solid' header and too short for binary STL", bytes.len()),
        },
    ))
}

fn binary(path: &Path, mut bytes: Vec<u8>) -> Result<RawMesh, InputError> {
    // stl_io takes a header starting "solid " for ASCII; the size already says binary.
    bytes[..5].copy_from_slice(b"     ");
    let mut cursor = Cursor::new(bytes);
    let reader = stl_io::create_stl_reader(&mut cursor)
        .map_err(|e| InputError::file(path, format!("malformed binary STL: {e}")))?;
    let mut group = Group::default();
    let mut against = 0;
    for (k, t) in reader.enumerate() {
        let t =
            t.map_err(|e| InputError::file(path, format!("malformed binary STL at triangle {k}: {e}")))?;
        against += usize::from(push(&mut group, &t));
    }
    let mut raw = RawMesh { groups: vec![group], notes: Vec::new() };
    note_normals(path, &mut raw, against);
    Ok(raw)
}

fn ascii(path: &Path, text: &str) -> Result<RawMesh, InputError> {
    let lines: Vec<&str> = text.lines().collect();
    let starts: Vec<usize> =
        (0..lines.len()).filter(|&i| lines[i].split_whitespace().next() == Some("solid")).collect();
    let mut raw = RawMesh::default();
    let mut against = 0;
    for (b, &start) in starts.iter().enumerate() {
        let end = starts.get(b + 1).copied().unwrap_or(lines.len());
        let name = lines[start].trim_start().trim_start_matches("solid").trim().to_string();
        let at = |what: String| InputError::file(path, what).at_line(start + 1);
        let label = if name.is_empty() { format!("solid {b}") } else { format!("solid '{name}'") };
        // The closing `endsolid`, and nothing but blank lines after it.
        let close = (start + 1..end)
            .find(|&i| lines[i].split_whitespace().next() == Some("endsolid"))
            .ok_or_else(|| at(format!("malformed ASCII STL: {label} has no endsolid")))?;
        if let Some(i) = (close + 1..end).find(|&i| !lines[i].trim().is_empty()) {
            return Err(InputError::file(
                path,
                format!(
                    "malformed ASCII STL: unexpected text after the endsolid of {label}: '{}'",
                    lines[i].trim()
                ),
            )
            .at_line(i + 1));
        }
        // stl_io wants "solid <name>" on the first line.
        let mut chunk = String::from("solid x\n");
        for l in &lines[start + 1..=close] {
            chunk.push_str(l);
            chunk.push('\n');
        }
        let mut cursor = Cursor::new(chunk.into_bytes());
        let reader = stl_io::create_stl_reader(&mut cursor)
            .map_err(|e| at(format!("malformed ASCII STL in {label}: {e}")))?;
        let mut group = Group { name, triangles: Vec::new() };
        for (k, t) in reader.enumerate() {
            let t = t.map_err(|e| at(format!("malformed ASCII STL in {label} at facet {k}: {e}")))?;
            against += usize::from(push(&mut group, &t));
        }
        raw.groups.push(group);
    }
    note_normals(path, &mut raw, against);
    Ok(raw)
}

/// Adds a facet; true when its non-zero stored normal points against its vertex order.
fn push(group: &mut Group, t: &stl_io::Triangle) -> bool {
    let v = t.vertices.map(|p| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64));
    group.triangles.push(v);
    let n = DVec3::new(t.normal[0] as f64, t.normal[1] as f64, t.normal[2] as f64);
    n.dot((v[1] - v[0]).cross(v[2] - v[0])) < 0.0
}

fn note_normals(path: &Path, raw: &mut RawMesh, against: usize) {
    if against > 0 {
        raw.notes.push(format!(
            "{}: {against} facets store a normal that points against their vertex order; lambert follows the \
             vertex order (counter-clockwise seen from the front)",
            path.display()
        ));
    }
}
