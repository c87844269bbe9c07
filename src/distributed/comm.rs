//! The MPI communicator (rsmpi, MPICH or Open MPI), used from the main thread only
//! (`Threading::Funneled`: rayon computes inside each rank, the main thread talks MPI).
//!
//! Every collective step starts at a *sync point*: a barrier that waits without spinning,
//! then an all-gather of (tag, value) from every rank. The tags say where each rank stands
//! (about to exchange rows, or finishing), the value carries the geometry hash or the exit
//! code. Ranks that disagree (another scene, another route, a rank whose input failed to load
//! and is finishing) end the whole run together with exit code 2 after rank 0 names the ranks
//! that differ: mixing their rows would give wrong numbers silently. Every rank learns the
//! disagreement at the same sync point, so each finalises MPI and exits in order; an abort
//! would let the process manager kill rank 0 before its message reached the terminal.
use mpi::collective::{CommunicatorCollectives, Root};
use mpi::datatype::PartitionMut;
use mpi::environment::Universe;
use mpi::topology::{Communicator, SimpleCommunicator};
use mpi::Threading;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, OnceLock};
use std::time::Duration;

/// Sleep between tests of a pending barrier: a waiting rank must not spin on a core that a
/// computing rank needs (MPICH's blocking calls poll), and 2 ms is far below any row block.
const POLL: Duration = Duration::from_millis(2);

/// Exit code of a run whose ranks disagree (bad input: docs/SPEC.md exit code 2).
const MISMATCH_EXIT: i32 = 2;

/// Tag of the sync point before the view-factor rows are split.
pub const TAG_ROWS: u64 = 1;
/// Tag of the sync point that ends the run.
pub const TAG_FINISH: u64 = 2;
/// Tag of the sync point before the link hierarchy is refined.
pub const TAG_HIERARCHY: u64 = 3;
/// Tag of the sync point before the ranks check that their row blocks of the dense store fit.
pub const TAG_STORE: u64 = 4;

static UNIVERSE: Mutex<Option<Universe>> = Mutex::new(None);
static RANK_SIZE: OnceLock<(usize, usize)> = OnceLock::new();
/// Set on rank 0 once the other ranks have sent their rows and are waiting to finish.
static WORKERS_GONE: AtomicBool = AtomicBool::new(false);

/// True when a process manager (`mpirun`/`mpiexec` of MPICH or Open MPI) started this process.
fn under_mpirun() -> bool {
    ["PMI_RANK", "PMI_SIZE", "OMPI_COMM_WORLD_RANK", "PMIX_RANK"]
        .iter()
        .any(|v| std::env::var_os(v).is_some())
}

/// Initialises MPI under `mpirun` (nothing otherwise) and silences the stdout and stderr of
/// ranks other than 0 unless [`super::VERBOSE_VAR`] is set.
pub fn start() {
    if !under_mpirun() {
        let _ = RANK_SIZE.set((0, 1));
        return;
    }
    let Some((universe, _)) = mpi::initialize_with_threading(Threading::Funneled) else {
        let _ = RANK_SIZE.set((0, 1));
        return;
    };
    let world = universe.world();
    let (rank, size) = (world.rank() as usize, world.size() as usize);
    let _ = RANK_SIZE.set((rank, size));
    *UNIVERSE.lock().unwrap_or_else(|e| e.into_inner()) = Some(universe);
    if rank != 0 && std::env::var_os(super::VERBOSE_VAR).is_none() {
        silence();
    }
}

/// Points stdout and stderr at /dev/null: rank 0 alone speaks to the user.
fn silence() {
    // SAFETY: open/dup2/close on file descriptors this process owns; no Rust object holds 1 or 2.
    unsafe {
        let fd = libc::open(c"/dev/null".as_ptr(), libc::O_WRONLY);
        if fd >= 0 {
            libc::dup2(fd, 1);
            libc::dup2(fd, 2);
            libc::close(fd);
        }
    }
}

/// (rank, size); (0, 1) before [`start`] or outside `mpirun`.
pub fn rank_size() -> (usize, usize) {
    RANK_SIZE.get().copied().unwrap_or((0, 1))
}

/// True when this process is one of several MPI ranks and may call collectives from here:
/// MPI is up, on the main thread, and (on rank 0) the other ranks have not yet left.
pub fn active() -> bool {
    let (rank, size) = rank_size();
    size > 1
        && std::thread::current().name() == Some("main")
        && (rank != 0 || !WORKERS_GONE.load(Ordering::Acquire))
}

fn world() -> SimpleCommunicator {
    SimpleCommunicator::world()
}

/// A barrier that sleeps between tests instead of spinning.
pub(crate) fn quiet_barrier(world: &SimpleCommunicator) {
    let mut req = world.immediate_barrier();
    loop {
        match req.test() {
            Ok(_) => return,
            Err(r) => {
                req = r;
                std::thread::sleep(POLL);
            }
        }
    }
}

/// A sync point: every rank's (tag, value), in rank order.
fn sync(tag: u64, value: u64) -> Vec<[u64; 2]> {
    let world = world();
    quiet_barrier(&world);
    let mine = [tag, value];
    let mut all = vec![0u64; 2 * world.size() as usize];
    world.all_gather_into(&mine[..], &mut all[..]);
    all.chunks_exact(2).map(|c| [c[0], c[1]]).collect()
}

fn tag_name(tag: u64) -> &'static str {
    match tag {
        TAG_ROWS => "about to compute view-factor rows",
        TAG_FINISH => "finishing",
        TAG_HIERARCHY => "about to refine the link hierarchy",
        TAG_STORE => "about to check the memory of the dense store",
        _ => "somewhere unknown",
    }
}

/// Ends every rank with exit code 2 after rank 0 prints `message`. Every rank calls it at the
/// same sync point (all of them saw the same all-gather), so MPI is finalised on every rank and
/// rank 0's message is written before any process ends.
fn refuse(message: &str) -> ! {
    if rank_size().0 == 0 {
        eprintln!("lambert: error: {message}");
    }
    drop(UNIVERSE.lock().unwrap_or_else(|e| e.into_inner()).take());
    std::process::exit(MISMATCH_EXIT)
}

/// The sync point before the rows are split: every rank must be there with the same `hash`
/// (geometry, method and options). A mismatch ends the run (exit code 2) with a message
/// naming the ranks that differ from rank 0.
pub fn check_rows(hash: u64, what: &str) {
    check(TAG_ROWS, hash, what);
}

/// A sync point at step `tag`: every rank must be there with the same `hash` (of `what`). A
/// mismatch (another hash, or a rank at another step) ends the run on every rank with exit
/// code 2 and a message naming the ranks that differ from rank 0.
pub fn check(tag: u64, hash: u64, what: &str) {
    let all = sync(tag, hash);
    let odd: Vec<String> = all
        .iter()
        .enumerate()
        .filter(|(_, e)| **e != all[0])
        .map(|(r, e)| {
            if e[0] != all[0][0] {
                format!("rank {r} is {} while rank 0 is {}", tag_name(e[0]), tag_name(all[0][0]))
            } else {
                format!("rank {r} has hash {:016x}, rank 0 {:016x}", e[1], all[0][1])
            }
        })
        .collect();
    if !odd.is_empty() {
        refuse(&format!(
            "the MPI ranks do not hold the same {what} ({}): every rank must load the same scene \
             files with the same options",
            odd.join("; ")
        ));
    }
}

/// Ends the run on every rank (all call it): rank `rank` holds `bytes` bytes for one all-gather, more than one MPI
/// message carries (2 GiB, MPI's int counts).
pub fn refuse_big(rank: usize, bytes: u64) -> ! {
    refuse(&format!(
        "rank {rank} holds {bytes} bytes for one exchange between the ranks, more than one MPI \
         message carries (2 GiB); run on more ranks"
    ))
}

/// Gathers every rank's bytes to rank 0, in rank order (`None` on the other ranks).
pub fn gather_bytes(mine: &[u8]) -> Option<Vec<Vec<u8>>> {
    let world = world();
    quiet_barrier(&world);
    let (rank, size) = rank_size();
    let root = world.process_at_rank(0);
    let len = mine.len() as u64;
    let mut lens = vec![0u64; if rank == 0 { size } else { 0 }];
    if rank == 0 {
        root.gather_into_root(&len, &mut lens[..]);
    } else {
        root.gather_into(&len);
    }
    // MPI counts are C ints: a rank's rows above 2 GiB cannot travel in one gather.
    let too_big = lens.iter().position(|&l| l > i32::MAX as u64);
    if rank == 0 {
        if let Some(r) = too_big {
            eprintln!(
                "lambert: error: rank {r} computed {} bytes of view-factor rows, more than one MPI \
                 message carries (2 GiB); run on more ranks",
                lens[r]
            );
            world.abort(1);
        }
        let counts: Vec<i32> = lens.iter().map(|&l| l as i32).collect();
        let displs: Vec<i32> =
            counts.iter().scan(0i32, |acc, &c| Some(std::mem::replace(acc, *acc + c))).collect();
        let mut buf = vec![0u8; lens.iter().sum::<u64>() as usize];
        {
            let mut part = PartitionMut::new(&mut buf[..], &counts[..], &displs[..]);
            root.gather_varcount_into_root(mine, &mut part);
        }
        let mut out = Vec::with_capacity(size);
        for (c, d) in counts.iter().zip(&displs) {
            out.push(buf[*d as usize..(*d + *c) as usize].to_vec());
        }
        Some(out)
    } else {
        root.gather_varcount_into(mine);
        None
    }
}

/// Marks (on rank 0) that the other ranks have left after sending their rows: later row
/// computations run on rank 0 alone.
pub fn workers_left() {
    WORKERS_GONE.store(true, Ordering::Release);
}

/// Ends this rank (not rank 0) after its rows are sent: it waits for rank 0's exit code and
/// exits with it.
pub fn leave() -> ! {
    let code = finish(0);
    std::process::exit(i32::from(code))
}

/// The last sync point: every rank learns rank 0's exit code and MPI is finalised. Returns
/// rank 0's code (`code` itself outside `mpirun`).
pub fn finish(code: u8) -> u8 {
    if UNIVERSE.lock().unwrap_or_else(|e| e.into_inner()).is_none() {
        return code;
    }
    if rank_size().1 == 1 {
        drop(UNIVERSE.lock().unwrap_or_else(|e| e.into_inner()).take());
        return code;
    }
    let all = sync(TAG_FINISH, u64::from(code));
    if let Some(r) = all.iter().position(|e| e[0] != TAG_FINISH) {
        refuse(&format!(
            "rank {r} is {} while rank 0 is finishing with exit code {}: the ranks took different \
             routes (every rank must load the same scene files with the same options)",
            tag_name(all[r][0]),
            all[0][1]
        ));
    }
    drop(UNIVERSE.lock().unwrap_or_else(|e| e.into_inner()).take());
    all[0][1] as u8
}
