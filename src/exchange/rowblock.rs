//! The dense exchange store of the `solve` route under MPI: every rank keeps its own row block
//! of the packed triangle (`crate::viewfactor::row_block`), and the one enforcement
//! (`super::enforce`), the anchoring check, the CG solve and the error propagation run on it
//! through the ordinary [`super::operator::Operator`] of [`DenseExchange`], whose hooks sum
//! through the store's own methods, collectives in a fixed order:
//!
//! - the mat-vec: each rank's row blocks' partial products, added in block order along the
//!   ranks (`PackedTriangular::matvec_scaled`); x and y are replicated O(N) vectors, so every
//!   rank runs the same CG and gets bit-identical numbers, the same as one process;
//! - max |s̄| and the negative count (`PackedTriangular::max_abs_and_negatives`);
//! - the coupled groups for the anchoring check (`super::ranks::couplings`: each rank's group labels,
//!   all-gathered), and the leaking rows named in a refusal (`super::ranks::merge_leak_rows`);
//! - [`check_fits`]: the memory refusal rule per rank (each rank's block against its own
//!   available memory, agreed across the ranks: a refusal ends every rank with one message),
//!   on the estimated split first, then on the final (measured) split before the block is
//!   allocated;
//! - [`build`] (view factors into the block), [`total_bytes`] and [`report`] (per-rank rows,
//!   store bytes and bytes sent, printed by rank 0 under `LAMBERT_MPI_STATS`).
//!
//! Without MPI (or on one rank, or with a kernel that is not symmetric, whose rows are
//! gathered to rank 0) every function here is the single-process one.
use super::dense::{self, DenseExchange, DENSE_PEAK_FACTOR};
use super::memory::{self, Available, Bound};
use crate::distributed::reduce;
use crate::error::InputError;
use crate::scene::Scene;
use crate::viewfactor::packed::PackedTriangular;
use crate::viewfactor::row_block::{self, RowSplit};
use crate::Result;
use std::hash::Hasher;

/// Computes the patch-level lean store of `scene` for the `solve` route (after the memory
/// check): under MPI each rank keeps its row block, its final share checked again once the
/// measured split is known; `None` when the method needs the sparse store (Monte Carlo).
pub fn build(scene: &Scene, params: &crate::viewfactor::Params) -> Result<Option<DenseExchange>> {
    if params.method.is_monte_carlo() {
        return Ok(None);
    }
    check_fits(scene, 8.0, params.method.is_symmetric())?;
    let check = |split: &RowSplit| check_share(scene, 8.0, split);
    let Some(t) = crate::viewfactor::compute_triangle_with(scene, params, Some(&check))? else {
        return Ok(None);
    };
    let names = (0..scene.patches.len()).map(|p| scene.patch_name(p)).collect();
    Ok(Some(DenseExchange::new(t, names)))
}

/// The bounds of [`memory::available`] in the order they travel between ranks.
const BOUNDS: [Bound; 5] = [Bound::Override, Bound::Free, Bound::AddressSpace, Bound::Data, Bound::Cgroup];

/// [`dense::check_fits`] for the store of the `solve` route: under MPI with a `symmetric`
/// kernel each rank checks its own row block under the estimated split (`bytes_per_pair` ×
/// its pairs, plus headroom) against its own available memory, and the ranks agree: when one
/// does not fit, every rank returns the same error (exit code 2) naming it. Otherwise the
/// single-process check. This early check (the route's choice, before any row) is repeated on
/// the final, measured split before the block is allocated ([`build`]).
pub fn check_fits(scene: &Scene, bytes_per_pair: f64, symmetric: bool) -> Result<()> {
    let (n, source) = (scene.patches.len(), scene.source.as_path());
    if row_block::keeps_rows(n, symmetric).is_none() {
        return dense::check_fits(n, bytes_per_pair, source);
    }
    crate::distributed::agree_store(
        conditions_hash(scene, bytes_per_pair),
        "patch count, surface conditions and dense store",
    );
    check_share(scene, bytes_per_pair, &RowSplit::estimated(n, crate::distributed::rank_size().1))
}

/// The per-rank check of [`check_fits`] on the split `split` (every rank calling): each
/// rank's rows (`bytes_per_pair` × its pairs, plus headroom) and the probe rows it holds in
/// passing, against its own available memory.
fn check_share(scene: &Scene, bytes_per_pair: f64, split: &RowSplit) -> Result<()> {
    let (n, source) = (scene.patches.len(), scene.source.as_path());
    let rank = crate::distributed::rank_size().0;
    let pairs_of = |r: usize| split.held[r].clone().map(|i| (n - i) as f64).sum::<f64>();
    let need = pairs_of(rank) * bytes_per_pair * DENSE_PEAK_FACTOR + split.transit[rank] as f64;
    let avail = memory::available();
    let mut mine = Vec::with_capacity(17);
    mine.extend_from_slice(&need.to_bits().to_le_bytes());
    mine.extend_from_slice(&avail.map_or(u64::MAX, |a| a.bytes).to_le_bytes());
    mine.push(avail.map_or(0, |a| BOUNDS.iter().position(|&b| b == a.bound).unwrap_or(0) as u8));
    let all = reduce::all_gather_bytes(&mine);
    let size = all.len();
    for (r, b) in all.iter().enumerate() {
        let word = |o: usize| u64::from_le_bytes(b[o..o + 8].try_into().expect("17 bytes a rank"));
        let (need, bytes) = (f64::from_bits(word(0)), word(8));
        let avail = Available { bytes, bound: BOUNDS[usize::from(b[16]).min(BOUNDS.len() - 1)] };
        if need <= avail.bytes as f64 {
            continue;
        }
        let rows = &split.held[r];
        let passing = match split.transit[r] {
            0 => String::new(),
            t => format!(", plus {:.3} MB of probe rows in passing", t as f64 / 1e6),
        };
        return Err(InputError::file(
            source,
            format!(
                "{n} patches need about {:.1} GB per MPI rank for the dense exchange matrix shared by {size} \
                 ranks (rank {r} holds rows {}..{}: {:.0} pairs × {bytes_per_pair} bytes{passing}) but only \
                 {:.1} GB is available to rank {r} ({}); run on more ranks, or use `{} hierarchical`, or \
                 coarser `subdivide`",
                need / 1e9,
                rows.start,
                rows.end,
                pairs_of(r),
                avail.bytes as f64 / 1e9,
                avail.bound,
                crate::error::opt("exchange"),
            ),
        )
        .into());
    }
    Ok(())
}

/// Hash of what the ranks of a distributed solve must share besides the geometry (checked
/// when the view factors start): the patch count, each surface's emissivity and condition,
/// the ambient, and the store's bytes per pair. Ranks whose conditions differed would mix
/// their right-hand sides in one CG.
fn conditions_hash(scene: &Scene, bytes_per_pair: f64) -> u64 {
    let mut h = fnv::FnvHasher::default();
    h.write_u64(scene.patches.len() as u64);
    h.write_u64(bytes_per_pair.to_bits());
    for s in &scene.surfaces {
        h.write_u64(s.emissivity.to_bits());
        h.write(format!("{:?}", s.condition).as_bytes());
    }
    h.write(format!("{:?}", scene.ambient.map(|a| a.temperature.to_bits())).as_bytes());
    h.finish()
}

/// Bytes of the whole store: every rank's block summed (a collective when distributed).
pub fn total_bytes(t: &PackedTriangular) -> usize {
    if !t.distributed {
        return t.bytes();
    }
    reduce::all_gather_u64(t.bytes() as u64).iter().sum::<u64>() as usize
}

/// Under MPI with [`crate::distributed::STATS_VAR`] set and a distributed store: rank 0 prints
/// each rank's rows, store bytes and the bytes it sent (a collective: every rank calls it).
pub fn report(t: &PackedTriangular) {
    use crate::distributed::STATS_VAR;
    if !t.distributed || std::env::var_os(STATS_VAR).is_none() {
        return;
    }
    let mut mine = Vec::with_capacity(32);
    for v in [t.held.start as u64, t.held.end as u64, t.bytes() as u64, reduce::bytes_sent()] {
        mine.extend_from_slice(&v.to_le_bytes());
    }
    let all = reduce::all_gather_bytes(&mine);
    if crate::distributed::writes_outputs() {
        for (r, b) in all.iter().enumerate() {
            let word =
                |k: usize| u64::from_le_bytes(b[8 * k..8 * k + 8].try_into().expect("32 bytes a rank"));
            eprintln!(
                "lambert: mpi: dense rank {r} holds rows {}..{} of {}, {} store bytes, sent {} bytes",
                word(0),
                word(1),
                t.n,
                word(2),
                word(3)
            );
        }
    }
}
