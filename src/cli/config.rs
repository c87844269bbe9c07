//! High-level configuration: validated values derived from the arguments, built before any
//! work starts.
use super::args::{CommonArgs, MeshArgs};
use super::limits;
use lambert::exchange::Enforce;
use lambert::report::outputs::Output;
use lambert::scene::mesh_model::{MeshOptions, Unit};
use lambert::viewfactor::Params;
use lambert::{Error, Result};
use std::path::PathBuf;

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
    pub enforce: Option<Enforce>,
    /// The `-o` output (a file, or stdout when absent or `-`).
    pub output: Output,
    /// `--tolerance` as given (`None`: the default, or the scene file's).
    pub tolerance_given: Option<f64>,
    /// How the scene may reach other files (`--allow-outside-paths`), and `--unit` and
    /// `--repair` of a bare mesh scene.
    pub load: lambert::scene::LoadOptions,
}

/// `--unit` and `--repair` as mesh options.
pub fn mesh_options(a: &MeshArgs) -> Result<MeshOptions> {
    Ok(MeshOptions { unit: a.unit.unwrap_or(Unit::M), repair: a.repair, ..MeshOptions::default() })
}

impl Config {
    /// Validates the shared arguments (ranges and caps of [`limits`]) and configures the thread
    /// pool.
    pub fn from_args(a: &CommonArgs) -> Result<Self> {
        let mut params =
            Params { method: a.method, seed: a.seed, progress: !super::say::quiet(), ..Params::default() };
        if let Some(s) = a.samples {
            params.samples = limits::samples(s)?;
        }
        if let Some(r) = a.resolution {
            let ok = lambert::viewfactor::limits::RESOLUTIONS;
            if !ok.contains(&r) {
                return Err(Error::Usage(format!(
                    "--resolution must be between {} and {}",
                    ok.start(),
                    ok.end()
                )));
            }
            params.resolution = r;
        }
        if let Some(t) = a.tolerance {
            params.tolerance = limits::tolerance(t, "--tolerance")?;
        }
        if let Some(t) = a.threads {
            limits::threads(t)?;
        }
        let output = match &a.output {
            None => Output::stdout("output", "-o", "CSV"),
            Some(p) => Output::new("output", "-o", "CSV", p),
        };
        Ok(Self {
            scene: a.scene.clone(),
            params,
            patches: a.patches,
            enforce: a.enforce,
            output,
            tolerance_given: a.tolerance,
            load: lambert::scene::LoadOptions {
                allow_outside_paths: a.allow_outside_paths,
                bare: mesh_options(&a.mesh)?,
            },
        })
    }
}
