//! Library error type. Every variant maps to a CLI exit code (SPEC.md): bad input → 2,
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

impl std::fmt::Display for InputError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
        }
        if let Some(s) = &self.surface {
            write!(f, ": surface '{s}'")?;
        }
        write!(f, ": {}", self.problem)
    }
}

/// Every error the library reports.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Bad scene, view-factor file or option value (exit code 2).
    #[error("{0}")]
    Input(InputError),
    /// A bad combination of options or an unsupported request (exit code 2).
    #[error("{0}")]
    Usage(String),
    /// The requested method cannot treat this configuration (exit code 2): never approximated
    /// silently.
    #[error("unsupported: {0}")]
    Unsupported(String),
    /// The computation failed: singular system, no convergence, leaking enclosure (exit code 1).
    #[error("{0}")]
    Compute(String),
    /// An I/O failure while writing results (exit code 1).
    #[error("{path}: {source}")]
    Io {
        /// The file being read or written.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
}

impl Error {
    /// The SPEC.md exit code for this error.
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
