//! Runs under `mpirun` (cargo feature `mpi`): every rank loads the same scene, the view-factor
//! rows are split between the ranks, and rank 0 gathers them, runs the rest of the route and
//! writes the outputs. Without the feature (or outside `mpirun`) every function here is the
//! single-process answer, so callers need no `cfg`.
//!
//! - [`partition`]: contiguous row blocks balanced by an estimated cost per row;
//! - `comm` (feature `mpi`): the communicator: start-up, checked sync points (a tag and a hash
//!   of the geometry compared across ranks; a mismatch aborts the run), byte gathers, and the
//!   end of the run (every rank exits with rank 0's code);
//! - [`reduce`]: reductions in a fixed order (an ordered chain, all-gathers), bit-identical to
//!   one process, for the distributed link hierarchy.
//!
//! Rank 0 is the root: it prints, writes and decides the exit code. On the routes that gather
//! (`viewfactors`, the sparse store, kernels that fold rows) the other ranks send their rows
//! and leave (see `viewfactor::distributed`); on the dense `solve` route each rank keeps its
//! row block and runs the route to its end (`exchange::rowblock`), as on the hierarchical
//! route. The other ranks' stderr is silenced unless [`VERBOSE_VAR`] is set.
pub mod partition;
pub mod reduce;

#[cfg(feature = "mpi")]
pub mod comm;

/// Environment variable that keeps the stderr of ranks other than 0 (for debugging).
pub const VERBOSE_VAR: &str = "LAMBERT_MPI_VERBOSE";

/// Environment variable that makes rank 0 print the per-rank rows, time and bytes of the gather.
pub const STATS_VAR: &str = "LAMBERT_MPI_STATS";

/// (rank, size) of this process: (0, 1) without MPI.
pub fn rank_size() -> (usize, usize) {
    #[cfg(feature = "mpi")]
    {
        comm::rank_size()
    }
    #[cfg(not(feature = "mpi"))]
    {
        (0, 1)
    }
}

/// True on the rank that writes the outputs (always, without MPI).
pub fn writes_outputs() -> bool {
    rank_size().0 == 0
}

/// Starts MPI when the binary runs under `mpirun` with the feature on; nothing otherwise.
pub fn start() {
    #[cfg(feature = "mpi")]
    comm::start();
}

/// Under MPI with several ranks: every rank must arrive here, at the same step, with the same
/// `hash` (of what `what` names); ranks that differ end the run together with exit code 2
/// after rank 0 names them. Nothing without MPI.
pub fn agree(hash: u64, what: &str) {
    #[cfg(feature = "mpi")]
    if comm::active() {
        comm::check(comm::TAG_HIERARCHY, hash, what);
    }
    #[cfg(not(feature = "mpi"))]
    let _ = (hash, what);
}

/// As [`agree`], at the step where the ranks check that their blocks of the dense store fit.
pub fn agree_store(hash: u64, what: &str) {
    #[cfg(feature = "mpi")]
    if comm::active() {
        comm::check(comm::TAG_STORE, hash, what);
    }
    #[cfg(not(feature = "mpi"))]
    let _ = (hash, what);
}

/// Ends the run on every rank with rank 0's exit code (`code` on rank 0); returns `code`
/// unchanged without MPI.
pub fn finish(code: u8) -> u8 {
    #[cfg(feature = "mpi")]
    {
        comm::finish(code)
    }
    #[cfg(not(feature = "mpi"))]
    {
        code
    }
}
