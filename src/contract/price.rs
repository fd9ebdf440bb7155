//! The price of synchronous work (issue 34, item 2): what a synchronous
//! request will cost in CPU seconds, counted from its validated request
//! with unit costs measured on the reference machine (2 cores, release
//! build; the figures are in each constant's doc), per-run, per-sample and
//! per-step overheads included; and the one budget past which a request is
//! refused (422 `too_large`) with a pointer to the job queue.
//!
//! A synchronous solve runs on the shared rayon pool: what one request
//! costs, every other request waits for. Pricing by the dominant count
//! alone (segment-steps) let a request of many tiny runs through at 0.7 %
//! of its limit that took 11.3 CPU-seconds (10 000 samples of 2 steps ×
//! 2 segments: each sample's static start and turbulence field cost far
//! more than its steps). So every term that grows with a request field is
//! priced here, in one place, and `tests/api_priced_work.rs` runs the most
//! expensive request each kind accepts and checks it stays within its
//! share of the solve timeout.
//!
//! Each kind prices itself ([`crate::contract::analysis::Analysis::price`]) with its unit costs beside its request (`dynamics/price.rs`, `envelope/price.rs`); the budget and the admission of work in flight are here.

/// CPU seconds a synchronous request may cost; past it: a job.
pub const SYNC_CPU_BUDGET_S: f64 = 2.0;

/// The price of one request: its CPU seconds and the field that sets them.
#[derive(Clone, Debug, PartialEq)]
pub struct Price {
    /// Estimated CPU seconds on the reference machine.
    pub cpu_s: f64,
    /// The request field that makes it expensive (a JSON path).
    pub field: String,
    /// The counts behind the price, in words.
    pub counts: String,
}

impl Price {
    /// Whether it fits the synchronous budget.
    pub fn fits(&self) -> bool {
        self.cpu_s <= SYNC_CPU_BUDGET_S
    }

    /// Why it does not fit, in plain words (for a 422 `too_large`).
    pub fn refusal(&self, job_kind: &str) -> String {
        format!(
            "{} take about {:.1} CPU-seconds, more than a synchronous answer may use ({SYNC_CPU_BUDGET_S} s): \
             submit a job with \"kind\": \"{job_kind}\"",
            self.counts, self.cpu_s
        )
    }
}

/// CPU seconds of priced work that may run at once over all synchronous
/// requests: two requests at the budget. A cheap request queued behind
/// them on the shared pool then waits about a second on two cores, not
/// as long as every expensive request that arrived before it.
pub const IN_FLIGHT_CPU_S: f64 = 2.0 * SYNC_CPU_BUDGET_S;
/// Work cheaper than this is not counted (it cannot hold the pool).
pub const CHEAP_CPU_S: f64 = 0.05;

/// The priced work running now, over all synchronous requests.
#[derive(Debug, Default)]
pub struct InFlight {
    micro_cpu_s: std::sync::atomic::AtomicU64,
}

/// Priced work admitted; given back when dropped.
#[derive(Debug)]
pub struct Admitted<'a> {
    pool: &'a InFlight,
    micro_cpu_s: u64,
}

impl Drop for Admitted<'_> {
    fn drop(&mut self) {
        self.pool
            .micro_cpu_s
            .fetch_sub(self.micro_cpu_s, std::sync::atomic::Ordering::AcqRel);
    }
}

impl InFlight {
    /// Admits `price` unless the priced work running would exceed
    /// [`IN_FLIGHT_CPU_S`] (one request alone is always admitted); `Err`
    /// holds the CPU seconds already running.
    pub fn admit(&self, price: &Price) -> Result<Admitted<'_>, f64> {
        use std::sync::atomic::Ordering;
        if price.cpu_s < CHEAP_CPU_S {
            return Ok(Admitted {
                pool: self,
                micro_cpu_s: 0,
            });
        }
        let micro = (price.cpu_s.min(1e6) * 1e6) as u64;
        let before = self.micro_cpu_s.fetch_add(micro, Ordering::AcqRel);
        if before > 0 && (before + micro) as f64 > IN_FLIGHT_CPU_S * 1e6 {
            self.micro_cpu_s.fetch_sub(micro, Ordering::AcqRel);
            return Err(before as f64 / 1e6);
        }
        Ok(Admitted {
            pool: self,
            micro_cpu_s: micro,
        })
    }

    /// CPU seconds of priced work running now.
    pub fn running_cpu_s(&self) -> f64 {
        self.micro_cpu_s.load(std::sync::atomic::Ordering::Acquire) as f64 / 1e6
    }
}
