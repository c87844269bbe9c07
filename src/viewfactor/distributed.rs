//! View-factor rows split between MPI ranks (see [`crate::distributed`]).
//!
//! Every rank has built the same kernel on the same scene. [`rows`] checks that (a hash of the
//! geometry, method, options and route, compared across ranks), splits the emitter rows into
//! contiguous blocks balanced by the pairs each row evaluates, computes this rank's block
//! with rayon, and gathers the blocks to rank 0 in row order. Rank 0 then runs the ordinary
//! engine or packed fill over a [`Gathered`] kernel that hands back those rows, so its outputs
//! are byte-identical to a run without MPI (Monte Carlo streams are keyed by row, never by
//! rank). The other ranks leave after sending. The flags and goal misses each rank's kernel
//! recorded travel with the rows and are merged into rank 0's kernel.
//!
//! The wire format ([`encode`], [`decode`]) is little-endian and private to one run (and to
//! the part files of [`super::shard`], which carry their format version).
use super::engine::{RawEntry, Row, RowKernel};
use super::flags::Flag;
use super::shadow::misses::Miss;
use super::MethodSet;
use crate::error::InputError;
use crate::scene::Scene;
use crate::{Error, Result};
use std::hash::Hasher;
use std::path::PathBuf;
use std::sync::Mutex;

/// One rank's share: its rows (cut at the first failed row), the failure, and its kernel's
/// flags and misses.
#[derive(Debug)]
pub struct Share {
    /// First row of the block.
    pub first: usize,
    /// Rows `first..first + rows.len()`, computed.
    pub rows: Vec<Row>,
    /// The row that failed (right after the last computed one) and why.
    pub failure: Option<(usize, Error)>,
    /// Flags the rank's kernel recorded.
    pub flags: Vec<Flag>,
    /// (count, worst) of the entries that missed their goal on the rank.
    pub misses: (u64, Option<Miss>),
    /// Seconds the rank spent computing its rows.
    pub seconds: f64,
}

/// A kernel that hands back rows computed elsewhere; warnings and flags come from the inner
/// kernel, into which every rank's flags and misses were merged.
pub struct Gathered<'k> {
    inner: &'k dyn RowKernel,
    first: usize,
    rows: Vec<Row>,
    failure: Mutex<Option<(usize, Error)>>,
}

impl<'k> Gathered<'k> {
    /// A kernel that hands back `rows` (rows `first..`), then `failure`, with `inner`'s
    /// warnings and flags.
    pub(super) fn new(
        inner: &'k dyn RowKernel,
        first: usize,
        rows: Vec<Row>,
        failure: Option<(usize, Error)>,
    ) -> Self {
        Self { inner, first, rows, failure: Mutex::new(failure) }
    }
}

impl RowKernel for Gathered<'_> {
    fn symmetric(&self) -> bool {
        self.inner.symmetric()
    }
    fn row(&self, i: usize, out: &mut Row) -> Result<()> {
        if let Some(r) = i.checked_sub(self.first).and_then(|k| self.rows.get(k)) {
            out.clone_from(r);
            return Ok(());
        }
        let mut failure = self.failure.lock().unwrap_or_else(|e| e.into_inner());
        match failure.take() {
            Some((row, e)) if row == i => Err(e),
            other => {
                *failure = other;
                Err(Error::Compute(format!("view-factor row {i} was not computed (an earlier row failed)")))
            }
        }
    }
    fn warnings(&self) -> Vec<String> {
        self.inner.warnings()
    }
    fn flags(&self) -> Vec<Flag> {
        self.inner.flags()
    }
}

/// Estimated cost of each row: the pairs it evaluates.
pub(super) fn row_costs(n: usize, symmetric: bool) -> Vec<f64> {
    (0..n).map(|i| if symmetric { (n - i) as f64 } else { n as f64 }).collect()
}

/// Computes rows `block` of `kernel` with rayon, cut at the first failure.
pub(super) fn compute_block(kernel: &dyn RowKernel, block: std::ops::Range<usize>) -> Share {
    use rayon::prelude::*;
    let start = std::time::Instant::now();
    let first = block.start;
    let outs: Vec<Result<Row>> = block
        .into_par_iter()
        .with_max_len(1)
        .map(|i| {
            let mut row = Row::default();
            kernel.row(i, &mut row).map(|_| row)
        })
        .collect();
    let mut rows = Vec::with_capacity(outs.len());
    let mut failure = None;
    for (k, o) in outs.into_iter().enumerate() {
        match o {
            Ok(r) => rows.push(r),
            Err(e) => {
                failure = Some((first + k, e));
                break;
            }
        }
    }
    Share {
        first,
        rows,
        failure,
        flags: kernel.flags(),
        misses: kernel.misses(),
        seconds: start.elapsed().as_secs_f64(),
    }
}

/// Hash of what every rank must agree on before its rows can be mixed with the others':
/// the geometry fingerprint, the number of patches, `options` (method and its settings, as
/// the caller writes them), whether the kernel is symmetric, and `tree`, the hash of the
/// acceleration trees the kernel built ([`RowKernel::tree_hash`]).
pub fn agreement_hash(scene: &Scene, options: &str, symmetric: bool, tree: u64) -> u64 {
    let mut h = fnv::FnvHasher::default();
    h.write(crate::scene::fingerprint::geometry(scene).as_bytes());
    h.write_u64(scene.patches.len() as u64);
    h.write(options.as_bytes());
    h.write_u8(u8::from(symmetric));
    h.write_u64(tree);
    h.finish()
}

/// Under `mpirun` with several ranks: splits `kernel`'s rows between the ranks and returns,
/// on rank 0, a kernel holding every row; the other ranks send their rows and exit with rank
/// 0's exit code. `None` (compute as usual) without MPI or on one rank. `options` names the
/// method, its settings and the route, for the agreement hash.
pub fn rows<'k>(scene: &Scene, kernel: &'k dyn RowKernel, options: &str) -> Result<Option<Gathered<'k>>> {
    // A shard run (`--shard`, `merge`) takes its rows from the shard hook instead.
    if let Some(g) = super::shard::rows(scene, kernel, options)? {
        return Ok(Some(g));
    }
    #[cfg(feature = "mpi")]
    {
        use crate::distributed::{comm, partition};
        if !comm::active() {
            return Ok(None);
        }
        let hash = agreement_hash(scene, options, kernel.symmetric(), kernel.tree_hash());
        comm::check_rows(hash, "scene geometry, acceleration trees, method and options");
        let (rank, size) = comm::rank_size();
        let blocks = partition::balanced(&row_costs(scene.patches.len(), kernel.symmetric()), size);
        let mine = compute_block(kernel, blocks[rank].clone());
        if rank != 0 {
            let bytes = encode(&mine);
            comm::gather_bytes(&bytes);
            comm::leave();
        }
        let local_seconds = mine.seconds;
        let empty = Vec::new();
        let parts = comm::gather_bytes(&encode_empty()).unwrap_or(empty);
        comm::workers_left();
        let stats = std::env::var_os(crate::distributed::STATS_VAR).is_some();
        let mut all = mine;
        for (r, bytes) in parts.iter().enumerate().skip(1) {
            let share = decode(bytes).ok_or_else(|| {
                Error::Compute(format!("the view-factor rows from MPI rank {r} arrived damaged"))
            })?;
            if stats {
                eprintln!(
                    "lambert: mpi: rank {r}: rows {}..{}, {:.3} s, {} bytes sent",
                    share.first,
                    share.first + share.rows.len(),
                    share.seconds,
                    bytes.len()
                );
            }
            kernel.absorb(share.flags, share.misses);
            if all.failure.is_none() {
                all.failure = share.failure;
                if all.rows.len() == share.first - all.first {
                    all.rows.extend(share.rows);
                }
            }
        }
        if stats {
            eprintln!(
                "lambert: mpi: rank 0: rows {}..{}, {local_seconds:.3} s",
                blocks[0].start, blocks[0].end
            );
        }
        Ok(Some(Gathered {
            inner: kernel,
            first: all.first,
            rows: all.rows,
            failure: Mutex::new(all.failure),
        }))
    }
    #[cfg(not(feature = "mpi"))]
    {
        let _ = (scene, kernel, options);
        Ok(None)
    }
}

/// What rank 0 sends to its own gather: nothing.
#[cfg(feature = "mpi")]
fn encode_empty() -> Vec<u8> {
    Vec::new()
}

// ---- wire format ----

pub(super) fn put_u8(b: &mut Vec<u8>, v: u8) {
    b.push(v);
}
pub(super) fn put_u32(b: &mut Vec<u8>, v: u32) {
    b.extend_from_slice(&v.to_le_bytes());
}
pub(super) fn put_u64(b: &mut Vec<u8>, v: u64) {
    b.extend_from_slice(&v.to_le_bytes());
}
pub(super) fn put_f64(b: &mut Vec<u8>, v: f64) {
    b.extend_from_slice(&v.to_bits().to_le_bytes());
}
pub(super) fn put_str(b: &mut Vec<u8>, s: &str) {
    put_u64(b, s.len() as u64);
    b.extend_from_slice(s.as_bytes());
}

/// Serialises a share (bit-exact floats).
pub fn encode(s: &Share) -> Vec<u8> {
    let entries: usize = s.rows.iter().map(|r| r.entries.len()).sum();
    let mut b = Vec::with_capacity(64 + s.rows.len() * 16 + entries * 21);
    put_u64(&mut b, s.first as u64);
    put_u64(&mut b, s.rows.len() as u64);
    put_f64(&mut b, s.seconds);
    for r in &s.rows {
        put_u32(&mut b, r.shared_samples);
        put_u64(&mut b, r.pairs);
        put_u64(&mut b, r.entries.len() as u64);
        for e in &r.entries {
            put_u32(&mut b, e.j);
            put_u8(&mut b, e.method.bits());
            put_f64(&mut b, e.s);
            put_f64(&mut b, e.var);
        }
    }
    match &s.failure {
        None => put_u8(&mut b, 0),
        Some((row, e)) => {
            put_u8(&mut b, 1);
            put_u64(&mut b, *row as u64);
            encode_error(&mut b, e);
        }
    }
    put_u64(&mut b, s.flags.len() as u64);
    for f in &s.flags {
        put_u64(&mut b, f.from as u64);
        put_u64(&mut b, f.to as u64);
        put_u8(&mut b, f.method.bits());
        put_str(&mut b, &f.note);
    }
    put_u64(&mut b, s.misses.0);
    match s.misses.1 {
        None => put_u8(&mut b, 0),
        Some(m) => {
            put_u8(&mut b, 1);
            put_u64(&mut b, m.i as u64);
            put_u64(&mut b, m.j as u64);
            put_f64(&mut b, m.error);
            put_f64(&mut b, m.goal);
        }
    }
    b
}

fn encode_error(b: &mut Vec<u8>, e: &Error) {
    match e {
        Error::Input(i) => {
            put_u8(b, 0);
            put_str(b, &i.file.to_string_lossy());
            put_str(b, i.surface.as_deref().unwrap_or(""));
            put_u8(b, u8::from(i.surface.is_some()));
            put_u64(b, i.line.map_or(0, |l| l as u64 + 1));
            put_str(b, &i.problem);
        }
        Error::Usage(s) => {
            put_u8(b, 1);
            put_str(b, s);
        }
        Error::Unsupported(s) => {
            put_u8(b, 2);
            put_str(b, s);
        }
        Error::Compute(s) => {
            put_u8(b, 3);
            put_str(b, s);
        }
        Error::Io { path, source } => {
            put_u8(b, 4);
            put_str(b, &path.to_string_lossy());
            put_str(b, &source.to_string());
        }
    }
}

/// Reads what [`encode`] wrote; `None` when the bytes are damaged.
pub(super) struct Reader<'a>(pub(super) &'a [u8]);

impl Reader<'_> {
    pub(super) fn take(&mut self, n: usize) -> Option<&[u8]> {
        if self.0.len() < n {
            return None;
        }
        let (a, rest) = self.0.split_at(n);
        self.0 = rest;
        Some(a)
    }
    pub(super) fn u8(&mut self) -> Option<u8> {
        self.take(1).map(|a| a[0])
    }
    pub(super) fn u32(&mut self) -> Option<u32> {
        self.take(4).map(|a| u32::from_le_bytes(a.try_into().expect("4 bytes")))
    }
    pub(super) fn u64(&mut self) -> Option<u64> {
        self.take(8).map(|a| u64::from_le_bytes(a.try_into().expect("8 bytes")))
    }
    pub(super) fn f64(&mut self) -> Option<f64> {
        self.u64().map(f64::from_bits)
    }
    pub(super) fn string(&mut self) -> Option<String> {
        let n = usize::try_from(self.u64()?).ok()?;
        self.take(n).map(|a| String::from_utf8_lossy(a).into_owned())
    }
}

/// Deserialises a share; `None` when the bytes are damaged or truncated.
pub fn decode(bytes: &[u8]) -> Option<Share> {
    let mut r = Reader(bytes);
    let first = usize::try_from(r.u64()?).ok()?;
    let count = usize::try_from(r.u64()?).ok()?;
    let seconds = r.f64()?;
    let mut rows = Vec::with_capacity(count.min(bytes.len()));
    for _ in 0..count {
        let shared_samples = r.u32()?;
        let pairs = r.u64()?;
        let n = usize::try_from(r.u64()?).ok()?;
        let mut entries = Vec::with_capacity(n.min(bytes.len()));
        for _ in 0..n {
            entries.push(RawEntry { j: r.u32()?, method: MethodSet(r.u8()?), s: r.f64()?, var: r.f64()? });
        }
        rows.push(Row { entries, shared_samples, pairs });
    }
    let failure = match r.u8()? {
        0 => None,
        _ => Some((usize::try_from(r.u64()?).ok()?, decode_error(&mut r)?)),
    };
    let nf = usize::try_from(r.u64()?).ok()?;
    let mut flags = Vec::with_capacity(nf.min(bytes.len()));
    for _ in 0..nf {
        flags.push(Flag {
            from: usize::try_from(r.u64()?).ok()?,
            to: usize::try_from(r.u64()?).ok()?,
            method: MethodSet(r.u8()?),
            note: r.string()?,
        });
    }
    let count_missed = r.u64()?;
    let worst = match r.u8()? {
        0 => None,
        _ => Some(Miss {
            i: usize::try_from(r.u64()?).ok()?,
            j: usize::try_from(r.u64()?).ok()?,
            error: r.f64()?,
            goal: r.f64()?,
        }),
    };
    if !r.0.is_empty() {
        return None;
    }
    Some(Share { first, rows, failure, flags, misses: (count_missed, worst), seconds })
}

fn decode_error(r: &mut Reader<'_>) -> Option<Error> {
    Some(match r.u8()? {
        0 => {
            let file = PathBuf::from(r.string()?);
            let surface = r.string()?;
            let has_surface = r.u8()? != 0;
            let line = r.u64()?;
            let problem = r.string()?;
            Error::Input(InputError {
                file,
                surface: has_surface.then_some(surface),
                line: line.checked_sub(1).map(|l| l as usize),
                problem,
            })
        }
        1 => Error::Usage(r.string()?),
        2 => Error::Unsupported(r.string()?),
        3 => Error::Compute(r.string()?),
        4 => {
            let path = PathBuf::from(r.string()?);
            Error::Io { path, source: std::io::Error::other(r.string()?) }
        }
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn share() -> Share {
        let row = |i: u32| Row {
            entries: vec![
                RawEntry { j: i + 1, method: MethodSet::ANALYTIC, s: 0.1 + f64::from(i), var: 0.0 },
                RawEntry {
                    j: i + 2,
                    method: MethodSet::MC_AREA.union(MethodSet::SHADOWED),
                    s: 1e-300,
                    var: 3e-7,
                },
            ],
            shared_samples: 7 * i,
            pairs: u64::from(i) * 1_000_000_007,
        };
        Share {
            first: 5,
            rows: vec![row(5), row(6), Row::default()],
            failure: Some((8, Error::Input(InputError::surface("a b.toml", "wall", "broken").at_line(3)))),
            flags: vec![Flag { from: 5, to: 9, method: MethodSet::SINGLE_PLANE, note: "cut ∅".into() }],
            misses: (4, Some(Miss { i: 6, j: 7, error: 2.5e-9, goal: 1e-9 })),
            seconds: 1.25,
        }
    }

    #[test]
    fn a_share_survives_the_wire_bit_for_bit() {
        let s = share();
        let d = decode(&encode(&s)).expect("decodes");
        assert_eq!(d.first, s.first);
        assert_eq!(d.rows, s.rows);
        assert_eq!(d.flags, s.flags);
        assert_eq!(d.misses, s.misses);
        assert_eq!(d.seconds, s.seconds);
        let (row, e) = d.failure.expect("the failure travels");
        assert_eq!(row, 8);
        assert_eq!(e.to_string(), s.failure.unwrap().1.to_string());
        assert_eq!(e.exit_code(), 2);
    }

    #[test]
    fn damaged_bytes_are_refused_not_misread() {
        let bytes = encode(&share());
        for cut in [0, 1, 8, 30, bytes.len() - 1] {
            assert!(decode(&bytes[..cut]).is_none(), "a share cut at {cut} bytes decoded");
        }
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(decode(&longer).is_none());
    }

    #[test]
    fn the_gathered_kernel_returns_the_rows_and_then_the_failure_in_row_order() {
        struct Never;
        impl RowKernel for Never {
            fn symmetric(&self) -> bool {
                true
            }
            fn row(&self, _: usize, _: &mut Row) -> Result<()> {
                unreachable!("the gathered kernel never asks its inner kernel for rows")
            }
        }
        let s = share();
        let g =
            Gathered { inner: &Never, first: s.first, rows: s.rows.clone(), failure: Mutex::new(s.failure) };
        let mut out = Row::default();
        g.row(6, &mut out).unwrap();
        assert_eq!(out, s.rows[1]);
        let e = g.row(8, &mut out).unwrap_err();
        assert!(e.to_string().contains("broken"), "{e}");
        assert!(g.row(9, &mut out).unwrap_err().to_string().contains("row 9 was not computed"));
    }

    #[test]
    fn the_agreement_hash_changes_with_the_options() {
        let scene = crate::scene::Scene::default();
        let h = |o: &str, s: bool, t: u64| agreement_hash(&scene, o, s, t);
        assert_ne!(h("auto 1e-4", true, 0), h("auto 1e-3", true, 0));
        assert_ne!(h("auto", true, 0), h("auto", false, 0));
        assert_ne!(h("auto", true, 1), h("auto", true, 2), "the trees' hash takes part");
    }
}
