//! The dynamics routes (SPEC §11): `POST /api/v1/dynamics` (one run in
//! time through a gust or turbulence) and `POST /api/v1/dynamics/peaks`
//! (the largest tension over an exposure, Monte Carlo over seeds). Runs
//! above the synchronous limits go to the job queue as `dynamics` /
//! `dynamics_peaks`.

use axum::extract::State;
use axum::response::Response;

use crate::api::AppState;
use crate::api::error::{ApiError, JsonBody};
use crate::api::solve::{Deadline, SolveCtx, solve_path};
use crate::contract::dto::ErrorBody;
use crate::contract::dynamics::{
    self, DynamicsPeaksRequest, DynamicsPeaksResponse, DynamicsRequest, DynamicsResponse,
    MAX_SYNC_PEAK_WORK, MAX_SYNC_SAMPLES, MAX_SYNC_WORK,
};
use crate::contract::{self};
use crate::numerics::chart::Parallelism;

fn to_json(value: &impl serde::Serialize) -> Result<Vec<u8>, ApiError> {
    Ok(contract::finite::to_vec(value)?)
}

solve_path!(
    /// The tether in time (SPEC §11): from rest in the static equilibrium
    /// of `wind.flow`, through the change of `wind.time_history` (a step,
    /// ramp or `1 − cos` gust, a sinusoid, or seeded von Kármán / Kaimal
    /// turbulence), at a fixed `tether_length_m` or along a `profile`.
    ///
    /// A lumped-mass tether in the vertical plane downwind (EA, internal
    /// damping, weight, drag on the relative velocity), the aerostat with
    /// its added mass, generalized-α steps. The answer: `samples` of the
    /// winch and top tensions and the aerostat's position, tether `shapes`
    /// at evenly spaced times, `slack_events`, and the peak and minimum
    /// tensions beside the quasi-static ones at the same wind.
    /// Synchronously at most 3 000 000 segment-steps (`duration_s /
    /// numerics.time_step_s × numerics.segments`), 20 000 samples and
    /// 2 CPU-seconds as priced from the steps, segments and turbulence
    /// field (`crate::price`); larger runs: a job with `"kind": "dynamics"`.
    run_dynamics, "/api/v1/dynamics", DynamicsRequest, DynamicsResponse,
    parse = |body| dynamics::parse_dynamics(body),
    |req, ctx| {
        let prepared = req.prepare().map_err(contract::RequestError::from)?;
        if prepared.work() > MAX_SYNC_WORK {
            return Err(ApiError::too_large(
                "duration_s",
                format!(
                    "{:.0} segment-steps take too long to answer synchronously (at most {MAX_SYNC_WORK:e}): submit a job with \"kind\": \"dynamics\"",
                    prepared.work()
                ),
            ));
        }
        let price = crate::price::dynamics(&prepared);
        let _admitted = ctx.charge(&price, "dynamics")?;
        if req.sample_count > MAX_SYNC_SAMPLES {
            return Err(ApiError::too_large(
                "sample_count",
                format!(
                    "{} samples are more than a synchronous answer keeps (at most {MAX_SYNC_SAMPLES}): submit a job with \"kind\": \"dynamics\"",
                    req.sample_count
                ),
            ));
        }
        let ran = dynamics::run::run_prepared(&prepared, &Deadline::after(ctx))?;
        to_json(&dynamics::run::response(&req, &prepared, &ran))
    }
);

solve_path!(
    /// The largest tension over an exposure by Monte Carlo over turbulence
    /// seeds (issue 23): e.g. the 99th percentile of the hourly maximum
    /// winch tension with its order-statistic interval, beside the
    /// quasi-static tensions of the mean wind and of the §10 gust check.
    ///
    /// Sample `i` is the `POST /api/v1/dynamics` run of the same system
    /// with turbulence seed `seed + i` and `duration_s = exposure_s`.
    /// Synchronously at most 6 000 000 segment-steps in all and 2
    /// CPU-seconds as priced per sample (its static start, its turbulence
    /// field, its steps and segments: `crate::price`); larger: a job with
    /// `"kind": "dynamics_peaks"`, split by sample over any number of
    /// workers with the same answer.
    run_dynamics_peaks, "/api/v1/dynamics/peaks", DynamicsPeaksRequest, DynamicsPeaksResponse,
    parse = |body| dynamics::parse_peaks(body),
    |req, ctx| {
        let prepared = req.prepare().map_err(contract::RequestError::from)?;
        let work = prepared.work() * req.samples as f64;
        if work > MAX_SYNC_PEAK_WORK {
            return Err(ApiError::too_large(
                "samples",
                format!(
                    "{work:.0} segment-steps (samples × steps × segments) take too long to answer synchronously (at most {MAX_SYNC_PEAK_WORK:e}): submit a job with \"kind\": \"dynamics_peaks\""
                ),
            ));
        }
        let price = crate::price::dynamics_peaks(&prepared, req.samples);
        let _admitted = ctx.charge(&price, "dynamics_peaks")?;
        to_json(&dynamics::peaks::peaks(&req, Parallelism::Rayon, &Deadline::after(ctx))?)
    }
);
