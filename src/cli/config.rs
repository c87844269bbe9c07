//! High-level configuration: validated values derived from the arguments, built before any
//! work starts.
use super::args::CommonArgs;
use lambert::viewfactor::{Method, Params};
use lambert::{Error, Result};
use std::path::PathBuf;

/// Where CSV goes.
#[derive(Debug, Clone, PartialEq)]
pub enum Output {
    /// Standard output.
    Stdout,
    /// A file, written through a temporary and renamed on success.
    File(PathBuf),
}

/// Validated options shared by `viewfactors` and `solve`.
#[derive(Debug, Clone)]
pub struct Config {
    /// Scene path.
    pub scene: PathBuf,
    /// View-factor parameters.
    pub params: Params,
    /// Report per patch.
    pub patches: bool,
    /// Enforcement choice as given (`None` = the subcommand's default).
    pub enforce: Option<String>,
    /// Output target.
    pub output: Output,
    /// `--tolerance` as given (`None`: the default, or the scene file's).
    pub tolerance_given: Option<f64>,
    /// How the scene may reach other files (`--allow-outside-paths`).
    pub load: lambert::scene::LoadOptions,
}

impl Config {
    /// A file target (`-` = stdout).
    pub fn file_output(p: &std::path::Path) -> Output {
        if p.as_os_str() == "-" {
            Output::Stdout
        } else {
            Output::File(p.to_path_buf())
        }
    }

    /// Validates the shared arguments and configures the thread pool.
    pub fn from_args(a: &CommonArgs) -> Result<Self> {
        let method: Method = a.method.parse()?;
        let mut params = Params { method, seed: a.seed, progress: !a.quiet, ..Params::default() };
        if let Some(s) = a.samples {
            if s == 0 {
                return Err(Error::Usage("--samples must be at least 1".into()));
            }
            params.samples = s;
        }
        if let Some(r) = a.resolution {
            if !(2..=16384).contains(&r) {
                return Err(Error::Usage("--resolution must be between 2 and 16384".into()));
            }
            params.resolution = r;
        }
        if let Some(t) = a.tolerance {
            if !(t.is_finite() && t > 0.0 && t < 1.0) {
                return Err(Error::Usage(format!("--tolerance must be in (0, 1), got {t}")));
            }
            params.tolerance = t;
        }
        if let Some(e) = &a.enforce {
            if !["none", "reciprocity", "closure"].contains(&e.as_str()) {
                return Err(Error::Usage(format!(
                    "unknown --enforce '{e}'; expected none, reciprocity or closure"
                )));
            }
        }
        if let Some(t) = a.threads {
            if t == 0 {
                return Err(Error::Usage("--threads must be at least 1".into()));
            }
            // The global pool can be set once per process; a second call keeps the first.
            let _ = rayon::ThreadPoolBuilder::new().num_threads(t).build_global();
        }
        let output = match &a.output {
            None => Output::Stdout,
            Some(p) if p.as_os_str() == "-" => Output::Stdout,
            Some(p) => Output::File(p.clone()),
        };
        Ok(Self {
            scene: a.scene.clone(),
            params,
            patches: a.patches,
            enforce: a.enforce.clone(),
            output,
            tolerance_given: a.tolerance,
            load: lambert::scene::LoadOptions { allow_outside_paths: a.allow_outside_paths },
        })
    }
}
