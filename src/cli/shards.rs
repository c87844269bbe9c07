//! `viewfactors --shard I/K` and `lambert merge`: argument checks, the replayed command, the
//! part output and the merge's balance note. The rows and the part format live in
//! [`lambert::viewfactor::shard`].
//!
//! A shard is a `viewfactors` run only: `solve` has no `--shard`. Enforcement, the per-surface
//! sums and the outputs run at the merge, on every row (a merged CSV feeds
//! `solve --viewfactors`). `--vtk` and stdout are refused for a shard: a part is a file for the
//! merge, not a result.
use super::args::{Cli, Command, CommonArgs, MergeArgs, ViewfactorsArgs};
use super::say;
use clap::{Parser, ValueEnum};
use lambert::report::outputs::OutputSet;
use lambert::scene::Scene;
use lambert::viewfactor::shard::{self, Part};
use lambert::{Error, Result};
use std::path::PathBuf;

/// Most shards of one run: far beyond any useful split, and small enough that a typo such as
/// `0/30000000` is caught before a kernel is built.
pub const MAX_SHARDS: usize = 1 << 20;

/// Parses and checks `--shard I/K` against the other options: (I, K).
pub fn shard_arg(text: &str, a: &CommonArgs) -> Result<(usize, usize)> {
    let usage = |why: &str| Error::Usage(format!("--shard {text}: {why}"));
    let (i, k) = text.split_once('/').ok_or_else(|| usage("give I/K, shard I (0 to K-1) of K"))?;
    let (Ok(i), Ok(k)) = (i.trim().parse::<usize>(), k.trim().parse::<usize>()) else {
        return Err(usage("give I/K with whole numbers, shard I (0 to K-1) of K"));
    };
    if k == 0 || k > MAX_SHARDS {
        return Err(usage(&format!("K must be 1 to {MAX_SHARDS}")));
    }
    if i >= k {
        return Err(usage(&format!("shards are numbered 0 to {} (as MPI ranks are)", k - 1)));
    }
    if a.output.as_deref().is_none_or(|p| p.as_os_str() == "-") {
        return Err(usage("a part goes to a file: give -o FILE (then `lambert merge` joins the parts)"));
    }
    if a.vtk.is_some() {
        return Err(usage("a shard writes a part only; --vtk is not written by shards"));
    }
    if lambert::distributed::rank_size().1 > 1 {
        return Err(usage("shards are for runs without MPI; under mpirun the ranks split the rows"));
    }
    Ok((i, k))
}

/// The `viewfactors` arguments that rebuild this run (scene path made absolute; threads, the
/// outputs and the shard left out).
pub fn replay(a: &CommonArgs, scene: &Scene) -> Vec<String> {
    let path = std::fs::canonicalize(&scene.source).unwrap_or_else(|_| scene.source.clone());
    let mut v = vec![path.to_string_lossy().into_owned()];
    let name = |e: &dyn Fn() -> Option<clap::builder::PossibleValue>| {
        e().map(|p| p.get_name().to_string()).unwrap_or_default()
    };
    if let Some(u) = a.mesh.unit {
        v.extend(["--unit".into(), name(&|| u.to_possible_value())]);
    }
    if a.mesh.repair {
        v.push("--repair".into());
    }
    v.extend(["--method".into(), name(&|| a.method.to_possible_value())]);
    if let Some(s) = a.samples {
        v.extend(["--samples".into(), s.to_string()]);
    }
    if let Some(r) = a.resolution {
        v.extend(["--resolution".into(), r.to_string()]);
    }
    if let Some(t) = a.tolerance {
        v.extend(["--tolerance".into(), t.to_string()]);
    }
    v.extend(["--seed".into(), a.seed.to_string()]);
    if let Some(e) = a.enforce {
        v.extend(["--enforce".into(), name(&|| e.to_possible_value())]);
    }
    if a.patches {
        v.push("--patches".into());
    }
    if a.allow_outside_paths {
        v.push("--allow-outside-paths".into());
    }
    v
}

/// Writes `part` through the run's planned outputs (temporary, then rename).
pub fn write_part(mut outs: OutputSet, part: &Part) -> Result<()> {
    let bytes = shard::to_bytes(part);
    outs.write("output", |w, p| {
        w.write_all(&bytes).map_err(|e| Error::Io { path: p.to_path_buf(), source: e })
    })?;
    outs.commit()?;
    let rows = part.rows();
    let pairs: u64 = part.share.rows.iter().map(|r| r.pairs).sum();
    say::note(format_args!(
        "lambert: shard {}/{}: rows {}..{} of {}, {pairs} pairs, {:.3} s; join the parts with lambert merge",
        part.index, part.count, rows.start, rows.end, part.n, part.share.seconds
    ));
    Ok(())
}

/// Reads and checks the parts of `a`, and builds the `viewfactors` arguments of their run.
pub fn merge_args(a: &MergeArgs) -> Result<(ViewfactorsArgs, Vec<(PathBuf, Part)>)> {
    if lambert::distributed::rank_size().1 > 1 {
        return Err(Error::Usage("lambert merge runs without MPI (it computes no rows)".into()));
    }
    let parts = a.parts.iter().map(|p| Ok((p.clone(), shard::read(p)?))).collect::<Result<Vec<_>>>()?;
    let parts = shard::check_parts(parts)?;
    let (first, part) = (&parts[0].0, &parts[0].1);
    let mut argv: Vec<std::ffi::OsString> = vec!["lambert".into(), "viewfactors".into()];
    let mut replay: Vec<std::ffi::OsString> = part.replay.iter().map(Into::into).collect();
    if replay.is_empty() {
        return Err(Error::Input(lambert::error::InputError::file(first, "the part records no command")));
    }
    if let Some(s) = &a.scene {
        replay[0] = s.clone().into();
    }
    argv.extend(replay);
    if let Some(o) = &a.output {
        argv.extend(["-o".into(), o.clone().into()]);
    }
    if let Some(t) = a.threads {
        argv.extend(["--threads".into(), t.to_string().into()]);
    }
    let bad = |why: String| {
        Error::Input(lambert::error::InputError::file(
            first,
            format!("its command cannot be run again: {why}"),
        ))
    };
    match Cli::try_parse_from(argv) {
        Ok(Cli { command: Command::Viewfactors(v), .. }) => Ok((v, parts)),
        Ok(_) => Err(bad("not a viewfactors command".into())),
        Err(e) => Err(bad(e.to_string().lines().next().unwrap_or_default().to_string())),
    }
}

/// The shards' compute seconds and their balance (max / mean), on stderr.
pub fn say_balance(parts: &[(PathBuf, Part)]) {
    let secs: Vec<f64> = parts.iter().map(|(_, p)| p.share.seconds).collect();
    let mean = secs.iter().sum::<f64>() / secs.len().max(1) as f64;
    let max = secs.iter().copied().fold(0.0, f64::max);
    let list: Vec<String> = secs.iter().map(|s| format!("{s:.3}")).collect();
    say::note(format_args!(
        "lambert: merging {} parts; shard compute seconds {} (max/mean {:.2})",
        parts.len(),
        list.join(" / "),
        if mean > 0.0 { max / mean } else { 1.0 }
    ));
}
