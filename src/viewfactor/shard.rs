//! Shards: one run's view-factor rows split between independent processes (any batch
//! scheduler, no MPI), and joined again into the file a single run writes, byte for byte.
//!
//! - `lambert viewfactors SCENE --shard i/K -o part_i` computes the rows of block i of the same
//!   cost-balanced partition an MPI run of K ranks uses ([`crate::distributed::partition`]),
//!   as raw kernel rows (upper triangle of symmetric kernels, per-row Monte Carlo streams), and
//!   writes them in a [`Part`] file;
//! - `lambert merge part_* -o full.csv` checks the parts ([`check_parts`]), replays the shards'
//!   `viewfactors` command with the rows of the parts in place of the kernel's, so enforcement,
//!   aggregation and output are those of a single run.
//!
//! The hook is `rows`, called where an MPI run splits its rows: in [`capture`] mode it
//! computes this shard's block, keeps the [`Part`] for [`captured`] and stops the run with an
//! error the caller recognises by the captured part; in [`supply`] mode it hands back every
//! part's rows after checking that this run has the parts' hash. The mode is process-wide
//! (the CLI sets it once); no mode, no effect.
//!
//! Part file: a text header (what a person needs: shard, rows, hash, the command), a blank
//! line, then a little-endian payload whose length and FNV-1a checksum the header states, so
//! a truncated or damaged part is refused before its rows are read.
use super::distributed::{self as wire, Gathered, Reader, Share};
use super::progress::{self, Progress};
use super::row::RowKernel;
use crate::distributed::partition;
use crate::error::InputError;
use crate::scene::Scene;
use crate::{Error, Result};
use std::hash::Hasher;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// First line of every part file.
pub const MAGIC: &str = "lambert view-factor part";
/// Version of the part layout; a merge refuses any other.
pub const FORMAT: u64 = 1;

/// One shard's rows and what identifies the run they belong to.
#[derive(Debug)]
pub struct Part {
    /// Shard index, 0-based (the MPI rank of the same rows).
    pub index: usize,
    /// Shards in the run.
    pub count: usize,
    /// Patches (rows) of the whole run.
    pub n: usize,
    /// True when the kernel computes the upper triangle only (it fixes the partition).
    pub symmetric: bool,
    /// Agreement hash: scene geometry, method, options, route and acceleration trees.
    pub hash: u64,
    /// The `viewfactors` arguments (scene first) that rebuild the run; `lambert merge` replays them.
    pub replay: Vec<String>,
    /// The rows.
    pub share: Share,
}

impl Part {
    /// Rows this part holds.
    pub fn rows(&self) -> Range<usize> {
        self.share.first..self.share.first + self.share.rows.len()
    }
}

/// The rows of a split run, for the engine and the packed store: a shard run's (`--shard`,
/// `merge`: this module's hook), else the MPI ranks' (`super::distributed::rows`); `None`:
/// compute every row as usual.
pub fn split_rows<'k>(
    scene: &Scene,
    kernel: &'k dyn RowKernel,
    options: &str,
) -> Result<Option<Gathered<'k>>> {
    if let Some(g) = rows(scene, kernel, options)? {
        return Ok(Some(g));
    }
    wire::rows(scene, kernel, options)
}

/// What the process-wide hook does.
enum Mode {
    /// Compute shard `index` of `count`, keep it, stop the run.
    Capture { index: usize, count: usize, replay: Vec<String> },
    /// The shard's part, once computed.
    Captured(Box<Part>),
    /// Hand back the rows of these parts (checked, in shard order).
    Supply(Vec<(PathBuf, Part)>),
}

static MODE: Mutex<Option<Mode>> = Mutex::new(None);

fn mode() -> std::sync::MutexGuard<'static, Option<Mode>> {
    MODE.lock().unwrap_or_else(|e| e.into_inner())
}

/// Makes the next view-factor run of this process compute shard `index` of `count` only,
/// recording `replay` (the `viewfactors` arguments) in its part; the run then stops with an
/// error and [`captured`] returns the part.
pub fn capture(index: usize, count: usize, replay: Vec<String>) {
    *mode() = Some(Mode::Capture { index, count, replay });
}

/// The part a [`capture`] run computed (taken once).
pub fn captured() -> Option<Part> {
    let mut m = mode();
    match m.take() {
        Some(Mode::Captured(p)) => Some(*p),
        other => {
            *m = other;
            None
        }
    }
}

/// Makes the next view-factor run of this process take its rows from `parts` (checked with
/// [`check_parts`] first) instead of computing them.
pub fn supply(parts: Vec<(PathBuf, Part)>) {
    *mode() = Some(Mode::Supply(parts));
}

/// True when parts given to [`supply`] are still waiting for a run (a run that computed its
/// rows without them must not write a merged file).
pub fn supply_pending() -> bool {
    matches!(*mode(), Some(Mode::Supply(_)))
}

/// The shard hook (see the module docs): `None` when no shard mode is set.
pub(super) fn rows<'k>(
    scene: &Scene,
    kernel: &'k dyn RowKernel,
    options: &str,
) -> Result<Option<Gathered<'k>>> {
    let mut m = mode();
    match m.take() {
        None => Ok(None),
        Some(Mode::Capture { index, count, replay }) => {
            let n = scene.patches.len();
            let symmetric = kernel.symmetric();
            let block = partition::balanced(&wire::row_costs(n, symmetric), count)[index].clone();
            drop(m);
            // The shard's own pairs are what its progress counts (the run's display shows it),
            // weighed by the kernel's estimated cost of each row when it has one and a display
            // draws them (`--quiet` skips the estimate).
            let pairs = |i: usize| if symmetric { (n - i) as u64 } else { n as u64 };
            let costs = super::row::row_costs(kernel, progress::displayed(), n, pairs);
            let progress = Progress::start_costed(
                block.clone().map(pairs).sum(),
                "pairs",
                progress::Mode::Off,
                costs[block.clone()].iter().sum(),
            );
            let mut share = wire::compute_block(kernel, block, &|i| progress.add_costed(pairs(i), costs[i]));
            progress.finish();
            if let Some((_, e)) = share.failure.take() {
                return Err(e);
            }
            let hash = wire::agreement_hash(scene, options, symmetric, kernel.tree_hash());
            let part = Part { index, count, n, symmetric, hash, replay, share };
            *mode() = Some(Mode::Captured(Box::new(part)));
            Err(Error::Compute(format!("the run stopped after the rows of shard {index}/{count}")))
        }
        Some(Mode::Supply(parts)) => {
            drop(m);
            let hash = wire::agreement_hash(scene, options, kernel.symmetric(), kernel.tree_hash());
            let n = scene.patches.len();
            let (path, first) = (&parts[0].0, &parts[0].1);
            if first.hash != hash || first.n != n || first.symmetric != kernel.symmetric() {
                return Err(Error::Input(InputError::file(
                    path,
                    format!(
                        "its rows were computed on another scene geometry, method or options than \
                         this merge's scene {} gives (part hash {:016x}, {} patches; this run {hash:016x}, \
                         {n} patches): merge the parts with the scene file they were computed from",
                        scene.source.display(),
                        first.hash,
                        first.n
                    ),
                )));
            }
            let mut rows = Vec::with_capacity(n);
            for (_, p) in parts {
                kernel.absorb(p.share.flags, p.share.misses);
                rows.extend(p.share.rows);
            }
            Ok(Some(Gathered::new(kernel, 0, rows, None)))
        }
        Some(other) => {
            *m = Some(other);
            Ok(None)
        }
    }
}

/// FNV-1a 64 of `bytes` (the payload checksum).
fn checksum(bytes: &[u8]) -> u64 {
    let mut h = fnv::FnvHasher::default();
    h.write(bytes);
    h.finish()
}

/// The bytes of a part file.
pub fn to_bytes(p: &Part) -> Vec<u8> {
    let mut payload = Vec::new();
    wire::put_u64(&mut payload, FORMAT);
    wire::put_u64(&mut payload, p.index as u64);
    wire::put_u64(&mut payload, p.count as u64);
    wire::put_u64(&mut payload, p.n as u64);
    wire::put_u8(&mut payload, u8::from(p.symmetric));
    wire::put_u64(&mut payload, p.hash);
    wire::put_u64(&mut payload, p.replay.len() as u64);
    for a in &p.replay {
        wire::put_str(&mut payload, a);
    }
    payload.extend_from_slice(&wire::encode(&p.share));
    let rows = p.rows();
    // One line per field; the command is for people (a newline in an argument would break
    // the header's lines, so control characters are shown escaped there).
    let command: Vec<String> = p.replay.iter().map(|a| a.escape_debug().to_string()).collect();
    let header = format!(
        "{MAGIC}\nformat: {FORMAT}\nshard: {}/{}\nrows: {}..{} of {}\nhash: {:016x}\n\
         command: lambert viewfactors {}\npayload: {} bytes, fnv {:016x}\n\n",
        p.index,
        p.count,
        rows.start,
        rows.end,
        p.n,
        p.hash,
        command.join(" "),
        payload.len(),
        checksum(&payload)
    );
    let mut out = header.into_bytes();
    out.extend_from_slice(&payload);
    out
}

/// Reads a part file, refusing (exit 2, naming the file) anything that is not a whole part.
pub fn read(path: &Path) -> Result<Part> {
    let bytes = std::fs::read(path).map_err(|e| Error::Io { path: path.to_path_buf(), source: e })?;
    from_bytes(&bytes).map_err(|problem| Error::Input(InputError::file(path, problem)))
}

/// Parses the bytes of a part file; the error says what is wrong.
pub fn from_bytes(bytes: &[u8]) -> std::result::Result<Part, String> {
    let not_part =
        || format!("not a lambert view-factor part (the file a {} run writes)", crate::error::opt("shard"));
    if !bytes.starts_with(MAGIC.as_bytes()) {
        return Err(not_part());
    }
    let end = bytes.windows(2).position(|w| w == b"\n\n").ok_or_else(not_part)?;
    let header = std::str::from_utf8(&bytes[..end]).map_err(|_| not_part())?;
    let payload = &bytes[end + 2..];
    let line = header.lines().find_map(|l| l.strip_prefix("payload: ")).ok_or_else(not_part)?;
    let (len, sum) = line.split_once(" bytes, fnv ").ok_or_else(not_part)?;
    let len: usize = len.parse().map_err(|_| not_part())?;
    let sum = u64::from_str_radix(sum, 16).map_err(|_| not_part())?;
    if payload.len() < len {
        return Err(format!(
            "the part is truncated: {} of its {len} payload bytes are there (was its copy or its \
             shard's run cut short?)",
            payload.len()
        ));
    }
    if payload.len() > len || checksum(payload) != sum {
        return Err("the part is damaged: its payload does not match the checksum in its header".into());
    }
    let damaged = || "the part is damaged: its payload cannot be read".to_string();
    let mut r = Reader(payload);
    let format = r.u64().ok_or_else(damaged)?;
    if format != FORMAT {
        return Err(format!("part format {format}; this lambert reads format {FORMAT}"));
    }
    let mut int = || r.u64().and_then(|v| usize::try_from(v).ok()).ok_or_else(damaged);
    let (index, count, n) = (int()?, int()?, int()?);
    let symmetric = r.u8().ok_or_else(damaged)? != 0;
    let hash = r.u64().ok_or_else(damaged)?;
    let args = r.u64().ok_or_else(damaged)?;
    let mut replay = Vec::new();
    for _ in 0..args {
        replay.push(r.string().ok_or_else(damaged)?);
    }
    let share = wire::decode(r.0).ok_or_else(damaged)?;
    if count == 0 || index >= count || share.first + share.rows.len() > n {
        return Err(damaged());
    }
    Ok(Part { index, count, n, symmetric, hash, replay, share })
}

/// Checks that `parts` are the whole of one run: the same scene, method and options (hash and
/// command), each shard of the same count exactly once, each holding its block of the
/// partition. Returns them in shard order; errors name the files.
pub fn check_parts(mut parts: Vec<(PathBuf, Part)>) -> Result<Vec<(PathBuf, Part)>> {
    let bad = |path: &Path, problem: String| Error::Input(InputError::file(path, problem));
    let Some((p0, first)) = parts.first() else {
        return Err(Error::Usage(format!(
            "no part files given: a merge needs every part of one {} run",
            crate::error::opt("shard")
        )));
    };
    let (p0, count, hash, n) = (p0.clone(), first.count, first.hash, first.n);
    let replay = first.replay.clone();
    for (path, p) in &parts[1..] {
        if p.count != count {
            return Err(bad(
                path,
                format!(
                    "it is shard {}/{} but {} is shard {}/{count}: the parts of one run share K",
                    p.index,
                    p.count,
                    p0.display(),
                    first.index
                ),
            ));
        }
        if p.hash != hash || p.n != n || p.replay != replay {
            return Err(bad(
                path,
                format!(
                    "it was computed on another scene or with other options than {} (hash {:016x} against \
                     {hash:016x}; command `{}` against `{}`): the parts of one run share scene and options",
                    p0.display(),
                    p.hash,
                    p.replay.join(" "),
                    replay.join(" ")
                ),
            ));
        }
    }
    parts.sort_by_key(|(_, p)| p.index);
    for w in parts.windows(2) {
        if w[0].1.index == w[1].1.index {
            return Err(bad(
                &w[1].0,
                format!(
                    "it is shard {}/{count}, as is {}: each shard is given once",
                    w[1].1.index,
                    w[0].0.display()
                ),
            ));
        }
    }
    let have: Vec<usize> = parts.iter().map(|(_, p)| p.index).collect();
    let missing: Vec<String> =
        (0..count).filter(|i| !have.contains(i)).map(|i| format!("{i}/{count}")).collect();
    if !missing.is_empty() {
        return Err(bad(
            &p0,
            format!(
                "its run has {count} shards and shard(s) {} are missing: give every part of the run",
                missing.join(", ")
            ),
        ));
    }
    let blocks = partition::balanced(&wire::row_costs(n, parts[0].1.symmetric), count);
    for (path, p) in &parts {
        let want = &blocks[p.index];
        if p.rows() != *want {
            return Err(bad(
                path,
                format!(
                    "it holds rows {}..{} but shard {}/{count} of {n} rows is rows {}..{}: the parts \
                     overlap or leave a gap",
                    p.rows().start,
                    p.rows().end,
                    p.index,
                    want.start,
                    want.end
                ),
            ));
        }
    }
    Ok(parts)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::viewfactor::row::{RawEntry, Row};
    use crate::viewfactor::MethodSet;

    fn part(index: usize, count: usize, n: usize) -> Part {
        let block = partition::balanced(&wire::row_costs(n, true), count)[index].clone();
        let rows = block
            .clone()
            .map(|i| Row {
                entries: vec![RawEntry {
                    j: i as u32,
                    method: MethodSet::ANALYTIC,
                    s: 0.1 * i as f64,
                    var: 0.0,
                }],
                shared_samples: 0,
                pairs: (n - i) as u64,
            })
            .collect();
        let share =
            Share { first: block.start, rows, failure: None, flags: vec![], misses: (0, None), seconds: 0.5 };
        Part {
            index,
            count,
            n,
            symmetric: true,
            hash: 42,
            replay: vec!["a b.toml".into(), "--patches".into()],
            share,
        }
    }

    fn named(parts: Vec<Part>) -> Vec<(PathBuf, Part)> {
        parts.into_iter().map(|p| (PathBuf::from(format!("part_{}", p.index)), p)).collect()
    }

    #[test]
    fn a_part_survives_its_file_bit_for_bit() {
        let p = part(1, 3, 20);
        let q = from_bytes(&to_bytes(&p)).expect("reads back");
        assert_eq!((q.index, q.count, q.n, q.symmetric, q.hash), (1, 3, 20, true, 42));
        assert_eq!(q.replay, p.replay);
        assert_eq!(q.share.rows, p.share.rows);
        assert_eq!(q.rows(), p.rows());
    }

    #[test]
    fn truncated_damaged_and_foreign_files_are_refused() {
        let bytes = to_bytes(&part(0, 2, 10));
        let cut = from_bytes(&bytes[..bytes.len() - 3]).unwrap_err();
        assert!(cut.contains("truncated"), "{cut}");
        let mut flipped = bytes.clone();
        let last = flipped.len() - 1;
        flipped[last] ^= 1;
        assert!(from_bytes(&flipped).unwrap_err().contains("damaged"));
        let foreign =
            Error::Input(InputError::file("t.csv", from_bytes(b"from,to,factor\na,b,0.5\n").unwrap_err()));
        assert_eq!(
            foreign.to_string(),
            "t.csv: not a lambert view-factor part (the file a shard run writes)"
        );
        let flag = |k: &str| format!("--{k}");
        assert!(foreign.spelled(&flag).ends_with("(the file a --shard run writes)"), "{foreign}");
    }

    #[test]
    fn check_parts_sorts_a_whole_run_and_refuses_the_rest() {
        let ok = check_parts(named(vec![part(2, 3, 30), part(0, 3, 30), part(1, 3, 30)])).expect("whole");
        assert_eq!(ok.iter().map(|(_, p)| p.index).collect::<Vec<_>>(), vec![0, 1, 2]);
        let err = |parts: Vec<Part>| check_parts(named(parts)).unwrap_err().to_string();
        assert!(err(vec![part(0, 3, 30), part(2, 3, 30)]).contains("1/3 are missing"));
        assert_eq!(err(vec![]), "no part files given: a merge needs every part of one shard run");
        assert!(
            err(vec![part(0, 2, 30), part(0, 2, 30), part(1, 2, 30)]).contains("each shard is given once")
        );
        assert!(err(vec![part(0, 2, 30), part(1, 3, 30)]).contains("share K"));
        let mut other = part(1, 2, 30);
        other.hash = 7;
        assert!(err(vec![part(0, 2, 30), other]).contains("another scene or with other options"));
        let mut shifted = part(1, 2, 30);
        shifted.share.first -= 1;
        assert!(err(vec![part(0, 2, 30), shifted]).contains("overlap or leave a gap"));
    }
}
