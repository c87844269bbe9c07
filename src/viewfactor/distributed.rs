//! View-factor rows split between MPI ranks (see [`crate::distributed`]).
//!
//! Every rank has built the same kernel on the same scene. [`rows`] checks that (a hash of the
//! geometry, method, options and route, compared across ranks), splits the emitter rows into
//! contiguous blocks balanced by the pairs each row evaluates, computes this rank's block
//! with rayon, and gathers the blocks to rank 0 in row order. Rank 0 then runs the ordinary
//! engine or packed fill over a [`Gathered`] kernel that hands back those rows, so its outputs
//! are byte-identical to a run without MPI (Monte Carlo streams are keyed by row, never by
//! rank). The other ranks leave after sending. The flags and goal misses each rank's kernel
//! recorded travel with the rows and are merged into rank 0's kernel. The dense `solve`
//! route with a symmetric kernel does not gather: each rank keeps its rows
//! ([`super::row_block`]).
//!
//! The wire format ([`encode`], [`decode`]) is little-endian and private to one run (and to
//! the part files of [`super::shard`], which carry their format version).
use super::flags::Flag;
use super::row::{RawEntry, Row, RowKernel};
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

/// Computes rows `block` of `kernel` with rayon, cut at the first failure; `done(i)` hears of
/// each row computed.
pub(super) fn compute_block(
    kernel: &dyn RowKernel,
    block: std::ops::Range<usize>,
    done: &(dyn Fn(usize) + Sync),
) -> Share {
    use rayon::prelude::*;
    let start = std::time::Instant::now();
    let first = block.start;
    let outs: Vec<Result<Row>> = block
        .into_par_iter()
        .with_max_len(1)
        .map(|i| {
            let mut row = Row::default();
            let out = kernel.row(i, &mut row).map(|_| row);
            done(i);
            out
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

/// One MPI rank's rows, any set of them: row indices `at` (increasing within each wave), the
/// rows, the first failure, each row's CPU seconds (local only), the kernel's flags and misses,
/// and the rank's wall seconds (all rows, and the probe wave).
#[cfg_attr(not(feature = "mpi"), allow(dead_code))]
#[derive(Debug, Default)]
struct Listed {
    at: Vec<usize>,
    rows: Vec<Row>,
    times: Vec<f64>,
    failure: Option<(usize, Error)>,
    flags: Vec<Flag>,
    misses: (u64, Option<Miss>),
    seconds: f64,
    probe_seconds: f64,
}

#[cfg_attr(not(feature = "mpi"), allow(dead_code))]
impl Listed {
    /// Appends a later wave; of two failures the one in the earlier row is kept (the one a
    /// run without MPI reports).
    fn append(&mut self, mut other: Listed) {
        self.at.append(&mut other.at);
        self.rows.append(&mut other.rows);
        self.times.append(&mut other.times);
        if other.failure.as_ref().is_some_and(|o| self.failure.as_ref().is_none_or(|f| o.0 < f.0)) {
            self.failure = other.failure;
        }
    }

    /// The wire form: indices, timings, then the rows as a [`Share`].
    fn encode(self) -> Vec<u8> {
        let mut b = Vec::new();
        put_u64(&mut b, self.at.len() as u64);
        self.at.iter().for_each(|&i| put_u64(&mut b, i as u64));
        put_f64(&mut b, self.probe_seconds);
        let share = Share {
            first: 0,
            rows: self.rows,
            failure: self.failure,
            flags: self.flags,
            misses: self.misses,
            seconds: self.seconds,
        };
        b.extend_from_slice(&encode(&share));
        b
    }

    /// Reads [`Listed::encode`]'s bytes; `None` when damaged.
    fn decode(bytes: &[u8]) -> Option<Listed> {
        let mut r = Reader(bytes);
        let count = usize::try_from(r.u64()?).ok()?;
        let mut at = Vec::with_capacity(count.min(bytes.len()));
        for _ in 0..count {
            at.push(usize::try_from(r.u64()?).ok()?);
        }
        let probe_seconds = r.f64()?;
        let s = decode(r.0)?;
        if s.rows.len() != at.len() {
            return None;
        }
        Some(Listed {
            at,
            rows: s.rows,
            times: Vec::new(),
            failure: s.failure,
            flags: s.flags,
            misses: s.misses,
            seconds: s.seconds,
            probe_seconds,
        })
    }
}

/// CPU seconds of the calling thread: a row's cost without the time other processes took
/// the core from it (wall time on a loaded machine measures the neighbours, not the row).
#[cfg_attr(not(feature = "mpi"), allow(dead_code))]
pub(super) fn thread_cpu_seconds() -> f64 {
    let mut t = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: clock_gettime writes one timespec that we own; the clock id is a constant.
    let ok = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut t) } == 0;
    if ok {
        t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9
    } else {
        0.0
    }
}

/// Computes rows `rows` (increasing) of `kernel` with rayon, timing each (thread CPU
/// seconds), cut at the first failure.
#[cfg_attr(not(feature = "mpi"), allow(dead_code))]
fn compute_rows(kernel: &dyn RowKernel, rows: &[usize]) -> Listed {
    use rayon::prelude::*;
    let outs: Vec<(Result<Row>, f64)> = rows
        .par_iter()
        .with_max_len(1)
        .map(|&i| {
            let start = thread_cpu_seconds();
            let mut row = Row::default();
            let out = kernel.row(i, &mut row).map(|_| row);
            (out, thread_cpu_seconds() - start)
        })
        .collect();
    let mut l = Listed::default();
    for (&i, (o, t)) in rows.iter().zip(outs) {
        match o {
            Ok(r) => {
                l.at.push(i);
                l.rows.push(r);
                l.times.push(t);
            }
            Err(e) => {
                l.failure = Some((i, e));
                break;
            }
        }
    }
    l
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
    #[cfg(feature = "mpi")]
    {
        use crate::distributed::{comm, partition};
        if !comm::active() {
            return Ok(None);
        }
        let hash = agreement_hash(scene, options, kernel.symmetric(), kernel.tree_hash());
        comm::check_rows(hash, "scene geometry, acceleration trees, method and options");
        let (rank, size) = comm::rank_size();
        let n = scene.patches.len();
        let est = row_costs(n, kernel.symmetric());
        let measured = partition::measured();
        let start = std::time::Instant::now();
        let mut mine = if measured {
            // Estimated first: the probe wave, timed row by row, its timings shared.
            let probe = compute_rows(kernel, &partition::probe_rows(n, size, rank));
            let probe_seconds = start.elapsed().as_secs_f64();
            let mut b = Vec::new();
            for (i, t) in probe.at.iter().zip(&probe.times) {
                put_u64(&mut b, *i as u64);
                put_f64(&mut b, *t);
            }
            let mut probes: Vec<(usize, f64)> = Vec::new();
            for bytes in crate::distributed::reduce::all_gather_bytes(&b) {
                let mut r = Reader(&bytes);
                while let (Some(i), Some(t)) = (r.u64(), r.f64()) {
                    probes.push((i as usize, t));
                }
            }
            probes.sort_by_key(|p| p.0);
            // Then measured: the other rows split by the measured cost around them.
            let runs = partition::rebalanced(&est, &probes, size);
            let mut all = probe;
            all.append(compute_rows(kernel, &runs[rank]));
            all.probe_seconds = probe_seconds;
            all
        } else {
            compute_rows(kernel, &partition::balanced(&est, size)[rank].clone().collect::<Vec<_>>())
        };
        mine.seconds = start.elapsed().as_secs_f64();
        mine.flags = kernel.flags();
        mine.misses = kernel.misses();
        if rank != 0 {
            comm::gather_bytes(&mine.encode());
            comm::leave();
        }
        let parts = comm::gather_bytes(&[]).unwrap_or_default();
        comm::workers_left();
        let stats = std::env::var_os(crate::distributed::STATS_VAR).is_some();
        let mut shares = vec![(0, mine)];
        for (r, bytes) in parts.iter().enumerate().skip(1) {
            let listed = Listed::decode(bytes).ok_or_else(|| {
                Error::Compute(format!("the view-factor rows from MPI rank {r} arrived damaged"))
            })?;
            shares.push((bytes.len(), listed));
        }
        let mut slots: Vec<Option<Row>> = vec![None; n];
        let mut failure: Option<(usize, Error)> = None;
        let mut seconds = Vec::with_capacity(size);
        for (r, (sent, l)) in shares.into_iter().enumerate() {
            if stats {
                eprintln!(
                    "lambert: mpi: rank {r}: {} rows, {:.3} s ({:.3} s probing), {sent} bytes sent",
                    l.at.len(),
                    l.seconds,
                    l.probe_seconds
                );
            }
            seconds.push(l.seconds);
            if r != 0 {
                kernel.absorb(l.flags, l.misses);
            }
            for (i, row) in l.at.into_iter().zip(l.rows) {
                slots[i] = Some(row);
            }
            if let Some((i, e)) = l.failure {
                if failure.as_ref().is_none_or(|f| i < f.0) {
                    failure = Some((i, e));
                }
            }
        }
        if stats {
            let mean = seconds.iter().sum::<f64>() / size as f64;
            let max = seconds.iter().copied().fold(0.0, f64::max);
            let split = if measured { "measured" } else { "estimated" };
            eprintln!("lambert: mpi: {split} split, compute seconds max/mean {:.2}", max / mean.max(1e-12));
        }
        let rows: Vec<Row> = slots.into_iter().map_while(|r| r).collect();
        Ok(Some(Gathered::new(kernel, 0, rows, failure)))
    }
    #[cfg(not(feature = "mpi"))]
    {
        let _ = (scene, kernel, options);
        Ok(None)
    }
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
    fn a_listed_share_survives_the_wire_and_keeps_the_earliest_failure() {
        let s = share();
        let mut l =
            Listed { at: vec![3, 11, 19], rows: s.rows.clone(), probe_seconds: 0.25, ..Listed::default() };
        l.failure = Some((27, Error::Compute("late".into())));
        let later = Listed { failure: Some((20, Error::Compute("early".into()))), ..Listed::default() };
        l.append(later);
        let d = Listed::decode(&l.encode()).expect("decodes");
        assert_eq!(d.at, vec![3, 11, 19]);
        assert_eq!(d.rows, s.rows);
        assert_eq!(d.probe_seconds, 0.25);
        let (row, e) = d.failure.expect("a failure");
        assert_eq!((row, e.to_string()), (20, "early".to_string()));
        let bytes = Listed { at: vec![1], ..Listed::default() }.encode();
        assert!(Listed::decode(&bytes).is_none(), "an index without its row is refused");
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
