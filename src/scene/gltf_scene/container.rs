//! The two glTF containers: a JSON text (.gltf) or a GLB binary (.glb, magic `glTF`), split
//! into the JSON text and the optional BIN chunk. Every length is checked against the bytes
//! before it is used (glTF 2.0 §4.4, binary glTF layout).

/// GLB header: magic, version, total length (three u32).
const HEADER_LEN: usize = 12;
/// GLB chunk header: chunk length, chunk type (two u32).
const CHUNK_HEADER_LEN: usize = 8;
/// Chunk type of the JSON chunk, "JSON" as a little-endian u32.
const CHUNK_JSON: u32 = 0x4E4F_534A;
/// Chunk type of the binary buffer chunk, "BIN\0" as a little-endian u32.
const CHUNK_BIN: u32 = 0x004E_4942;

/// The JSON text of a glTF file and, for a GLB, its BIN chunk.
#[derive(Debug, Clone, Copy)]
pub struct Container<'a> {
    /// The JSON text.
    pub json: &'a [u8],
    /// The GLB BIN chunk, the data of a buffer without `uri`.
    pub bin: Option<&'a [u8]>,
    /// True for a GLB file.
    pub glb: bool,
}

fn word(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
}

/// Splits `bytes` into the JSON text and the BIN chunk; a file not starting with `glTF` is JSON.
pub fn split(bytes: &[u8]) -> Result<Container<'_>, String> {
    if !bytes.starts_with(b"glTF") {
        return Ok(Container { json: bytes, bin: None, glb: false });
    }
    if bytes.len() < HEADER_LEN + CHUNK_HEADER_LEN {
        return Err(format!(
            "malformed GLB: the file has {} bytes, fewer than its {}-byte header and first chunk header",
            bytes.len(),
            HEADER_LEN + CHUNK_HEADER_LEN
        ));
    }
    let version = word(bytes, 4);
    if version != 2 {
        return Err(format!("unsupported GLB version {version}; lambert reads glTF 2.0"));
    }
    let length = word(bytes, 8) as usize;
    if length < HEADER_LEN + CHUNK_HEADER_LEN || length > bytes.len() {
        return Err(format!("malformed GLB: header length {length} but the file has {} bytes", bytes.len()));
    }
    let mut rest = &bytes[HEADER_LEN..length];
    let mut chunks: Vec<(u32, &[u8])> = Vec::new();
    while !rest.is_empty() {
        let k = chunks.len();
        if rest.len() < CHUNK_HEADER_LEN {
            return Err(format!(
                "malformed GLB: chunk {k} header is cut off ({} of {CHUNK_HEADER_LEN} bytes before the end)",
                rest.len()
            ));
        }
        let (len, kind) = (word(rest, 0) as usize, word(rest, 4));
        let body = &rest[CHUNK_HEADER_LEN..];
        if len > body.len() {
            return Err(format!(
                "malformed GLB: chunk {k} declares {len} bytes but only {} remain in the file",
                body.len()
            ));
        }
        chunks.push((kind, &body[..len]));
        rest = &body[len..];
    }
    let json = match chunks.first() {
        Some(&(CHUNK_JSON, json)) => json,
        _ => return Err("malformed GLB: the first chunk must be the JSON chunk".into()),
    };
    // The BIN chunk, when present, is the second; later chunks of unknown types are ignored
    // (glTF 2.0: clients must ignore unknown chunk types).
    let bin = match chunks.get(1) {
        Some(&(CHUNK_BIN, bin)) => Some(bin),
        _ => None,
    };
    for (k, &(kind, _)) in chunks.iter().enumerate().skip(1) {
        if (kind == CHUNK_JSON || kind == CHUNK_BIN) && !(k == 1 && kind == CHUNK_BIN) {
            return Err(format!(
                "malformed GLB: chunk {k} is a second JSON or a misplaced BIN chunk (JSON first, then at most one BIN)"
            ));
        }
    }
    Ok(Container { json, bin, glb: true })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn glb(chunks: &[(u32, &[u8])]) -> Vec<u8> {
        let mut body = Vec::new();
        for (kind, data) in chunks {
            body.extend((data.len() as u32).to_le_bytes());
            body.extend(kind.to_le_bytes());
            body.extend(*data);
        }
        let mut out = b"glTF".to_vec();
        out.extend(2u32.to_le_bytes());
        out.extend(((HEADER_LEN + body.len()) as u32).to_le_bytes());
        out.extend(body);
        out
    }

    #[test]
    fn splits_json_and_bin_and_ignores_unknown_chunks() {
        let bytes = glb(&[(CHUNK_JSON, b"{}  "), (CHUNK_BIN, &[1, 2, 3, 4]), (0x1234, b"xyz!")]);
        let c = split(&bytes).unwrap();
        assert_eq!((c.json, c.bin, c.glb), (&b"{}  "[..], Some(&[1u8, 2, 3, 4][..]), true));
        let text = split(b"{\"asset\":{}}").unwrap();
        assert!(!text.glb && text.bin.is_none());
    }

    #[test]
    fn refuses_bad_layouts() {
        let cases: Vec<(Vec<u8>, &str)> = vec![
            (b"glTF\x02\0\0\0".to_vec(), "fewer than its 20-byte header"),
            (glb(&[(CHUNK_BIN, b"1234")]), "first chunk must be the JSON chunk"),
            (glb(&[(CHUNK_JSON, b"{}  "), (CHUNK_JSON, b"{}  ")]), "second JSON or a misplaced BIN"),
            (glb(&[(CHUNK_JSON, b"{}  "), (7, b"...."), (CHUNK_BIN, b"1234")]), "misplaced BIN"),
        ];
        for (bytes, needle) in cases {
            let e = split(&bytes).unwrap_err();
            assert!(e.contains(needle), "{e}");
        }
        let mut v3 = glb(&[(CHUNK_JSON, b"{}  ")]);
        v3[4] = 3;
        assert!(split(&v3).unwrap_err().contains("version 3"));
        let mut long = glb(&[(CHUNK_JSON, b"{}  ")]);
        long[8] = 200;
        assert!(split(&long).unwrap_err().contains("header length 200"));
        let mut chunk = glb(&[(CHUNK_JSON, b"{}  ")]);
        chunk[12] = 9;
        assert!(split(&chunk).unwrap_err().contains("declares 9 bytes"));
        let mut cut = glb(&[(CHUNK_JSON, b"{}  ")]);
        cut.extend([0, 0, 0]);
        let n = cut.len() as u32;
        cut[8..12].copy_from_slice(&n.to_le_bytes());
        assert!(split(&cut).unwrap_err().contains("header is cut off"));
    }
}
