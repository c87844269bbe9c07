//! TOML and serde errors as [`InputError`]s: the span becomes a 1-based line, and the
//! `[[surface]]` entry that holds it gives the surface name.
use crate::error::InputError;
use std::path::Path;

/// 1-based line of byte `offset` in `text`.
pub fn line_of(text: &str, offset: usize) -> usize {
    let end = offset.min(text.len());
    text.as_bytes()[..end].iter().filter(|&&b| b == b'\n').count() + 1
}

/// The newline offsets of a text, for many [`line_of`] lookups (one per `[[surface]]`) in
/// O(log n) each instead of a scan from the start.
pub struct Lines(Vec<usize>);

impl Lines {
    /// Indexes `text`.
    pub fn new(text: &str) -> Self {
        Self(text.bytes().enumerate().filter(|&(_, b)| b == b'\n').map(|(k, _)| k).collect())
    }
    /// 1-based line of byte `offset` (as [`line_of`]).
    pub fn line(&self, offset: usize) -> usize {
        self.0.partition_point(|&k| k < offset) + 1
    }
}

/// Which section holds byte `offset`.
pub enum SurfaceAt {
    /// A named surface.
    Named(String),
    /// The k-th `[[surface]]`, without a usable name.
    Unnamed(usize),
    /// Another top-level table, e.g. `[ambient]` or `[[model]] number 2`.
    Section(String),
}

/// The `[[surface]]` entry whose section holds `offset`, if any. Recovers from syntax errors
/// elsewhere in the file (duplicate keys, say) as far as the TOML parser can.
pub fn surface_at(text: &str, offset: usize) -> Option<SurfaceAt> {
    let (table, _) = toml::de::DeTable::parse_recoverable(text);
    // Every top-level section start; array-of-tables entries start at their header.
    let mut best: Option<(usize, Option<SurfaceAt>)> = None;
    let mut consider = |start: usize, what: Option<SurfaceAt>| {
        if start <= offset && best.as_ref().is_none_or(|b| start >= b.0) {
            best = Some((start, what));
        }
    };
    for (key, value) in table.get_ref().iter() {
        let name = key.get_ref();
        let start = key.span().start.min(value.span().start);
        match value.get_ref().as_array() {
            Some(entries) if entries.iter().all(|e| e.get_ref().is_table()) => {
                for (k, e) in entries.iter().enumerate() {
                    let what = match name.as_ref() {
                        "surface" => describe(e.get_ref(), k),
                        _ => SurfaceAt::Section(format!("[[{name}]] number {}", k + 1)),
                    };
                    consider(e.span().start, Some(what));
                }
            }
            _ if value.get_ref().is_table() => consider(start, Some(SurfaceAt::Section(format!("[{name}]")))),
            _ => consider(start, None),
        }
    }
    best.and_then(|b| b.1)
}

/// A `[[surface]]` entry by name, or by position when it has no usable name.
fn describe(entry: &toml::de::DeValue<'_>, k: usize) -> SurfaceAt {
    entry
        .as_table()
        .and_then(|t| t.iter().find(|(key, _)| key.get_ref() == "name"))
        .and_then(|(_, v)| v.get_ref().as_str().map(str::to_string))
        .filter(|n| !n.trim().is_empty())
        .map_or(SurfaceAt::Unnamed(k + 1), SurfaceAt::Named)
}

/// serde's wording, made plainer.
fn plain(message: &str) -> String {
    message
        .replace("expected i64", "expected an integer")
        .replace("expected f64", "expected a number")
        .replace("expected a sequence", "expected an array")
        .replace("expected u64", "expected a non-negative integer")
}

/// A TOML syntax or schema error located by line and surface.
pub fn from_toml(path: &Path, text: &str, e: &toml::de::Error) -> InputError {
    let mut err = InputError::file(path, plain(e.message().trim()));
    if let Some(span) = e.span() {
        err.line = Some(line_of(text, span.start));
        match surface_at(text, span.start) {
            Some(SurfaceAt::Named(n)) => err.surface = Some(n),
            Some(SurfaceAt::Unnamed(k)) => {
                err.problem = format!("in [[surface]] number {k}: {}", err.problem)
            }
            Some(SurfaceAt::Section(s)) => err.problem = format!("in {s}: {}", err.problem),
            None => {}
        }
    }
    err
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn indexed_lines_match_the_scan() {
        let text = "a\n\nbc\nd";
        let lines = Lines::new(text);
        for offset in 0..=text.len() + 2 {
            assert_eq!(lines.line(offset), line_of(text, offset), "offset {offset}");
        }
    }

    #[test]
    fn locates_surface_sections() {
        let text =
            "title = \"x\"\n[[surface]]\nname = \"a\"\nfoo = 1\n[[surface]]\nbar = 2\n[ambient]\nt = 1\n";
        assert!(matches!(surface_at(text, text.find("foo").unwrap()), Some(SurfaceAt::Named(n)) if n == "a"));
        assert!(matches!(surface_at(text, text.find("bar").unwrap()), Some(SurfaceAt::Unnamed(2))));
        assert!(
            matches!(surface_at(text, text.find("t = 1").unwrap()), Some(SurfaceAt::Section(s)) if s == "[ambient]")
        );
        assert!(surface_at(text, 0).is_none());
        assert_eq!(line_of(text, text.find("bar").unwrap()), 6);
    }
}
