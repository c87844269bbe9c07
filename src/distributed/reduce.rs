//! Reductions across MPI ranks in a fixed order, so that a distributed sum is bit-identical to
//! the single-process one (used by the distributed link hierarchy, `exchange::hierarchy`):
//!
//! - [`ordered_sum`]: an ordered chain. Rank r receives the running sum of the ranks before it,
//!   adds its own terms in their order, and passes it on; the last rank broadcasts the total.
//!   The additions happen in exactly the order of one process adding every term in rank order.
//! - [`all_gather_bytes`], [`all_gather_u64`]: every rank's data, in rank order, on every rank.
//! - [`all_to_all_bytes`]: each rank's bytes for each other rank, delivered (in rounds of at
//!   most [`ROUND_BYTES`] per rank, below MPI's 2 GiB counts).
//! - [`bytes_sent`]: what this rank has sent through these functions (for the scaling notes).
//!
//! Every function is collective when [`active`] is true (MPI up with several ranks, called from
//! the main thread): every rank must call it, in the same order. Otherwise each is the
//! single-process answer, so callers need no `cfg`. Waits test and sleep instead of spinning,
//! since ranks may share cores with computing ranks.
use std::sync::atomic::{AtomicU64, Ordering};

/// Bytes this rank has sent through the functions of this module.
static SENT: AtomicU64 = AtomicU64::new(0);

/// True when the calls here are collectives over several ranks.
pub fn active() -> bool {
    #[cfg(feature = "mpi")]
    {
        super::comm::active()
    }
    #[cfg(not(feature = "mpi"))]
    {
        false
    }
}

/// Bytes this rank has sent through this module since the start (0 without MPI).
pub fn bytes_sent() -> u64 {
    SENT.load(Ordering::Relaxed)
}

/// The sum over ranks, in rank order, of `len` values: starts from zeros on rank 0 (from the
/// running sum of the ranks before it on the others), lets `add` add this rank's terms in
/// place, and returns the total, the same on every rank. Single process: zeros, then `add`.
pub fn ordered_sum(len: usize, add: impl FnOnce(&mut [f64])) -> Vec<f64> {
    let mut y = vec![0.0; len];
    if !active() {
        add(&mut y);
        return y;
    }
    #[cfg(feature = "mpi")]
    mpi_impl::chain(&mut y, add);
    y
}

/// Every rank's bytes, in rank order (`[mine]` in a single process).
pub fn all_gather_bytes(mine: &[u8]) -> Vec<Vec<u8>> {
    if !active() {
        return vec![mine.to_vec()];
    }
    #[cfg(feature = "mpi")]
    {
        mpi_impl::all_gather_bytes(mine)
    }
    #[cfg(not(feature = "mpi"))]
    unreachable!("active() is false without MPI")
}

/// Bytes a rank sends in one round of [`all_to_all_bytes`] (MPI counts are C ints).
pub const ROUND_BYTES: usize = 1 << 30;

/// `to[d]` goes to rank d; returns what each rank sent to this one, in rank order (`to`
/// itself in a single process). Large exchanges travel in rounds of at most [`ROUND_BYTES`]
/// sent by each rank.
pub fn all_to_all_bytes(to: Vec<Vec<u8>>) -> Vec<Vec<u8>> {
    if !active() {
        return to;
    }
    #[cfg(feature = "mpi")]
    {
        mpi_impl::all_to_all_bytes(&to)
    }
    #[cfg(not(feature = "mpi"))]
    unreachable!("active() is false without MPI")
}

/// Every rank's `v`, in rank order (`[v]` in a single process).
pub fn all_gather_u64(v: u64) -> Vec<u64> {
    all_gather_bytes(&v.to_le_bytes())
        .iter()
        .map(|b| u64::from_le_bytes(b[..8].try_into().expect("8 bytes a rank")))
        .collect()
}

#[cfg(feature = "mpi")]
mod mpi_impl {
    use super::SENT;
    use mpi::collective::{CommunicatorCollectives, Root};
    use mpi::datatype::PartitionMut;
    use mpi::point_to_point::{Destination, Source};
    use mpi::request::{Request, Scope};
    use mpi::topology::{Communicator, SimpleCommunicator};
    use std::sync::atomic::Ordering;
    use std::time::Duration;

    /// Sleep between tests of a pending message: short against a solve's matrix–vector
    /// product, long enough that a waiting rank leaves its core to the computing ones.
    const POLL: Duration = Duration::from_micros(50);

    /// Waits for `req` by testing and sleeping.
    fn wait<'a, B: ?Sized, S: Scope<'a>>(mut req: Request<'a, B, S>) {
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

    fn sent(bytes: usize) {
        SENT.fetch_add(bytes as u64, Ordering::Relaxed);
    }

    /// The ordered chain of [`super::ordered_sum`].
    pub fn chain(y: &mut [f64], add: impl FnOnce(&mut [f64])) {
        let world = SimpleCommunicator::world();
        let (rank, size) = (world.rank() as usize, world.size() as usize);
        if rank > 0 {
            let from = world.process_at_rank(rank as i32 - 1);
            while from.immediate_probe().is_none() {
                std::thread::sleep(POLL);
            }
            from.receive_into(y);
        }
        add(y);
        if rank + 1 < size {
            mpi::request::scope(|scope| {
                wait(world.process_at_rank(rank as i32 + 1).immediate_send(scope, &*y));
            });
            sent(std::mem::size_of_val(y));
        }
        let last = world.process_at_rank(size as i32 - 1);
        mpi::request::scope(|scope| wait(last.immediate_broadcast_into(scope, y)));
        if rank + 1 == size {
            // A broadcast tree sends about one copy per other rank in all.
            sent(std::mem::size_of_val(y) * (size - 1));
        }
    }

    /// [`super::all_to_all_bytes`]: the lengths all-gathered first, so every rank knows the
    /// rounds, then one `Alltoallv` per round.
    pub fn all_to_all_bytes(to: &[Vec<u8>]) -> Vec<Vec<u8>> {
        let world = SimpleCommunicator::world();
        let size = world.size() as usize;
        assert_eq!(to.len(), size, "one buffer for each rank");
        let lens: Vec<u8> = to.iter().flat_map(|b| (b.len() as u64).to_le_bytes()).collect();
        let all: Vec<Vec<u64>> = all_gather_bytes(&lens)
            .iter()
            .map(|b| b.chunks_exact(8).map(|c| u64::from_le_bytes(c.try_into().expect("8"))).collect())
            .collect();
        let rank = world.rank() as usize;
        let piece = (super::ROUND_BYTES / size).max(1) as u64;
        let rounds = all.iter().flatten().map(|&l| l.div_ceil(piece)).max().unwrap_or(0);
        let mut got: Vec<Vec<u8>> = (0..size).map(|s| Vec::with_capacity(all[s][rank] as usize)).collect();
        let displs = |c: &[i32]| -> Vec<i32> {
            c.iter().scan(0i32, |acc, &c| Some(std::mem::replace(acc, *acc + c))).collect()
        };
        for k in 0..rounds {
            let cut = |len: u64| (k * piece).min(len) as usize..((k + 1) * piece).min(len) as usize;
            let send: Vec<u8> = to.iter().flat_map(|b| b[cut(b.len() as u64)].iter().copied()).collect();
            let sc: Vec<i32> = to.iter().map(|b| cut(b.len() as u64).len() as i32).collect();
            let rc: Vec<i32> = (0..size).map(|s| cut(all[s][rank]).len() as i32).collect();
            let (sd, rd) = (displs(&sc), displs(&rc));
            let mut recv = vec![0u8; rc.iter().map(|&c| c as usize).sum()];
            {
                let part = mpi::datatype::Partition::new(&send[..], &sc[..], &sd[..]);
                let mut into = PartitionMut::new(&mut recv[..], &rc[..], &rd[..]);
                super::super::comm::quiet_barrier(&world);
                world.all_to_all_varcount_into(&part, &mut into);
            }
            sent(send.len() - sc[rank] as usize);
            for s in 0..size {
                got[s].extend_from_slice(&recv[rd[s] as usize..(rd[s] + rc[s]) as usize]);
            }
        }
        got
    }

    /// Every rank's bytes, in rank order; ranks that arrive early wait without spinning.
    pub fn all_gather_bytes(mine: &[u8]) -> Vec<Vec<u8>> {
        let world = SimpleCommunicator::world();
        super::super::comm::quiet_barrier(&world);
        let size = world.size() as usize;
        let len = mine.len() as u64;
        let mut lens = vec![0u64; size];
        world.all_gather_into(&len, &mut lens[..]);
        if let Some(r) = lens.iter().position(|&l| l > i32::MAX as u64) {
            super::super::comm::refuse_big(r, lens[r]);
        }
        let counts: Vec<i32> = lens.iter().map(|&l| l as i32).collect();
        let displs: Vec<i32> =
            counts.iter().scan(0i32, |acc, &c| Some(std::mem::replace(acc, *acc + c))).collect();
        let mut buf = vec![0u8; lens.iter().sum::<u64>() as usize];
        {
            let mut part = PartitionMut::new(&mut buf[..], &counts[..], &displs[..]);
            world.all_gather_varcount_into(mine, &mut part);
        }
        sent(mine.len() * (size - 1));
        counts.iter().zip(&displs).map(|(c, d)| buf[*d as usize..(*d + *c) as usize].to_vec()).collect()
    }
}
