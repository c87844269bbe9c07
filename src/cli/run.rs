//! Orchestration of the subcommands: load → compute → report. No physics here.
use super::args::{Command, SolveArgs, ValidateArgs, ViewfactorsArgs};
use super::config::{Config, Output};
use lambert::report;
use lambert::scene;
use lambert::viewfactor::{self, Level};
use lambert::{Error, Result};
use std::io::Write;
use std::path::Path;

/// Runs one subcommand.
pub fn run(cmd: Command) -> Result<()> {
    match cmd {
        Command::Viewfactors(a) => viewfactors(a),
        Command::Solve(a) => solve(a),
        Command::Validate(a) => validate(a),
    }
}

/// Writes through `f` to stdout, or to a temporary beside `path` that replaces it only on
/// success, so a failed run never destroys an earlier result.
pub fn write_output(output: &Output, f: impl FnOnce(&mut dyn Write, &Path) -> Result<()>) -> Result<()> {
    match output {
        Output::Stdout => {
            let stdout = std::io::stdout();
            let mut lock = stdout.lock();
            f(&mut lock, Path::new("<stdout>"))
        }
        Output::File(path) => {
            let io = |e| Error::Io { path: path.clone(), source: e };
            let mut tmp_name = path.file_name().unwrap_or_default().to_os_string();
            tmp_name.push(".partial");
            let tmp = path.with_file_name(tmp_name);
            let mut file = std::io::BufWriter::new(std::fs::File::create(&tmp).map_err(io)?);
            let result = f(&mut file, path).and_then(|_| file.flush().map_err(io));
            drop(file);
            match result {
                Ok(()) => std::fs::rename(&tmp, path).map_err(io),
                Err(e) => {
                    let _ = std::fs::remove_file(&tmp);
                    Err(e)
                }
            }
        }
    }
}

fn viewfactors(a: ViewfactorsArgs) -> Result<()> {
    let cfg = Config::from_args(&a.common)?;
    let scene = scene::load(&cfg.scene)?;
    for w in &scene.warnings {
        eprintln!("lambert: warning: {w}");
    }
    let level = if cfg.patches { Level::Patch } else { Level::Surface };
    let vf = viewfactor::compute(&scene, &cfg.params, level)?;
    write_output(&cfg.output, |w, p| report::csv::write_viewfactors(w, &vf, !scene.is_closed(), p))?;
    let (worst, at) = vf.max_patch_row_error();
    let secs = vf.wall.as_secs_f64();
    eprintln!(
        "lambert: {} patches, {} pairs, {:.3} s ({:.3e} pairs/s), method {}",
        scene.patches.len(),
        vf.pairs,
        secs,
        vf.pairs as f64 / secs.max(1e-9),
        cfg.params.method
    );
    if scene.is_closed() && !scene.patches.is_empty() {
        eprintln!("lambert: closed scene, max |row sum - 1| = {worst:.3e} (patch {})", scene.patch_name(at));
    }
    Ok(())
}

fn solve(_a: SolveArgs) -> Result<()> {
    Err(Error::Usage("`solve` is not available in this build yet".into()))
}

fn validate(a: ValidateArgs) -> Result<()> {
    let options = lambert::validate::Options { cases: a.cases, out: a.out, quick: a.quick };
    lambert::validate::check_options(&options)?;
    let suite = lambert::validate::run(&options, &mut |line| eprintln!("validate: {line}"))?;
    print!("{}", lambert::validate::report::console(&suite.checks));
    eprintln!("validate: report written to {}", options.out.join("report.md").display());
    match suite.failures() {
        0 => Ok(()),
        n => Err(Error::Compute(format!("{n} validation checks failed"))),
    }
}
