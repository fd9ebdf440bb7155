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
//! Kept apart from the routes so the analysis-kind registry can call it.

use crate::contract::dynamics::validate::Prepared;

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

// Dynamics unit costs, measured through `POST /api/v1/dynamics/peaks`
// (server CPU time from /proc, 2-core machine, release build), each set
// about 1.5 times the measurement:
//   200 samples, 100 m, 2 steps × 2 segments: 0.02 CPU-s (0.1 ms a sample);
//   1 000 samples, 500 m tether, 8 m/s, 2 × 2: 1.35 CPU-s (13 levels ×
//     1 024 times: 1.0e-8 s per field sample and log2);
//   200 samples, 500 m, 2 m/s, 2 × 2: 1.2 CPU-s (13 × 4 096: 9.4e-9);
//   200 samples, 2 000 m, 8 m/s, 2 × 2: 3.96 CPU-s (49 × 4 096: 8.2e-9);
//   20 samples, 200 steps × 200 segments: 0.18 CPU-s (1.9e-7 per
//     segment-step beside the field); 20 samples, 2 000 steps × 2
//     segments: 0.05 CPU-s (about 2e-7 per step).
/// Dynamics: each run's fixed cost (the §6 static start relaxed to the
/// discrete equilibrium, the quasi-static comparison), s.
pub const DYNAMICS_RUN_S: f64 = 2e-4;
/// Dynamics: one time step's fixed cost (generalized-α predictor, outputs), s.
pub const DYNAMICS_STEP_S: f64 = 4e-7;
/// Dynamics: one segment of one step (Newton on the block-tridiagonal
/// Jacobian, drag and turbulence at its node), s.
pub const DYNAMICS_SEGMENT_STEP_S: f64 = 2.8e-7;
/// Dynamics: one sample of one level of the turbulence field per
/// `log2` of the series length (its normal draws and FFT), s.
pub const DYNAMICS_FIELD_SAMPLE_S: f64 = 1.5e-8;

/// The turbulence field a run synthesises (levels × series samples), an
/// upper estimate from the request (as `numerics::dynamics::run` sizes it:
/// levels every 50 m to 1.2 × the longest length, the series of period
/// `duration + 2 top / U_c + 10 s` at 0.2 s, a power of two; `U_c` is
/// bounded below by the flow's slowest speed between half the first
/// length and the top).
pub fn turbulence_field(p: &Prepared) -> (f64, f64) {
    if p.problem.turbulence.is_none() {
        return (0.0, 0.0);
    }
    let c = &p.config;
    let top = p.problem.length.longest_m(c.duration_s) * 1.2;
    let low = 0.5 * p.problem.length.at(0.0).length_m;
    let levels = ((top / c.turbulence_level_spacing_m).ceil() + 1.0).clamp(4.0, 256.0);
    let slowest = (0..=64)
        .map(|i| {
            let z = low + (top - low) * i as f64 / 64.0;
            p.problem.flow.speed_m_s(z).abs()
        })
        .fold(f64::INFINITY, f64::min)
        .max(1e-6);
    let period = c.duration_s + 2.0 * top / slowest + 10.0;
    let wanted = (period / c.turbulence_time_step_s).ceil().max(4.0);
    let samples = if wanted.is_finite() && wanted < 1e15 {
        (wanted as u64).next_power_of_two() as f64
    } else {
        f64::INFINITY
    };
    (levels, samples)
}

/// CPU seconds of one dynamics run.
pub fn dynamics_run_s(p: &Prepared) -> f64 {
    let steps = p.steps as f64;
    let segments = p.config.segments as f64;
    let (levels, samples) = turbulence_field(p);
    let field = if samples > 0.0 {
        levels * samples * samples.log2().max(1.0) * DYNAMICS_FIELD_SAMPLE_S
    } else {
        0.0
    };
    DYNAMICS_RUN_S + steps * DYNAMICS_STEP_S + steps * segments * DYNAMICS_SEGMENT_STEP_S + field
}

/// Envelopes: one RK4 step of one equilibrium, the shooting's passes
/// included (measured 4.9e-7 to 7e-7 s: 2 000 points × 100 steps 0.14
/// CPU-s, × 1 000 steps 0.98 CPU-s, 5 000 × 1 000 2.51 CPU-s; the bands'
/// 2 100 sample-cells × 1 000 steps 1.37 CPU-s), s.
pub const ENVELOPE_POINT_STEP_S: f64 = 7e-7;
/// Envelopes: one equilibrium's fixed cost, s.
pub const ENVELOPE_POINT_S: f64 = 2e-6;

/// `POST /api/v1/envelope` and `/envelope/bands`: `points` equilibria of
/// `steps` RK4 steps each; `field` names the count that sets them.
pub fn envelope(points: usize, steps: usize, field: &str) -> Price {
    let points_f = points as f64;
    let steps_f = steps as f64;
    Price {
        cpu_s: points_f * (ENVELOPE_POINT_S + steps_f * ENVELOPE_POINT_STEP_S),
        field: if steps > 100 {
            "integration_steps".into()
        } else {
            field.into()
        },
        counts: format!("{points} equilibria of {steps} integration steps"),
    }
}

/// GE envelopes on a fixed mesh: one wind row's critical length and rate
/// searches at 20 elements (measured 0.14 CPU-s per row at 20 elements,
/// 0.77 at 40, 0.32 at 10: Newton restarts), s; they grow as
/// `(elements / 20)^2.5`.
pub const GE_ENVELOPE_ROW_S: f64 = 0.35;
/// GE envelopes on a fixed mesh: one cell's stability at 20 elements, s
/// (as `(elements / 20)^2`).
pub const GE_ENVELOPE_POINT_S: f64 = 0.01;
/// GE envelopes converged (no `elements`): one cell (measured 500 cells
/// in 0.06 CPU-s), s.
pub const GE_ENVELOPE_CONVERGED_POINT_S: f64 = 5e-4;

/// `POST /api/v1/envelope` with `stability.method = quasi_static_ge`:
/// `rows` winds × `points` cells, on a mesh of `elements` (None: the
/// converged searches).
pub fn ge_envelope(rows: usize, points: usize, elements: Option<usize>) -> Price {
    let cpu_s = match elements {
        Some(e) => {
            let r = (e as f64 / 20.0).max(1.0);
            rows as f64 * GE_ENVELOPE_ROW_S * r.powf(2.5)
                + points as f64 * GE_ENVELOPE_POINT_S * r * r
        }
        None => points as f64 * GE_ENVELOPE_CONVERGED_POINT_S,
    };
    Price {
        cpu_s,
        field: if elements.is_some() {
            "stability.elements".into()
        } else {
            "tether_lengths_m".into()
        },
        counts: match elements {
            Some(e) => format!(
                "{rows} winds × {} lengths of the quasi-static GE stability on {e} elements",
                points / rows.max(1)
            ),
            None => format!("{points} cells of the quasi-static GE stability"),
        },
    }
}

/// `POST /api/v1/dynamics`.
pub fn dynamics(p: &Prepared) -> Price {
    Price {
        cpu_s: dynamics_run_s(p),
        field: "duration_s".into(),
        counts: format!(
            "{} steps of {} segments{}",
            p.steps,
            p.config.segments,
            field_words(p)
        ),
    }
}

/// `POST /api/v1/dynamics/peaks`: `samples` runs.
pub fn dynamics_peaks(p: &Prepared, samples: usize) -> Price {
    Price {
        cpu_s: dynamics_run_s(p) * samples as f64,
        field: "samples".into(),
        counts: format!(
            "{samples} samples of {} steps × {} segments{}",
            p.steps,
            p.config.segments,
            field_words(p)
        ),
    }
}

fn field_words(p: &Prepared) -> String {
    let (levels, samples) = turbulence_field(p);
    if samples > 0.0 {
        format!(" with a turbulence field of {levels:.0} levels × {samples:.0} times each")
    } else {
        String::new()
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
