//! Memory given back after a load passes (issue 34): the allocator's
//! settings for a long-running server ([`tune_allocator`]) and a trim of
//! the free heap once connections have closed ([`Trimmer`]).
//!
//! glibc's malloc keeps freed memory in its arenas: one per thread that
//! ever contended, up to eight per core, and a heap top it gives back
//! only past a threshold that grows with the largest buffer freed. After
//! a flood of connections each tokio worker's arena holds what that load
//! needed, long after it passed (463 MB stayed after a trickle that took
//! the server from 32 MB to 756 MB). So, on glibc:
//!
//! * at most [`ARENAS`] arenas (`M_ARENA_MAX`): the heap is shared, not
//!   split per thread;
//! * buffers of [`MMAP_THRESHOLD`] and more are mapped on their own and
//!   unmapped when freed (`M_MMAP_THRESHOLD`, which also stops glibc from
//!   raising the threshold after each large free);
//! * the heap top is given back past [`TRIM_THRESHOLD`] (`M_TRIM_THRESHOLD`);
//! * and [`Trimmer`] calls `malloc_trim(0)` (which also gives back whole free
//!   pages inside the heap, not only at its top) a moment after
//!   connections have closed, at most once per [`TRIM_EVERY`].
//!
//! The settings apply to `tetherplan serve` only (`main.rs` calls
//! [`tune_allocator`] before any thread starts); elsewhere nothing changes.

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

/// Arenas of the allocator.
pub const ARENAS: i32 = 2;
/// Allocations of this size and more are mapped on their own.
pub const MMAP_THRESHOLD: i32 = 256 << 10;
/// Free memory at the heap top beyond this is given back at once.
pub const TRIM_THRESHOLD: i32 = 4 << 20;
/// Least time between two trims.
pub const TRIM_EVERY: Duration = Duration::from_secs(2);

/// Sets the allocator's limits (glibc; a no-op elsewhere). Call before the
/// runtime's threads start.
pub fn tune_allocator() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    glibc::tune(ARENAS, MMAP_THRESHOLD, TRIM_THRESHOLD);
}

/// Gives the free heap back to the system now (glibc; a no-op elsewhere).
/// Returns whether memory was released.
pub fn trim() -> bool {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    let released = glibc::trim();
    #[cfg(not(all(target_os = "linux", target_env = "gnu")))]
    let released = false;
    released
}

#[cfg(all(target_os = "linux", target_env = "gnu"))]
mod glibc {
    pub fn tune(arenas: i32, mmap_threshold: i32, trim_threshold: i32) {
        // SAFETY: mallopt only changes the allocator's parameters; called
        // before other threads allocate.
        unsafe {
            libc::mallopt(libc::M_ARENA_MAX, arenas);
            libc::mallopt(libc::M_MMAP_THRESHOLD, mmap_threshold);
            libc::mallopt(libc::M_TRIM_THRESHOLD, trim_threshold);
        }
    }

    pub fn trim() -> bool {
        // SAFETY: malloc_trim is thread-safe.
        unsafe { libc::malloc_trim(0) != 0 }
    }
}

/// Counts closed connections and trims the heap a moment after some have
/// closed (at most once per [`TRIM_EVERY`]).
#[derive(Clone, Default)]
pub struct Trimmer {
    closed: Arc<AtomicU64>,
}

impl Trimmer {
    /// One connection has ended.
    pub fn closed(&self) {
        self.closed.fetch_add(1, Ordering::Relaxed);
    }

    /// Runs until the process ends: every [`TRIM_EVERY`], if connections
    /// closed since the last look, trims the heap on a blocking thread.
    pub async fn run(self) {
        let mut seen = 0;
        loop {
            tokio::time::sleep(TRIM_EVERY).await;
            let now = self.closed.load(Ordering::Relaxed);
            if now != seen {
                seen = now;
                let _ = tokio::task::spawn_blocking(trim).await;
            }
        }
    }
}
