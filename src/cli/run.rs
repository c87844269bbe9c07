//! Orchestration of the subcommands: load → compute → report. No physics here.
use super::args::{Command, MergeArgs, RenderArgs, SolveArgs, ValidateArgs, ViewfactorsArgs};
use super::config::Config;
use super::limits;
use super::say;
use lambert::exchange::{self, Enforce};
use lambert::plan::{
    with_unstamped_note, Goal, Matrix, Outcome, Phase, Plan, PlanError, Progress, Reason, Request, Route,
    Tolerance, HIERARCHICAL_MIN_PATCHES,
};
use lambert::report;
use lambert::report::decks::{DeckFormat, DeckInfo};
use lambert::report::outputs::{Input, Output, OutputSet};
use lambert::report::vtk::VtkKind;
use lambert::report::writers::{write_all, Deck, Png, Results, Table, Vtk, Writer};
use lambert::scene::{self, Scene};
use lambert::solve;
use lambert::viewfactor::progress::{self, Display};
use lambert::viewfactor::{self, Level, Method, MethodSet, ViewFactors};
use lambert::{Error, Result};
use std::path::Path;

/// Runs one subcommand.
pub fn run(cmd: Command) -> Result<()> {
    match cmd {
        Command::Viewfactors(a) => {
            let _shown = display();
            viewfactors(a)
        }
        Command::Merge(a) => {
            let _shown = display();
            merge(a)
        }
        Command::Solve(a) => {
            let _shown = display();
            solve(a)
        }
        Command::Validate(a) => validate(a),
        Command::Render(a) => render(a),
    }
}

/// The progress display of a `viewfactors` or `solve` run on stderr (nothing under `-q`): the
/// library's phases and counts, drawn until it is dropped.
fn display() -> Display {
    Display::start(progress::Mode::for_stderr(!say::quiet()))
}

/// The writing phase starts.
fn writing() {
    progress::enter(Phase::Write);
}

/// Plans the outputs of `viewfactors` / `solve` (`-o`, `--vtk`, `--conductances`) and checks
/// them against the scene file and `inputs` before any work.
fn plan_outputs(
    cfg: &Config,
    what: &str,
    vtk: Option<&Path>,
    conductances: Option<&Path>,
    inputs: &[Input],
) -> Result<OutputSet> {
    let mut outs = vec![cfg.output.clone().described(what)];
    if let Some(p) = vtk {
        outs.push(Output::new("vtk", "--vtk", "VTK results", p));
    }
    if let Some(p) = conductances {
        outs.push(Output::new("conductances", "--conductances", "conductance deck", p));
    }
    let set = OutputSet::plan(outs)?;
    let mut all = vec![Input::new("the scene file", &cfg.scene)];
    all.extend_from_slice(inputs);
    set.check_inputs(&all)?;
    Ok(set)
}

/// The files `scene` was read from, as inputs no output may overwrite.
fn scene_inputs(scene: &Scene) -> Vec<Input> {
    let loaded = format!("a file that the scene {} loads", scene.source.display());
    let what = |p: &Path| if p == scene.source { "the scene file".to_string() } else { loaded.clone() };
    scene.inputs.iter().map(|p| Input::new(what(p), p)).collect()
}

fn viewfactors(a: ViewfactorsArgs) -> Result<()> {
    viewfactors_with(a, &[])
}

/// `viewfactors`, with `inputs` (the parts of a merge) that no output may overwrite.
fn viewfactors_with(a: ViewfactorsArgs, inputs: &[Input]) -> Result<()> {
    if let Some(points) = &a.points {
        if a.shard.is_some() {
            return Err(Error::Usage(
                "--shard splits view-factor rows; it does not apply to --points".into(),
            ));
        }
        return super::points::run(&a, points);
    }
    let cfg = Config::from_args(&a.common)?;
    let shard = a.shard.as_deref().map(|s| super::shards::shard_arg(s, &a.common)).transpose()?;
    let vtk = check_vtk(&a.common.vtk)?;
    let what = if shard.is_some() { "view-factor part" } else { "view-factor CSV" };
    let mut outs = plan_outputs(&cfg, what, a.common.vtk.as_deref(), None, inputs)?;
    let scene = lambert::plan::load(&cfg.scene, &cfg.load, &mut lambert::plan::Silent)?;
    outs.check_inputs(&scene_inputs(&scene))?;
    for w in &scene.warnings {
        say::warning(format_args!("lambert: warning: {w}"));
    }
    warn_facing_away(&scene);
    let level = if cfg.patches { Level::Patch } else { Level::Surface };
    let request = Request { goal: Goal::ViewFactors { level }, ..request(&cfg)? };
    let plan = Plan::new(&scene, &request)?;
    for note in &plan.scene_notes {
        say::note(format_args!("lambert: {note}"));
    }
    let cheaper =
        "a coarser mesh cuts it, or a Monte Carlo method (-m mc-cosine: cost in patches × --samples)";
    if let Some(w) = limits::mesh_cost(&scene, cfg.params.method, rayon::current_num_threads(), cheaper) {
        say::warning(format_args!("lambert: warning: {w}"));
    }
    if let Some((index, count)) = shard {
        let replay = super::shards::replay(&a.common, &scene);
        lambert::viewfactor::shard::capture(index, count, replay);
    }
    let out = plan.view_factors(&scene, &mut Sink { scene: &scene });
    if shard.is_some() {
        // The shard hook stops the run once its rows are computed; a run that went on (or
        // failed before) wrote no part.
        return match (lambert::viewfactor::shard::captured(), out) {
            (Some(part), _) => super::shards::write_part(outs, &part),
            (None, Err(e)) => Err(e),
            (None, Ok(_)) => Err(Error::Compute("the shard's rows were not computed apart".into())),
        };
    }
    let out = out?;
    if lambert::viewfactor::shard::supply_pending() {
        return Err(Error::Compute("the merge did not use the parts' rows".into()));
    }
    let d = &out.diagnostics;
    say_warnings(&d.leak_warnings);
    if let Some(rep) = &d.enforcement {
        print_enforcement(plan.enforce, rep);
    }
    let method = match (&out.matrix, out.route) {
        (Matrix::Rows(vf), Route::Sparse) => method_summary(cfg.params.method, vf),
        _ => cfg.params.method.to_string(),
    };
    let store = match out.route {
        Route::Packed => format!(", dense store {:.1} MB", d.store_bytes as f64 / 1e6),
        _ => String::new(),
    };
    let (pairs, secs) = (d.pairs, d.viewfactor_wall.as_secs_f64());
    let worst = out.worst_row.clone();
    writing();
    let results = Results::ViewFactors { scene: &scene, outcome: &out };
    write_results(&mut outs, vtk, &results)?;
    outs.commit()?;
    say::note(format_args!(
        "lambert: {} patches, {pairs} pairs, {secs:.3} s ({:.3e} pairs/s), method {method}{store}",
        scene.patches.len(),
        pairs as f64 / secs.max(1e-9),
    ));
    if let Some((worst, name, level)) = worst {
        let kind = if level == Level::Patch { "patch" } else { "surface" };
        say::note(format_args!("lambert: closed scene, max |row sum - 1| = {worst:.3e} ({kind} {name})"));
    }
    Ok(())
}

/// `lambert merge`: the parts are read and checked, then the shards' `viewfactors` command
/// runs again with their rows in place of the kernel's (enforcement and output as a single run).
fn merge(a: MergeArgs) -> Result<()> {
    let (args, parts) = super::shards::merge_args(&a)?;
    let inputs: Vec<Input> =
        parts.iter().map(|(p, _)| Input::new("a part file given to lambert merge", p)).collect();
    super::shards::say_balance(&parts);
    lambert::viewfactor::shard::supply(parts);
    viewfactors_with(args, &inputs)
}

/// The plan request of the options shared by `viewfactors` and `solve`.
fn request(cfg: &Config) -> Result<Request> {
    Ok(Request {
        method: cfg.params.method,
        samples: cfg.params.samples,
        resolution: cfg.params.resolution,
        tolerance: cfg.tolerance_given,
        seed: cfg.params.seed,
        enforce: cfg.enforce,
        progress_bar: cfg.params.progress,
        ..Request::default()
    })
}

/// Prints what the view-factor method reported about its own accuracy.
fn say_warnings(warnings: &[String]) {
    for w in warnings {
        say::warning(format_args!("lambert: warning: {w}"));
    }
}

/// A scene file's tolerance (View3D `eps`), held to the same floor as `--tolerance`.
fn scene_tolerance(scene: &Scene, t: f64) -> Result<f64> {
    limits::tolerance(t, &format!("{}: View3D eps", scene.source.display()))
}

/// The requested method and, when it chooses per pair (`auto`), what produced the entries:
/// the `method` column's values, so stderr and the rows agree.
fn method_summary(method: Method, vf: &ViewFactors) -> String {
    let used = vf.rows.iter().flatten().fold(MethodSet::default(), |m, e| m.union(e.method));
    if method == Method::Auto && !used.is_empty() {
        format!("auto (entries by {})", used.to_string().replace('+', ", "))
    } else {
        method.to_string()
    }
}

/// SPEC extension: a panel of an open scene that faces away from every surface it could see.
fn warn_facing_away(scene: &Scene) {
    for f in scene::hints::facing_away(scene) {
        say::warning(format_args!("lambert: warning: {}", scene::hints::facing_away_warning(scene, &f)));
    }
}

/// The residuals before and after enforcement, on stderr.
fn print_enforcement(mode: Enforce, rep: &exchange::enforce::EnforceReport) {
    say::note(format_args!("lambert: exchange before enforcement: {}", rep.before));
    say::note(format_args!(
        "lambert: enforce {mode} ({}, {} iterations): {}",
        rep.method, rep.iterations, rep.after
    ));
}

/// A bad `--vtk` extension is refused before any work starts; the file type otherwise.
fn check_vtk(path: &Option<std::path::PathBuf>) -> Result<Option<report::vtk::VtkKind>> {
    path.as_deref().map(report::vtk::kind_of).transpose()
}

fn solve(a: SolveArgs) -> Result<()> {
    let cfg = Config::from_args(&a.common)?;
    let vtk = check_vtk(&a.common.vtk)?;
    let deck = match (a.format, &a.conductances) {
        (Some(f), Some(_)) => f,
        (Some(_), None) => {
            return Err(Error::Usage("--format applies to --conductances, which is not given".into()))
        }
        (None, Some(path)) => DeckFormat::from_path(path)?,
        (None, None) => DeckFormat::Csv,
    };
    let saved: Vec<Input> = a.viewfactors.iter().map(|p| Input::new("the --viewfactors input", p)).collect();
    let mut outs =
        plan_outputs(&cfg, "results CSV", a.common.vtk.as_deref(), a.conductances.as_deref(), &saved)?;
    let scene = lambert::plan::load(&cfg.scene, &cfg.load, &mut lambert::plan::Silent)?;
    outs.check_inputs(&scene_inputs(&scene))?;
    for w in &scene.warnings {
        say::warning(format_args!("lambert: warning: {w}"));
    }
    if let (None, Some(t)) = (cfg.tolerance_given, scene.run_defaults.tolerance) {
        scene_tolerance(&scene, t)?;
    }
    scene.check_boundary_conditions()?;
    warn_facing_away(&scene);
    if a.conductances.is_some() {
        // RADK comes from one dense solve over the patches: refuse before any work is done.
        solve::conductance::check_nodes(scene.patches.len())?;
        let level = if a.viewfactors.is_some() { Level::Surface } else { Level::Patch };
        solve::conductance::check_deck(&scene, level, cfg.patches)?;
    }
    let request = Request {
        store: a.exchange,
        solver: a.solver,
        saved_viewfactors: a.viewfactors.is_some(),
        conductances: a.conductances.is_some(),
        ..request(&cfg)?
    };
    let plan = Plan::new(&scene, &request).map_err(|e| match e {
        PlanError::ClusteredUnserved => Error::Usage(
            "--exchange hierarchical serves gray `solve` runs with -m auto or analytic and the direct \
             solver, without --viewfactors or --conductances"
                .into(),
        ),
        PlanError::Other(e) => e,
    })?;
    if a.viewfactors.is_none() {
        warn_mesh_cost(&scene, &cfg, &plan);
    }
    say_route(&plan);
    let mut sink = Sink { scene: &scene };
    if plan.route == Route::Clustered {
        let out = plan.run(&scene, &mut sink)?;
        say_clustered(&scene, &plan, &out);
        finish_solve(&scene, &cfg, out.solution, vtk, &mut outs)?;
        return outs.commit();
    }
    let (vf, stamped) = match &a.viewfactors {
        Some(path) => {
            let (vf, stamped) = report::read_vf::read_stamped(path, &scene)?;
            if a.conductances.is_some() {
                solve::conductance::check_deck(&scene, vf.level, cfg.patches)?;
            }
            if cfg.patches && vf.level == Level::Surface {
                return Err(Error::Usage(
                    "--patches needs patch-level view factors (a `viewfactors --patches` file)".into(),
                ));
            }
            (Some(vf), stamped)
        }
        None => (None, true),
    };
    let out = plan.run_with(&scene, vf.as_ref(), &mut sink).map_err(|e| match (&a.viewfactors, stamped) {
        (Some(file), false) => with_unstamped_note(e, file),
        _ => e,
    })?;
    let d = &out.diagnostics;
    if let Some(rep) = &d.enforcement {
        print_enforcement(plan.enforce, rep);
    }
    let Some(ex) = &out.exchange else {
        say::note(format_args!(
            "lambert: {} patches, {} pairs, dense store {:.1} MB",
            scene.patches.len(),
            d.pairs,
            d.store_bytes as f64 / 1e6
        ));
        finish_solve(&scene, &cfg, out.solution, vtk, &mut outs)?;
        return outs.commit();
    };
    // The deck is written (as a temporary) before the results, so that a deck that cannot be
    // written stops the run before anything reaches stdout.
    if a.conductances.is_some() {
        let c = solve::conductance::radk(&scene, ex, &plan.solve)?;
        let c = if cfg.patches || ex.level == Level::Surface {
            c
        } else {
            let mut group: Vec<usize> = scene.patches.iter().map(|p| p.surface).collect();
            let mut names: Vec<String> = scene.surfaces.iter().map(|s| s.name.clone()).collect();
            if c.names.len() > group.len() {
                group.push(names.len());
                names.push(solve::AMBIENT.to_string());
            }
            c.aggregate(&group, names)
        };
        let info = DeckInfo { scene: cfg.scene.display().to_string(), title: scene.title.clone() };
        writing();
        write_all(&mut outs, &[&Deck(deck)], &Results::Conductances { matrix: &c, info: &info })?;
    }
    finish_solve(&scene, &cfg, out.solution, vtk, &mut outs)?;
    outs.commit()
}

/// The plan's progress sink: prints the method's warnings and flags as they arrive.
struct Sink<'a> {
    scene: &'a Scene,
}

impl Progress for Sink<'_> {
    fn phase(&mut self, _: Phase) {}
    fn method_report(&mut self, warnings: &[String], flags: &[viewfactor::Flag]) {
        say_warnings(warnings);
        say_warnings(&lambert::plan::flag_warnings(self.scene, flags));
    }
}

/// Says the route a `solve` takes when `--exchange auto` chose it, or when it is clustered.
fn say_route(plan: &Plan) {
    let why = match plan.reason {
        Reason::Small { .. } | Reason::Tight { .. } => {
            say::note(format_args!(
                "lambert: exchange: dense ({}; --exchange hierarchical for clustered links)",
                plan.reason
            ));
            return;
        }
        Reason::NoExactKernel { .. } => {
            say::note(format_args!("lambert: exchange: dense ({})", plan.reason));
            return;
        }
        Reason::Asked if plan.route == Route::Clustered => "forced by --exchange hierarchical".to_string(),
        Reason::Large { .. } => format!("{}; --exchange dense for every pair", plan.reason),
        Reason::NoMemory { .. } => plan.reason.to_string(),
        _ => return,
    };
    if let Tolerance::HeatRate { rate, .. } = plan.tolerance {
        say::note(format_args!("lambert: exchange: hierarchical, heat-rate tolerance {rate:e} ({why})"));
    }
}

/// The clustered route's enforcement, build statistics and heat-rate error bound.
fn say_clustered(scene: &Scene, plan: &Plan, out: &Outcome) {
    let d = &out.diagnostics;
    if let Some(rep) = &d.enforcement {
        print_enforcement(plan.enforce, rep);
    }
    let Some((s, first)) = &d.clustered else { return };
    if let Some((loose, s)) = first {
        say::note(format_args!(
            "lambert: first pass at tolerance {loose:e} for the radiosity ranges: {} cluster links, {} patch \
             pairs (links {:.2} s, patch pairs {:.2} s)",
            s.links,
            s.leaf_pairs,
            s.refine.as_secs_f64(),
            s.pairs.as_secs_f64()
        ));
    }
    say::note(format_args!(
        "lambert: {} patches, {} cluster links, {} patch pairs, {} visibility rays, store {:.1} MB \
         (links {:.2} s, patch pairs {:.2} s)",
        scene.patches.len(),
        s.links,
        s.leaf_pairs,
        s.rays,
        s.bytes as f64 / 1e6,
        s.refine.as_secs_f64(),
        s.pairs.as_secs_f64()
    ));
    if out.solution.heat_rate_error.is_some() {
        let by_surface = out.solution.by_surface(scene);
        let (_, max) = by_surface.heat_balance();
        let worst =
            by_surface.heat_rate_error.as_ref().map_or(0.0, |e| e.iter().copied().fold(0.0, f64::max));
        say::note(format_args!(
            "lambert: estimated heat-rate error: at most {worst:.3e} W on a surface ({:.1e} of max |heat_rate|)",
            if max > 0.0 { worst / max } else { 0.0 }
        ));
    }
}

/// The cost warning of [`limits::mesh_cost`] for a `solve` that integrates every patch pair
/// (the clustered route is what large meshes are for).
fn warn_mesh_cost(scene: &Scene, cfg: &Config, plan: &Plan) {
    // Pairwise routes that `--exchange auto` chose for a scene it would not cluster are quiet.
    match (plan.route, plan.reason) {
        (Route::Clustered, _) => return,
        (Route::Packed, r) if r != Reason::Asked => return,
        _ => {}
    }
    let cheaper = if plan.route == Route::Packed {
        format!(
            "`--exchange hierarchical` (the default above {HIERARCHICAL_MIN_PATCHES} patches) clusters them"
        )
    } else {
        "a coarser mesh cuts it; the clustered path (`--exchange hierarchical`) serves gray runs with -m auto \
         or analytic and the direct solver, without --viewfactors or --conductances"
            .to_string()
    };
    if let Some(w) = limits::mesh_cost(scene, cfg.params.method, rayon::current_num_threads(), &cheaper) {
        say::warning(format_args!("lambert: warning: {w}"));
    }
}
/// Prints the solve summary and energy balance and writes the VTK file (when asked) and the
/// results table into `outs` (committed by the caller).
fn finish_solve(
    scene: &Scene,
    cfg: &Config,
    sol: solve::Solution,
    vtk: Option<report::vtk::VtkKind>,
    outs: &mut OutputSet,
) -> Result<()> {
    let info = &sol.info;
    say::note(format_args!(
        "lambert: solve: {} unknowns, {}, {} iterations, residual {:.2e}, {:.3} s",
        info.unknowns,
        info.solver,
        info.iterations,
        info.residual,
        info.wall.as_secs_f64()
    ));
    writing();
    let out = if cfg.patches { sol } else { sol.by_surface(scene) };
    let (sum, max) = out.heat_balance();
    let scale = out.balance_scale();
    let ok = sum.abs() <= solve::BALANCE_TOL * scale;
    // A balance that is not conserved is a warning (it shows under -q too).
    let balance = if ok { say::note } else { say::warning };
    balance(format_args!(
        "lambert: energy balance: sum of heat_rate = {} W ({:.1e} of the {} W exchanged; max |heat_rate| = {max} W){}",
        report::fmt_f64(sum),
        if scale > 0.0 { sum.abs() / scale } else { 0.0 },
        report::fmt_f64(scale),
        if ok { "" } else { " -- WARNING: not conserved; enforce closure for closed scenes" }
    ));
    write_results(outs, vtk, &Results::Solution { scene, solution: &out })
}

/// Writes a `viewfactors` or `solve` run's results: the VTK mesh when asked, then the CSV
/// table.
fn write_results(outs: &mut OutputSet, vtk: Option<VtkKind>, results: &Results) -> Result<()> {
    let vtk = vtk.map(Vtk);
    let mut writers: Vec<&dyn Writer> = vtk.iter().map(|v| v as &dyn Writer).collect();
    writers.push(&Table);
    write_all(outs, &writers, results)
}

/// `validate --quick` writes here unless `--out` is given (never over the committed report).
const QUICK_SCRATCH: &str = "lambert-validate-quick";

fn validate(a: ValidateArgs) -> Result<()> {
    let out = match (a.out, a.quick) {
        (Some(out), _) => out,
        (None, false) => "validation".into(),
        (None, true) => std::env::temp_dir().join(QUICK_SCRATCH),
    };
    let options = lambert::validate::Options { cases: a.cases, out, quick: a.quick };
    lambert::validate::check_options(&options)?;
    let suite = lambert::validate::run(&options, &mut |line| say::note(format_args!("validate: {line}")))?;
    print!("{}", lambert::validate::report::console(&suite.checks));
    say::note(format_args!("validate: report written to {}", options.out.join("report.md").display()));
    match suite.failures() {
        0 => Ok(()),
        n => Err(Error::Compute(format!("{n} validation checks failed"))),
    }
}

fn render(a: RenderArgs) -> Result<()> {
    use report::render::{self, camera::Camera, values};
    let unit = a.field.unit();
    if !a.output.extension().is_some_and(|e| e.eq_ignore_ascii_case("png")) {
        return Err(Error::Usage(format!(
            "-o {}: the picture is written as PNG; name it .png",
            a.output.display()
        )));
    }
    let size = parse_size(&a.size)?;
    let range = a.range.as_deref().map(parse_range).transpose()?;
    let mut outs = OutputSet::plan(vec![Output::new("output", "-o", "PNG picture", &a.output)])?;
    outs.check_inputs(&[Input::new("the scene file", &a.scene), Input::new("the result CSV", &a.result)])?;
    let scene = scene::load_with(
        &a.scene,
        &scene::LoadOptions {
            allow_outside_paths: a.allow_outside_paths,
            bare: super::config::mesh_options(&a.mesh)?,
        },
    )?;
    outs.check_inputs(&scene_inputs(&scene))?;
    let camera = match &a.camera {
        Some(spec) => Camera::frame(&scene).with_spec(spec)?,
        None => Camera::frame(&scene),
    };
    let v = values::read(&a.result, &scene, a.field)?;
    let title = scene.title.clone().unwrap_or_else(|| a.scene.display().to_string());
    let caption = format!("{} per {}: {title}", a.field, if v.per_patch { "patch" } else { "surface" });
    let opts = render::Options {
        size,
        camera,
        two_sided: a.two_sided,
        range,
        field: a.field.to_string(),
        unit: unit.to_string(),
        caption,
        flat: a.flat,
        fit: !a.camera.as_deref().is_some_and(|c| c.contains("fov=")),
    };
    let img = render::render(&scene, &v.values, &opts)?;
    write_all(&mut outs, &[&Png], &Results::Picture(&img))?;
    outs.commit()?;
    let c = &opts.camera;
    say::note(format_args!(
        "lambert: render: {} patches, {}x{} px, colour range {}..{}, camera eye={},{},{} target={},{},{} up={},{},{} fov={}",
        scene.patches.len(),
        size.0,
        size.1,
        img.range.0,
        img.range.1,
        c.eye.x,
        c.eye.y,
        c.eye.z,
        c.target.x,
        c.target.y,
        c.target.z,
        c.up.x,
        c.up.y,
        c.up.z,
        c.fov
    ));
    Ok(())
}

/// `WIDTHxHEIGHT`.
fn parse_size(s: &str) -> Result<(u32, u32)> {
    let bad = || Error::Usage(format!("--size '{s}': expected WIDTHxHEIGHT, e.g. 1000x720"));
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    Ok((w.trim().parse().map_err(|_| bad())?, h.trim().parse().map_err(|_| bad())?))
}

/// `MIN,MAX` with MIN < MAX, both finite.
fn parse_range(s: &str) -> Result<(f64, f64)> {
    let bad = || Error::Usage(format!("--range '{s}': expected MIN,MAX with MIN < MAX"));
    let (lo, hi) = s.split_once(',').ok_or_else(bad)?;
    let (lo, hi): (f64, f64) = (lo.trim().parse().map_err(|_| bad())?, hi.trim().parse().map_err(|_| bad())?);
    if lo.is_finite() && hi.is_finite() && lo < hi {
        Ok((lo, hi))
    } else {
        Err(bad())
    }
}
