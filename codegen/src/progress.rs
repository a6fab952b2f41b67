//! How far a long run is, for a display: the phase it is in and the work done of the work
//! planned, updated from the simulation threads and read by a display thread (the CLI's
//! progress bar). Counting never changes what a run computes.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

/// The state of a run: phase, work units done and planned.
#[derive(Debug, Default)]
pub struct Progress {
    done: AtomicU64,
    total: AtomicU64,
    phase: Mutex<&'static str>,
}

impl Progress {
    /// Enters `phase` (a short name: "chain run", "files", "writing").
    pub fn set_phase(&self, phase: &'static str) {
        *self.phase.lock().unwrap_or_else(|e| e.into_inner()) = phase;
    }

    /// The current phase ("" before the first).
    pub fn phase(&self) -> &'static str {
        *self.phase.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Plans `units` more units of work.
    pub fn plan(&self, units: u64) {
        self.total.fetch_add(units, Ordering::Relaxed);
    }

    /// Counts `units` units of work done.
    pub fn advance(&self, units: u64) {
        self.done.fetch_add(units, Ordering::Relaxed);
    }

    /// Units done and planned.
    pub fn counts(&self) -> (u64, u64) {
        (
            self.done.load(Ordering::Relaxed),
            self.total.load(Ordering::Relaxed),
        )
    }
}
