//! Flagged entries: pairs whose factor a method wrote without being able to bound its error
//! (or knowingly short), reported on stderr by the CLI instead of passing silently.
//!
//! A kernel records them while it runs ([`FlagLog`]); the engine hands them, sorted, to the
//! result ([`super::ViewFactors::flags`], [`super::packed::PackedTriangular::flags`]).
use super::MethodSet;
use std::sync::Mutex;

/// One flagged patch pair.
#[derive(Debug, Clone, PartialEq)]
pub struct Flag {
    /// Emitting patch.
    pub from: usize,
    /// Receiving patch.
    pub to: usize,
    /// The method that produced the entry.
    pub method: MethodSet,
    /// What is wrong, for the user (the value, the bound, what was cut).
    pub note: String,
}

/// Flags recorded by a kernel's parallel rows; rare, so one lock is enough.
#[derive(Debug, Default)]
pub struct FlagLog(Mutex<Vec<Flag>>);

impl FlagLog {
    /// Records a flag.
    pub fn push(&self, flag: Flag) {
        self.0.lock().unwrap_or_else(|e| e.into_inner()).push(flag);
    }

    /// The flags recorded so far, sorted by pair (the same on any thread count).
    pub fn sorted(&self) -> Vec<Flag> {
        let mut v = self.0.lock().unwrap_or_else(|e| e.into_inner()).clone();
        v.sort_by_key(|a| (a.from, a.to, a.method.bits()));
        v.dedup_by(|a, b| a.from == b.from && a.to == b.to && a.method == b.method);
        v
    }
}
