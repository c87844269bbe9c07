//! Entries whose error estimate ended above their goal, counted so that a run can name them.
//!
//! A partly obstructed pair is computed to an absolute goal on its exchange area (`auto`:
//! [`super::policy::pair_goal`]; `analytic`: a relative target on the unobstructed value).
//! Monte Carlo that cannot reach the goal within its sample cap is replaced by the shadow
//! integration, and the integration stops only at its depth limit or where its error stops
//! falling ([`super::adaptive::STALL_MIN_WORK`]); under `auto` an integration that ends there
//! is checked against a capped sample, which is kept where its error is the smaller. An entry
//! that still misses its goal is recorded here. The log keeps the count and the worst entry (largest
//! estimate over goal, ties broken by the pair), so its report is the same on any thread count.
use std::sync::Mutex;

/// One entry over its goal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Miss {
    /// Emitting patch.
    pub i: usize,
    /// Receiving patch.
    pub j: usize,
    /// Error estimate of A_i F_ij (Monte Carlo: [`super::policy::MC_SIGMAS`] standard errors), m².
    pub error: f64,
    /// The goal it missed, m².
    pub goal: f64,
}

impl Miss {
    /// Estimate over goal.
    pub fn ratio(&self) -> f64 {
        self.error / self.goal
    }
}

/// Count and worst entry of the misses of one run.
#[derive(Debug, Default)]
pub struct MissLog {
    inner: Mutex<(u64, Option<Miss>)>,
}

impl MissLog {
    /// Records `m`.
    pub fn record(&self, m: Miss) {
        let mut g = self.inner.lock().unwrap_or_else(|e| e.into_inner());
        g.0 += 1;
        let worse = match g.1 {
            None => true,
            Some(w) => m.ratio().total_cmp(&w.ratio()).then((w.i, w.j).cmp(&(m.i, m.j))).is_gt(),
        };
        if worse {
            g.1 = Some(m);
        }
    }
    /// Adds another log's (count, worst), as recorded by a copy of the kernel on another MPI
    /// rank: the result is the log of all the rows together.
    pub fn merge(&self, count: u64, worst: Option<Miss>) {
        if let Some(w) = worst {
            self.record(w);
            let mut g = self.inner.lock().unwrap_or_else(|e| e.into_inner());
            g.0 += count - 1;
        }
    }
    /// (count, worst).
    pub fn summary(&self) -> (u64, Option<Miss>) {
        *self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_worst_entry_does_not_depend_on_the_order() {
        let a = Miss { i: 3, j: 9, error: 3.0, goal: 1.0 };
        let b = Miss { i: 1, j: 4, error: 6.0, goal: 2.0 }; // the same ratio, a smaller pair
        let c = Miss { i: 0, j: 2, error: 1.5, goal: 1.0 };
        for order in [[a, b, c], [c, b, a], [b, a, c]] {
            let log = MissLog::default();
            order.iter().for_each(|&m| log.record(m));
            assert_eq!(log.summary(), (3, Some(b)), "{order:?}");
        }
    }
}
