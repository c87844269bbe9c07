//! Library error type. Every variant maps to a CLI exit code (docs/SPEC.md): bad input → 2,
//! failed computation → 1.
use std::path::PathBuf;

/// Result alias for the library.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// A problem with the user's input, located by file, surface and (when known) line.
#[derive(Debug, Clone, PartialEq)]
pub struct InputError {
    /// The file that holds the problem.
    pub file: PathBuf,
    /// The surface (or model) the problem belongs to, when there is one.
    pub surface: Option<String>,
    /// 1-based line in `file`, when known.
    pub line: Option<usize>,
    /// What is wrong, in words a user can act on.
    pub problem: String,
}

impl InputError {
    /// An input error about `file` as a whole.
    pub fn file(file: impl Into<PathBuf>, problem: impl Into<String>) -> Self {
        Self { file: file.into(), surface: None, line: None, problem: problem.into() }
    }
    /// An input error about one named surface in `file`.
    pub fn surface(file: impl Into<PathBuf>, surface: impl Into<String>, problem: impl Into<String>) -> Self {
        Self { file: file.into(), surface: Some(surface.into()), line: None, problem: problem.into() }
    }
    /// Attach a 1-based line number.
    pub fn at_line(mut self, line: usize) -> Self {
        self.line = Some(line);
        self
    }
}

impl InputError {
    /// The message with its option marks ([`opt`]) unspelled.
    fn to_string_raw(&self) -> String {
        let mut s = self.file.display().to_string();
        if let Some(line) = self.line {
            s.push_str(&format!(":{line}"));
        }
        if let Some(surface) = &self.surface {
            s.push_str(&format!(": surface '{surface}'"));
        }
        s.push_str(": ");
        s.push_str(&self.problem);
        s
    }
}

impl std::fmt::Display for InputError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&spell_options(&self.to_string_raw(), &keyword))
    }
}

/// Every error the library reports.
#[derive(Debug)]
pub enum Error {
    /// Bad scene, view-factor file or option value (exit code 2).
    Input(InputError),
    /// A bad combination of options or an unsupported request (exit code 2).
    Usage(String),
    /// The requested method cannot treat this configuration (exit code 2): never approximated
    /// silently.
    Unsupported(String),
    /// The computation failed: singular system, no convergence, leaking enclosure (exit code 1).
    Compute(String),
    /// An I/O failure while writing results (exit code 1).
    Io {
        /// The file being read or written.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
}

/// Opens an option's mark in a message ([`opt`]).
const MARK_OPEN: &str = "{option:";
/// Closes it.
const MARK_CLOSE: char = '}';

/// An option of a run named inside a message: each front end spells it its own way (the
/// library and Python by its keyword, `samples`; the command line by its flag, `--samples`),
/// so the library's messages name its own concepts. `name` is the keyword (snake case).
pub fn opt(name: &str) -> String {
    format!("{MARK_OPEN}{name}{MARK_CLOSE}")
}

/// `msg` with every option mark spelled by `spell` (given the keyword).
pub fn spell_options(msg: &str, spell: &dyn Fn(&str) -> String) -> String {
    let mut out = String::with_capacity(msg.len());
    let mut rest = msg;
    while let Some(k) = rest.find(MARK_OPEN) {
        let after = &rest[k + MARK_OPEN.len()..];
        match after.find(MARK_CLOSE) {
            Some(e) if after[..e].bytes().all(|b| b.is_ascii_lowercase() || b == b'_') => {
                out.push_str(&rest[..k]);
                out.push_str(&spell(&after[..e]));
                rest = &after[e + 1..];
            }
            _ => {
                out.push_str(&rest[..k + MARK_OPEN.len()]);
                rest = after;
            }
        }
    }
    out.push_str(rest);
    out
}

/// The library's spelling of an option: its keyword.
pub fn keyword(name: &str) -> String {
    name.to_string()
}

impl Error {
    /// The message with its options spelled by `spell` (the command line passes its flags);
    /// `Display` spells them as the library's keywords.
    pub fn spelled(&self, spell: &dyn Fn(&str) -> String) -> String {
        let raw = match self {
            Error::Input(e) => e.to_string_raw(),
            Error::Usage(s) | Error::Compute(s) => s.clone(),
            Error::Unsupported(s) => format!("unsupported: {s}"),
            Error::Io { path, source } => format!("{}: {source}", path.display()),
        };
        spell_options(&raw, spell)
    }
}

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.spelled(&keyword))
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

impl Error {
    /// The docs/SPEC.md exit code for this error.
    pub fn exit_code(&self) -> u8 {
        match self {
            Error::Input(_) | Error::Usage(_) | Error::Unsupported(_) => 2,
            Error::Compute(_) | Error::Io { .. } => 1,
        }
    }
    /// The same error with `notes` appended to its message (what the computation reported
    /// before it failed, such as entries that missed their error goal); unchanged without notes.
    pub fn with_notes(self, notes: &[String]) -> Self {
        if notes.is_empty() {
            return self;
        }
        let tail = format!(" (the view-factor method reported: {})", notes.join("; "));
        match self {
            Error::Input(mut e) => {
                e.problem.push_str(&tail);
                Error::Input(e)
            }
            Error::Usage(s) => Error::Usage(s + &tail),
            Error::Unsupported(s) => Error::Unsupported(s + &tail),
            Error::Compute(s) => Error::Compute(s + &tail),
            io @ Error::Io { .. } => io,
        }
    }
}

impl From<InputError> for Error {
    fn from(e: InputError) -> Self {
        Error::Input(e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Options read as the library's keywords by default and as flags when the command line
    /// spells them; text that only looks like a mark is left alone.
    #[test]
    fn options_are_spelled_by_each_front_end() {
        let e = Error::Usage(format!(
            "{} 3 is too few; {} {{x}} {{option:Bad}}",
            opt("samples"),
            opt("allow_outside_paths")
        ));
        assert_eq!(e.to_string(), "samples 3 is too few; allow_outside_paths {x} {option:Bad}");
        let flag = |n: &str| format!("--{}", n.replace('_', "-"));
        assert_eq!(e.spelled(&flag), "--samples 3 is too few; --allow-outside-paths {x} {option:Bad}");
        let i = Error::Input(
            InputError::file("a.gltf", format!("give {}", opt("allow_outside_paths"))).at_line(3),
        );
        assert_eq!(i.spelled(&flag), "a.gltf:3: give --allow-outside-paths");
        assert_eq!(i.to_string(), "a.gltf:3: give allow_outside_paths");
    }
}
