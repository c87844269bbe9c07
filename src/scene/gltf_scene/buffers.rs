//! glTF buffers, loaded on first use and kept: the GLB BIN chunk, `data:` URIs (base64) and
//! external files. An external file must be a regular file under the glTF file's own folder,
//! named by a relative path without `..`; absolute and `..` paths (and symbolic links leading
//! out of the folder) are refused unless [`super::super::LoadOptions::allow_outside_paths`] is
//! set. Devices, FIFOs and folders are never opened, `file:` and network URIs never followed,
//! and no file is read past the buffer's declared `byteLength`.
use super::json::{self, Obj};
use crate::error::opt;
use serde_json::Value;
use std::borrow::Cow;
use std::io::Read;
use std::path::{Component, Path, PathBuf};

/// The buffers of one glTF file.
pub struct Buffers<'a> {
    list: &'a [Value],
    bin: Option<&'a [u8]>,
    glb: bool,
    folder: PathBuf,
    allow_outside: bool,
    loaded: Vec<Option<Cow<'a, [u8]>>>,
}

impl<'a> Buffers<'a> {
    /// The buffers of `list` (the JSON `buffers` array) of a file in `folder`.
    pub fn new(
        list: &'a [Value],
        bin: Option<&'a [u8]>,
        glb: bool,
        folder: &Path,
        allow_outside: bool,
    ) -> Self {
        Self { list, bin, glb, folder: folder.to_path_buf(), allow_outside, loaded: vec![None; list.len()] }
    }

    /// The files that the buffers' relative URIs name (read or not), so that no output of a
    /// run replaces one of them.
    pub fn external_files(&self) -> Vec<PathBuf> {
        self.list
            .iter()
            .filter_map(|b| b.get("uri").and_then(Value::as_str))
            .filter(|uri| scheme(uri).is_none_or(|s| s.len() == 1))
            .filter_map(|uri| percent_decode(uri).ok())
            .map(|rel| if self.folder == Path::new(".") { PathBuf::from(rel) } else { self.folder.join(rel) })
            .collect()
    }

    /// Number of buffers in the file.
    pub fn len(&self) -> usize {
        self.list.len()
    }

    /// The declared `byteLength` of buffer `i` (< [`Self::len`]).
    pub fn byte_length(&self, i: usize) -> Result<u64, String> {
        let what = format!("buffer {i}");
        let o = json::object(&self.list[i], &what)?;
        let n = json::uint(o, "byteLength", &what)?;
        if n == 0 {
            return Err(format!("{what}: `byteLength` is 0; glTF requires at least 1"));
        }
        Ok(n)
    }

    /// The first `byteLength` bytes of buffer `i` (< [`Self::len`]), loaded on first use.
    pub fn data(&mut self, i: usize) -> Result<&[u8], String> {
        if self.loaded[i].is_none() {
            let data = self.load(i).map_err(|e| format!("buffer {i}: {e}"))?;
            self.loaded[i] = Some(data);
        }
        Ok(self.loaded[i].as_deref().unwrap_or_default())
    }

    fn load(&self, i: usize) -> Result<Cow<'a, [u8]>, String> {
        let n = self.byte_length(i)?;
        let o: &Obj = json::object(&self.list[i], "the buffer")?;
        let data: Cow<[u8]> = match json::opt_str(o, "uri", "the buffer")? {
            None if self.glb && i == 0 => {
                Cow::Borrowed(self.bin.ok_or("it has no `uri` and the GLB file has no BIN chunk")?)
            }
            None if self.glb => {
                return Err("only buffer 0 of a GLB file may omit `uri` (the BIN chunk)".into())
            }
            None => return Err("it has no `uri`; a .gltf file's buffers need one".into()),
            Some(uri) => self.read_uri(uri, n)?,
        };
        if (data.len() as u64) < n {
            return Err(format!("it holds {} bytes, fewer than its `byteLength` {n}", data.len()));
        }
        Ok(match data {
            Cow::Borrowed(b) => Cow::Borrowed(&b[..n as usize]),
            Cow::Owned(mut v) => {
                v.truncate(n as usize);
                Cow::Owned(v)
            }
        })
    }

    fn read_uri(&self, uri: &str, n: u64) -> Result<Cow<'a, [u8]>, String> {
        match scheme(uri) {
            Some(s) if s.eq_ignore_ascii_case("data") => data_uri(uri).map(Cow::Owned),
            Some(s) if s.eq_ignore_ascii_case("file") => Err(format!(
                "the URI '{}' is a file: URI, which lambert does not follow; put the buffer file \
                 beside the glTF file and give its relative path",
                quote(uri)
            )),
            Some(s) if s.len() > 1 => Err(format!(
                "the URI '{}' has the scheme '{s}:'; lambert reads only relative file paths and data: URIs",
                quote(uri)
            )),
            // One letter before ':' is a Windows drive (C:\…), an absolute path.
            _ => external(&self.folder, uri, n, self.allow_outside).map(Cow::Owned),
        }
    }
}

/// The URI's scheme (RFC 3986: a letter, then letters, digits, `+`, `-`, `.`, then `:`).
fn scheme(uri: &str) -> Option<&str> {
    let (s, _) = uri.split_once(':')?;
    let mut chars = s.chars();
    let ok = chars.next().is_some_and(|c| c.is_ascii_alphabetic())
        && chars.all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c));
    ok.then_some(s)
}

/// The decoded bytes of a `data:[<media type>][;base64],<data>` URI.
fn data_uri(uri: &str) -> Result<Vec<u8>, String> {
    let Some((head, body)) = uri.split_once(',') else {
        return Err("the data: URI has no ',' before its data".into());
    };
    if !head.ends_with(";base64") {
        return Err("the data: URI is not base64-encoded (';base64,' is missing)".into());
    }
    use base64::engine::{general_purpose, DecodePaddingMode, Engine, GeneralPurpose};
    // Padding optional, as glTF writers differ on it.
    let config = general_purpose::PAD.with_decode_padding_mode(DecodePaddingMode::Indifferent);
    GeneralPurpose::new(&base64::alphabet::STANDARD, config)
        .decode(body)
        .map_err(|e| format!("the data: URI is not valid base64: {e}"))
}

/// The URI with its percent escapes decoded (RFC 3986), as UTF-8 text.
fn percent_decode(uri: &str) -> Result<String, String> {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut k = 0;
    while k < b.len() {
        if b[k] == b'%' {
            let hex = b.get(k + 1..k + 3).and_then(|h| std::str::from_utf8(h).ok());
            let byte = hex.and_then(|h| u8::from_str_radix(h, 16).ok());
            let byte = byte.ok_or_else(|| format!("the URI '{}' has a bad percent escape", quote(uri)))?;
            out.push(byte);
            k += 3;
        } else {
            out.push(b[k]);
            k += 1;
        }
    }
    String::from_utf8(out).map_err(|_| format!("the URI '{}' decodes to text that is not UTF-8", quote(uri)))
}

/// The first `n` bytes of the external file `uri`, relative to `folder`.
fn external(folder: &Path, uri: &str, n: u64, allow_outside: bool) -> Result<Vec<u8>, String> {
    let rel = percent_decode(uri)?;
    let rel_path = Path::new(&rel);
    let drive = scheme(&rel).is_some();
    let outside = drive
        || rel.starts_with(['/', '\\'])
        || rel_path.is_absolute()
        || rel.split(['/', '\\']).any(|c| c == "..")
        || rel_path.components().any(|c| matches!(c, Component::ParentDir | Component::RootDir));
    if outside && !allow_outside {
        return Err(format!(
            "the buffer file '{}' is an absolute path or leaves the glTF file's folder with '..'; \
             buffer files must lie under that folder ({} allows others)",
            quote(&rel),
            opt("allow_outside_paths")
        ));
    }
    if rel.is_empty() {
        return Err("the buffer's `uri` is empty".into());
    }
    let full = folder.join(rel_path);
    let shown = full.display();
    let meta = std::fs::metadata(&full).map_err(|e| format!("cannot open the buffer file {shown}: {e}"))?;
    if !meta.is_file() {
        return Err(format!(
            "the buffer file {shown} is not a regular file (a folder, device or FIFO); it is not read"
        ));
    }
    if !allow_outside {
        let canon = |p: &Path| p.canonicalize().map_err(|e| format!("cannot resolve {}: {e}", p.display()));
        let (real, base) = (canon(&full)?, canon(folder)?);
        if !real.starts_with(&base) {
            return Err(format!(
                "the buffer file {shown} is a link to {}, outside the glTF file's folder \
                 ({} allows it)",
                real.display(),
                opt("allow_outside_paths")
            ));
        }
    }
    let file = std::fs::File::open(&full).map_err(|e| format!("cannot open the buffer file {shown}: {e}"))?;
    let mut data = Vec::with_capacity(meta.len().min(n) as usize);
    file.take(n).read_to_end(&mut data).map_err(|e| format!("cannot read the buffer file {shown}: {e}"))?;
    if (data.len() as u64) < n {
        return Err(format!(
            "the buffer file {shown} has {} bytes, fewer than the buffer's `byteLength` {n}",
            data.len()
        ));
    }
    Ok(data)
}

/// At most this many characters of a URI are quoted in a message (a data: URI can be huge).
const URI_QUOTE_MAX: usize = 80;

fn quote(uri: &str) -> String {
    if uri.chars().count() <= URI_QUOTE_MAX {
        uri.to_string()
    } else {
        format!("{}…", uri.chars().take(URI_QUOTE_MAX).collect::<String>())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn load(list: &Value, folder: &Path, allow: bool) -> Result<Vec<u8>, String> {
        let list = list.as_array().unwrap();
        let mut b = Buffers::new(list, None, false, folder, allow);
        b.data(0).map(<[u8]>::to_vec)
    }

    #[test]
    fn uri_rules() {
        let dir = tempfile::tempdir().unwrap();
        let sub = dir.path().join("model");
        std::fs::create_dir(&sub).unwrap();
        std::fs::write(sub.join("a b.bin"), [1u8, 2, 3, 4, 5, 6]).unwrap();
        std::fs::write(dir.path().join("up.bin"), [9u8; 8]).unwrap();
        let ok = |uri: &str, n: u64| load(&json!([{"uri": uri, "byteLength": n}]), &sub, false);
        assert_eq!(ok("a%20b.bin", 4).unwrap(), [1, 2, 3, 4], "read only byteLength bytes");
        assert!(ok("a%20b.bin", 7)
            .unwrap_err()
            .contains("has 6 bytes, fewer than the buffer's `byteLength` 7"));
        assert_eq!(ok("data:application/octet-stream;base64,AQID", 3).unwrap(), [1, 2, 3]);
        assert_eq!(ok("data:application/gltf-buffer;base64,AQI=", 2).unwrap(), [1, 2]);
        assert_eq!(ok("data:application/gltf-buffer;base64,AQI", 2).unwrap(), [1, 2]);
        assert!(ok("data:application/octet-stream;base64,AQID", 4).unwrap_err().contains("fewer than"));
        assert!(ok("data:,abc", 3).unwrap_err().contains("not base64"));
        assert!(ok("data:;base64,@@@", 3).unwrap_err().contains("not valid base64"));
        for bad in ["../up.bin", "sub/../../up.bin", "/etc/passwd", "C:/x.bin", "..\\up.bin"] {
            let e = ok(bad, 4).unwrap_err();
            assert!(
                e.contains("leaves the glTF file's folder") && e.contains(&opt("allow_outside_paths")),
                "{bad}: {e}"
            );
        }
        assert_eq!(load(&json!([{"uri": "../up.bin", "byteLength": 8}]), &sub, true).unwrap(), [9; 8]);
        assert!(ok("file:///etc/passwd", 4).unwrap_err().contains("file: URI"));
        assert!(ok("https://example.org/a.bin", 4).unwrap_err().contains("scheme 'https:'"));
        assert!(ok("a%zz.bin", 4).unwrap_err().contains("bad percent escape"));
        assert!(ok("a%ff.bin", 4).unwrap_err().contains("not UTF-8"));
        assert!(ok("missing.bin", 4).unwrap_err().contains("cannot open the buffer file"));
        assert!(ok(".", 4).unwrap_err().contains("not a regular file"));
        let e = load(&json!([{"uri": "x.bin"}]), &sub, false).unwrap_err();
        assert!(e.contains("buffer 0 has no `byteLength`"), "{e}");
        let e = load(&json!([{"byteLength": 4}]), &sub, false).unwrap_err();
        assert!(e.contains("has no `uri`"), "{e}");
    }

    #[cfg(unix)]
    #[test]
    fn devices_fifos_and_links_out_are_never_read() {
        let dir = tempfile::tempdir().unwrap();
        let n = |uri: &str| json!([{"uri": uri, "byteLength": 16}]);
        for dev in ["/dev/zero", "/dev/urandom"] {
            let e = load(&n(dev), dir.path(), true).unwrap_err();
            assert!(e.contains("not a regular file"), "{e}");
        }
        let fifo = dir.path().join("pipe.bin");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if made.is_ok_and(|s| s.success()) {
            assert!(load(&n("pipe.bin"), dir.path(), false).unwrap_err().contains("not a regular file"));
        }
        let elsewhere = tempfile::tempdir().unwrap();
        std::fs::write(elsewhere.path().join("secret.bin"), [7u8; 16]).unwrap();
        std::os::unix::fs::symlink(elsewhere.path().join("secret.bin"), dir.path().join("link.bin")).unwrap();
        let e = load(&n("link.bin"), dir.path(), false).unwrap_err();
        assert!(e.contains("is a link to") && e.contains("outside the glTF file's folder"), "{e}");
        assert_eq!(load(&n("link.bin"), dir.path(), true).unwrap(), [7u8; 16]);
    }
}
