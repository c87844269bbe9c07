//! `lambert viewfactors SCENE --points points.csv`: factors from points (sensors) to every
//! surface, or every patch with `--patches` ([`lambert::viewfactor::points`]).
//!
//! The factors are exact (Lambert's formula with the pair methods' exact shadow clipping), so
//! what would change them is refused before any work (exit 2): a method other than `auto` or
//! `analytic` (nothing to sample or rasterise), `--samples` and `--resolution` (their knobs),
//! `--enforce` (a point's row has no reciprocal entry to enforce against) and `--vtk` (there is
//! no field on the patches). `--tolerance` is checked and met by any exact factor; `--seed`
//! changes nothing (nothing is random). Closed scenes get the row-sum check on stderr.
use super::args::ViewfactorsArgs;
use super::config::Config;
use lambert::report::outputs::{Input, OutputSet};
use lambert::report::points_csv;
use lambert::scene;
use lambert::viewfactor::{points, Level, MethodSet};
use lambert::{Error, Result};
use std::path::Path;

/// Runs `viewfactors --points`.
pub fn run(a: &ViewfactorsArgs, file: &Path) -> Result<()> {
    let cfg = Config::from_args(&a.common)?;
    refuse(a, &cfg)?;
    let mut outs = OutputSet::plan(vec![cfg.output.clone().described("point view-factor CSV")])?;
    outs.check_inputs(&[Input::new("the scene file", &cfg.scene), Input::new("the points file", file)])?;
    let pts = points_csv::read_points(file)?;
    let scene = lambert::plan::load(&cfg.scene, &cfg.load, &mut lambert::plan::Silent)?;
    let loaded: Vec<Input> = scene
        .inputs
        .iter()
        .map(|p| Input::new(format!("a file that the scene {} loads", cfg.scene.display()), p))
        .collect();
    outs.check_inputs(&loaded)?;
    for w in &scene.warnings {
        super::say::warning(format_args!("lambert: warning: {w}"));
    }
    let level = if cfg.patches { Level::Patch } else { Level::Surface };
    lambert::viewfactor::progress::enter(lambert::plan::Phase::ViewFactors);
    let pf = points::compute(&scene, &pts.points, level, cfg.params.progress);
    let geometry = scene::fingerprint::geometry(&scene);
    let open = !scene.is_closed();
    lambert::viewfactor::progress::enter(lambert::plan::Phase::Write);
    outs.write("output", |w, p| points_csv::write_point_factors(w, &pf, &pts.names, open, &geometry, p))?;
    outs.commit()?;
    let used = pf.rows.iter().flatten().fold(MethodSet::default(), |m, e| m.union(e.method));
    super::say::note(format_args!(
        "lambert: {} points, {} patches, {} pairs, {:.3} s, exact point factors (entries by {})",
        pts.points.len(),
        scene.patches.len(),
        pf.pairs,
        pf.wall.as_secs_f64(),
        used.to_string().replace('+', ", ")
    ));
    if scene.is_closed() && !scene.patches.is_empty() {
        let closure = pf.closure();
        super::say::note(format_args!("lambert: {}", closure.summary(&pts.names)));
        if let Some(w) = closure.warning(&pts.names, !scene.obstructions.is_empty()) {
            super::say::warning(format_args!("lambert: warning: {w}"));
        }
    }
    Ok(())
}

/// The options `--points` cannot honour, refused with the reason.
fn refuse(a: &ViewfactorsArgs, cfg: &Config) -> Result<()> {
    let c = &a.common;
    let why = if !cfg.params.method.exact_shadows() {
        format!(
            "-m {}: point factors are exact (Lambert's formula with exact shadows); use -m auto or analytic",
            cfg.params.method
        )
    } else if c.samples.is_some() || c.resolution.is_some() {
        let flag = if c.samples.is_some() { "--samples" } else { "--resolution" };
        format!("{flag} does not apply: point factors are exact, nothing is sampled or rasterised")
    } else if let Some(e) = &c.enforce {
        format!(
            "--enforce {e}: a point's row has no reciprocal entry to enforce against (its factors are exact)"
        )
    } else if c.vtk.is_some() {
        "--vtk: point factors are rows per point, not a field on the patches; write them with -o".to_string()
    } else {
        return Ok(());
    };
    Err(Error::Usage(format!("--points: {why}")))
}
