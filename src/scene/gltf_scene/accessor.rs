//! Accessors checked against the glTF 2.0 rules before a byte is read, then read with their
//! strides: the component type and element type each use allows, byte offsets aligned to the
//! component size (and to 4 bytes for vertex attributes), strides within 4..=252, a multiple
//! of 4 and no smaller than one element, every element inside its buffer view and every buffer
//! view inside its buffer, and sparse substitutions with increasing indices below the count.
//! All offset arithmetic is checked, so no declared number can index past the data.
use super::buffers::Buffers;
use super::json::{self, Obj};
use serde_json::Value;

/// glTF component types.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Component {
    /// 5120.
    I8,
    /// 5121.
    U8,
    /// 5122.
    I16,
    /// 5123.
    U16,
    /// 5125.
    U32,
    /// 5126.
    F32,
}

impl Component {
    fn from_code(c: u64) -> Option<Self> {
        Some(match c {
            5120 => Self::I8,
            5121 => Self::U8,
            5122 => Self::I16,
            5123 => Self::U16,
            5125 => Self::U32,
            5126 => Self::F32,
            _ => return None,
        })
    }

    /// Bytes per component.
    pub fn size(self) -> u64 {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::U32 | Self::F32 => 4,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Self::I8 => "BYTE (5120)",
            Self::U8 => "UNSIGNED_BYTE (5121)",
            Self::I16 => "SHORT (5122)",
            Self::U16 => "UNSIGNED_SHORT (5123)",
            Self::U32 => "UNSIGNED_INT (5125)",
            Self::F32 => "FLOAT (5126)",
        }
    }

    fn is_unsigned_int(self) -> bool {
        matches!(self, Self::U8 | Self::U16 | Self::U32)
    }
}

/// Element types by name and component count.
const TYPES: [(&str, u64); 7] =
    [("SCALAR", 1), ("VEC2", 2), ("VEC3", 3), ("VEC4", 4), ("MAT2", 4), ("MAT3", 9), ("MAT4", 16)];

/// Smallest and largest `byteStride` (glTF 2.0 bufferView schema), both multiples of 4.
const STRIDE_RANGE: std::ops::RangeInclusive<u64> = 4..=252;

/// Vertex attribute elements start on 4-byte boundaries (glTF 2.0 §3.6.2.4).
const ATTRIBUTE_ALIGN: u64 = 4;

/// Most elements of an accessor without a buffer view (zeros that sparse values override):
/// its count is backed by no bytes of the file, so it is bounded here (2^24 vertices, 200 MB of
/// positions, is beyond any surface lambert can solve).
const MAX_IMPLICIT_ELEMENTS: u64 = 1 << 24;

/// What an accessor is read as.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Use {
    /// A vertex attribute (POSITION).
    Position,
    /// The vertex indices of a primitive.
    Indices,
}

/// A checked accessor.
#[derive(Debug, Clone)]
pub struct Accessor {
    view: Option<usize>,
    offset: u64,
    /// Its component type.
    pub component: Component,
    components: u64,
    /// Its element count (≥ 1).
    pub count: u64,
    sparse: Option<Sparse>,
}

#[derive(Debug, Clone)]
struct Sparse {
    count: u64,
    index_view: usize,
    index_offset: u64,
    index_component: Component,
    value_view: usize,
    value_offset: u64,
}

/// A checked buffer view.
#[derive(Debug, Clone, Copy)]
struct View {
    buffer: usize,
    offset: u64,
    length: u64,
    stride: Option<u64>,
}

/// The JSON arrays accessors read from.
pub struct Arrays<'a> {
    /// `accessors`.
    pub accessors: &'a [Value],
    /// `bufferViews`.
    pub views: &'a [Value],
}

impl Accessor {
    fn element_size(&self) -> u64 {
        self.component.size() * self.components
    }
}

/// Checks the declaration of accessor `i` (< `arrays.accessors.len()`) for `role`.
pub fn parse(arrays: &Arrays, i: usize, role: Use) -> Result<Accessor, String> {
    let what = "";
    let o = json::object(&arrays.accessors[i], "the accessor")?;
    let code = json::uint(o, "componentType", what)?;
    let component = Component::from_code(code)
        .ok_or_else(|| format!("`componentType` {code} is not a glTF component type"))?;
    let ty = json::opt_str(o, "type", what)?.ok_or("`type` is missing, and glTF requires it")?;
    let components = TYPES
        .iter()
        .find(|(n, _)| *n == ty)
        .map(|&(_, c)| c)
        .ok_or_else(|| format!("`type` \"{ty}\" is not a glTF accessor type"))?;
    let count = json::uint(o, "count", what)?;
    if count == 0 {
        return Err("`count` is 0; glTF requires at least 1".into());
    }
    let normalized = json::opt_bool(o, "normalized", what)?.unwrap_or(false);
    if normalized && matches!(component, Component::F32 | Component::U32) {
        return Err(format!(
            "it is `normalized` with component type {}; only byte and short components can be",
            component.name()
        ));
    }
    match role {
        Use::Position if (ty, component) != ("VEC3", Component::F32) => {
            return Err(format!(
                "POSITION is {ty} of {}; glTF requires VEC3 of FLOAT (5126) (quantized positions, \
                 KHR_mesh_quantization, are not read)",
                component.name()
            ))
        }
        Use::Indices if ty != "SCALAR" || !component.is_unsigned_int() => {
            return Err(format!(
            "indices are {ty} of {}; glTF requires SCALAR of UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT",
            component.name()
        ))
        }
        _ => {}
    }
    let view = json::opt_index(o, "bufferView", arrays.views.len(), "buffer views", what)?;
    let offset = json::opt_uint(o, "byteOffset", what)?;
    if view.is_none() && offset.is_some_and(|b| b > 0) {
        return Err("it has a `byteOffset` but no `bufferView`".into());
    }
    let sparse = match o.get("sparse") {
        None | Some(Value::Null) => None,
        Some(s) => Some(parse_sparse(arrays, json::object(s, "`sparse`")?, count)?),
    };
    Ok(Accessor { view, offset: offset.unwrap_or(0), component, components, count, sparse })
}

fn parse_sparse(arrays: &Arrays, o: &Obj, count: u64) -> Result<Sparse, String> {
    let n = json::uint(o, "count", "`sparse`")?;
    if n == 0 || n > count {
        return Err(format!("`sparse.count` is {n}; it must be between 1 and the accessor's count {count}"));
    }
    let nv = arrays.views.len();
    let ix = json::object(o.get("indices").unwrap_or(&Value::Null), "`sparse.indices`")?;
    let vals = json::object(o.get("values").unwrap_or(&Value::Null), "`sparse.values`")?;
    let code = json::uint(ix, "componentType", "`sparse.indices`")?;
    let index_component = Component::from_code(code)
        .filter(|c| c.is_unsigned_int())
        .ok_or_else(|| format!("`sparse.indices.componentType` {code} is not an unsigned integer type"))?;
    Ok(Sparse {
        count: n,
        index_view: json::index(ix, "bufferView", nv, "buffer views", "`sparse.indices`")?,
        index_offset: json::opt_uint(ix, "byteOffset", "`sparse.indices`")?.unwrap_or(0),
        index_component,
        value_view: json::index(vals, "bufferView", nv, "buffer views", "`sparse.values`")?,
        value_offset: json::opt_uint(vals, "byteOffset", "`sparse.values`")?.unwrap_or(0),
    })
}

fn parse_view(arrays: &Arrays, buffers: &Buffers, v: usize) -> Result<View, String> {
    let what = format!("buffer view {v}");
    let o = json::object(&arrays.views[v], &what)?;
    let buffer = json::index(o, "buffer", buffers.len(), "buffers", &what)?;
    let offset = json::opt_uint(o, "byteOffset", &what)?.unwrap_or(0);
    let length = json::uint(o, "byteLength", &what)?;
    if length == 0 {
        return Err(format!("{what}: `byteLength` is 0; glTF requires at least 1"));
    }
    let stride = json::opt_uint(o, "byteStride", &what)?;
    if let Some(s) = stride {
        if !STRIDE_RANGE.contains(&s) || !s.is_multiple_of(4) {
            return Err(format!("{what}: `byteStride` is {s}; glTF requires a multiple of 4 from 4 to 252"));
        }
    }
    let total = buffers.byte_length(buffer)?;
    if offset.checked_add(length).is_none_or(|end| end > total) {
        return Err(format!(
            "{what} spans bytes {offset}..{} of buffer {buffer}, which has {total} (`byteLength`); \
             glTF requires buffer views inside their buffers",
            offset as u128 + length as u128
        ));
    }
    Ok(View { buffer, offset, length, stride })
}

/// Checks that `count` elements of `size` bytes, `stride` apart from `offset`, fit in `view`,
/// and returns the byte range of the view within its buffer.
fn fit(
    view: &View,
    v: usize,
    offset: u64,
    stride: u64,
    count: u64,
    size: u64,
) -> Result<(usize, usize), String> {
    let need =
        stride.checked_mul(count - 1).and_then(|x| x.checked_add(size)).and_then(|x| x.checked_add(offset));
    match need {
        Some(end) if end <= view.length => Ok((view.offset as usize, (view.offset + view.length) as usize)),
        _ => Err(format!(
            "{count} element(s) of {size} bytes, {stride} bytes apart from offset {offset}, need {} bytes but \
             buffer view {v} has {}; glTF requires accessors inside their buffer views",
            offset as u128 + stride as u128 * (count as u128 - 1) + size as u128,
            view.length
        )),
    }
}

fn aligned(x: u64, to: u64, what: &str, rule: &str) -> Result<(), String> {
    if x.is_multiple_of(to) {
        Ok(())
    } else {
        Err(format!("{what} {x} is not a multiple of {to}; glTF requires {rule}"))
    }
}

/// The accessor's elements tightly packed (little-endian), sparse substitutions applied.
pub fn packed(arrays: &Arrays, buffers: &mut Buffers, a: &Accessor, role: Use) -> Result<Vec<u8>, String> {
    let size = a.element_size();
    let c = a.component.size();
    let mut out = Vec::new();
    match a.view {
        None => {
            // glTF: an accessor without a buffer view reads as zeros (sparse may override).
            if a.sparse.is_none() {
                return Err(
                    "it has neither a `bufferView` nor `sparse` values: every element would be zero".into()
                );
            }
            if a.count > MAX_IMPLICIT_ELEMENTS {
                return Err(format!(
                    "`count` is {} with no `bufferView`; lambert reads at most {MAX_IMPLICIT_ELEMENTS} implicit \
                     (zero) elements",
                    a.count
                ));
            }
            out.resize((a.count * size) as usize, 0);
        }
        Some(v) => {
            let view = parse_view(arrays, buffers, v)?;
            if role == Use::Indices && view.stride.is_some() {
                return Err(format!(
                    "buffer view {v} has a `byteStride`; glTF forbids one on the view of indices"
                ));
            }
            let stride = view.stride.unwrap_or(size);
            if stride < size {
                return Err(format!(
                    "buffer view {v} has `byteStride` {stride}, less than the {size}-byte element; glTF requires \
                     the stride to hold one element"
                ));
            }
            aligned(
                a.offset,
                c,
                "`byteOffset`",
                "accessor offsets that are multiples of the component size",
            )?;
            aligned(
                view.offset + a.offset,
                c,
                "the offset in the buffer",
                "element starts aligned to the component size",
            )?;
            if role == Use::Position {
                aligned(a.offset, ATTRIBUTE_ALIGN, "`byteOffset`", "vertex attributes aligned to 4 bytes")?;
                aligned(stride, c, "`byteStride`", "a stride that is a multiple of the component size")?;
            }
            let (lo, hi) = fit(&view, v, a.offset, stride, a.count, size)?;
            let data = &buffers.data(view.buffer)?[lo..hi];
            out.reserve((a.count * size) as usize);
            for k in 0..a.count {
                let s = (a.offset + k * stride) as usize;
                out.extend_from_slice(&data[s..s + size as usize]);
            }
        }
    }
    if let Some(s) = &a.sparse {
        apply_sparse(arrays, buffers, a, s, &mut out)?;
    }
    Ok(out)
}

fn apply_sparse(
    arrays: &Arrays,
    buffers: &mut Buffers,
    a: &Accessor,
    s: &Sparse,
    out: &mut [u8],
) -> Result<(), String> {
    let size = a.element_size() as usize;
    let read = |buffers: &mut Buffers, v: usize, offset: u64, elem: u64, c: u64| -> Result<Vec<u8>, String> {
        let view = parse_view(arrays, buffers, v)?;
        if view.stride.is_some() {
            return Err(format!("buffer view {v} of sparse data has a `byteStride`; glTF forbids one there"));
        }
        aligned(
            view.offset + offset,
            c,
            "the sparse data offset",
            "element starts aligned to the component size",
        )?;
        let (lo, hi) = fit(&view, v, offset, elem, s.count, elem)?;
        let o = offset as usize;
        Ok(buffers.data(view.buffer)?[lo..hi][o..o + (s.count * elem) as usize].to_vec())
    };
    let ic = s.index_component.size();
    let idx =
        read(buffers, s.index_view, s.index_offset, ic, ic).map_err(|e| format!("`sparse.indices`: {e}"))?;
    let vals = read(buffers, s.value_view, s.value_offset, size as u64, a.component.size())
        .map_err(|e| format!("`sparse.values`: {e}"))?;
    let mut last: Option<u64> = None;
    for (k, (ib, vb)) in idx.chunks_exact(ic as usize).zip(vals.chunks_exact(size)).enumerate() {
        let i = unsigned(ib);
        if i >= a.count || last.is_some_and(|l| i <= l) {
            return Err(format!(
                "sparse index {k} is {i}; glTF requires strictly increasing indices below the count {}",
                a.count
            ));
        }
        last = Some(i);
        out[i as usize * size..(i as usize + 1) * size].copy_from_slice(vb);
    }
    Ok(())
}

/// A little-endian unsigned integer of 1, 2 or 4 bytes.
fn unsigned(b: &[u8]) -> u64 {
    b.iter().rev().fold(0u64, |acc, &x| acc << 8 | u64::from(x))
}

/// Reads accessor `i` as POSITION: f32 triples.
pub fn positions(arrays: &Arrays, buffers: &mut Buffers, i: usize) -> Result<Vec<[f32; 3]>, String> {
    let a = parse(arrays, i, Use::Position)?;
    let bytes = packed(arrays, buffers, &a, Use::Position)?;
    let f = |b: &[u8]| f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
    Ok(bytes.chunks_exact(12).map(|p| [f(&p[0..4]), f(&p[4..8]), f(&p[8..12])]).collect())
}

/// Reads accessor `i` as the indices of a primitive with `vertices` vertices: each below
/// `vertices` and none the primitive-restart value (the type's maximum), which glTF forbids.
pub fn indices(
    arrays: &Arrays,
    buffers: &mut Buffers,
    i: usize,
    vertices: usize,
) -> Result<Vec<u32>, String> {
    let a = parse(arrays, i, Use::Indices)?;
    let bytes = packed(arrays, buffers, &a, Use::Indices)?;
    let c = a.component.size() as usize;
    let restart = (1u64 << (8 * c)) - 1;
    let mut out = Vec::with_capacity(bytes.len() / c);
    for (k, b) in bytes.chunks_exact(c).enumerate() {
        let v = unsigned(b);
        if v == restart {
            return Err(format!(
                "index {v} (entry {k}) is the primitive-restart value of {}; glTF forbids it",
                a.component.name()
            ));
        }
        if v >= vertices as u64 {
            return Err(format!("index {v} is past the {vertices} vertices of POSITION (entry {k})"));
        }
        out.push(v as u32);
    }
    Ok(out)
}
