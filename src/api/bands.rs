//! The uncertainty routes of the plan and the envelope (SPEC §8):
//! `POST /api/v1/plan/bands` and `POST /api/v1/envelope/bands` (the chart
//! bands, `POST /api/v1/bands`, are in [`crate::api::solve`]). Large runs
//! go to the job queue as `plan_bands` / `envelope_bands`.

use axum::extract::State;
use axum::response::Response;

use crate::api::AppState;
use crate::api::error::{ApiError, JsonBody};
use crate::api::solve::{Deadline, SolveCtx, solve_path};
use crate::contract::bands::envelope::{self, EnvelopeBandsRequest, EnvelopeBandsResponse};
use crate::contract::bands::plan::{self, PlanBandsRequest, PlanBandsResponse};
use crate::contract::dto::ErrorBody;
use crate::numerics::chart::Parallelism;

/// Sample × instant values a synchronous plan bands request may have.
pub const MAX_SYNC_PLAN_BAND_VALUES: usize = 2_000_000;
/// Sample × cell equilibria a synchronous envelope bands request may have
/// (about 0.1 ms each in a wind at 100 steps: about a second on 2 cores).
pub const MAX_SYNC_ENVELOPE_BAND_EVALUATIONS: usize = 10_000;

fn to_json(value: &impl serde::Serialize) -> Result<Vec<u8>, ApiError> {
    Ok(crate::contract::finite::to_vec(value)?)
}

solve_path!(
    /// A deployment plan under uncertain inputs: the nominal schedule, and per
    /// sample what it does to that sample's system.
    ///
    /// The body is a `POST /api/v1/plan` request plus `uncertainty` (seeded
    /// Monte Carlo over `aerostat.net_buoyancy_n`, `aerostat.mass_kg`, the
    /// cable's mass, `gravity_m_s2`, `tether.breaking_strength_n`). The answer
    /// holds the nominal plan, 5/50/95 % bands of the winch tension, largest
    /// tension and stability margin at every instant of its schedule, and the
    /// probabilities (Wilson 95 % interval) that some instant is unstable,
    /// breaks the lift reserve, or exceeds the tether rating. Synchronously at
    /// most 2 000 000 sample × instant values; larger as a job with
    /// `"kind": "plan_bands"`.
    compute_plan_bands, "/api/v1/plan/bands", PlanBandsRequest, PlanBandsResponse,
    parse = |body| plan::parse_plan_bands(body),
    |req, ctx| {
        plan::prepare_plan_bands(&req)?;
        let values = plan::plan_band_values(&req);
        if values > MAX_SYNC_PLAN_BAND_VALUES {
            return Err(ApiError::too_large(
                "uncertainty.samples",
                format!(
                    "{values} sample × instant values take too long to answer synchronously (at most {MAX_SYNC_PLAN_BAND_VALUES}): submit a job with \"kind\": \"plan_bands\""
                ),
            ));
        }
        to_json(&plan::plan_bands(&req, Parallelism::Rayon, &Deadline::after(ctx))?)
    }
);

solve_path!(
    /// The operating envelope under uncertain inputs: per cell, the
    /// probability of exceeding the tension limit, of instability and of
    /// leaving the envelope, and the band of the largest tension.
    ///
    /// The body is a `POST /api/v1/envelope` request plus `uncertainty` (over
    /// the aerostat's buoyancy, drag and lift coefficients and area, the
    /// tether's mass, diameter, drag coefficient, stiffness and breaking
    /// strength, the air density and gravity). Each sample solves the whole
    /// envelope. Synchronously at most 10 000 sample × cell equilibria; up to
    /// 2 000 000 as a job with `"kind": "envelope_bands"`.
    compute_envelope_bands, "/api/v1/envelope/bands", EnvelopeBandsRequest, EnvelopeBandsResponse,
    parse = |body| envelope::parse_envelope_bands(body),
    |req, ctx| {
        envelope::prepare_envelope_bands(&req)?;
        let total = envelope::envelope_band_evaluations(&req);
        if total > MAX_SYNC_ENVELOPE_BAND_EVALUATIONS {
            return Err(ApiError::too_large(
                "uncertainty.samples",
                format!(
                    "{total} equilibria (samples × cells) take too long to answer synchronously (at most {MAX_SYNC_ENVELOPE_BAND_EVALUATIONS}): submit a job with \"kind\": \"envelope_bands\""
                ),
            ));
        }
        let price = crate::price::envelope(total, req.envelope.integration_steps, "uncertainty.samples");
        let _admitted = ctx.charge(&price, "envelope_bands")?;
        to_json(&envelope::envelope_bands(&req, Parallelism::Rayon, &Deadline::after(ctx))?)
    }
);
