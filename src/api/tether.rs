//! The tether routes (SPEC §6): `POST /api/v1/equilibrium` (one static
//! equilibrium in a steady wind) and `POST /api/v1/envelope` (equilibria
//! over wind speed × tether length; large ones go to the job queue).

use axum::extract::State;
use axum::response::Response;

use crate::api::AppState;
use crate::api::error::{ApiError, JsonBody};
use crate::api::solve::{Deadline, SolveCtx, solve_path};
use crate::contract::dto::ErrorBody;
use crate::contract::envelope::dto::{EnvelopeRequest, EnvelopeResponse};
use crate::contract::envelope::{self, MAX_SYNC_ENVELOPE_POINTS};
use crate::contract::equilibrium::dto::{EquilibriumRequest, EquilibriumResponse};
use crate::contract::{self, equilibrium};
use crate::numerics::chart::Parallelism;

/// The part of an envelope's price that names the field it is refused for.
const SOLO_SHARE: f64 = 0.5;

fn to_json(value: &impl serde::Serialize) -> Result<Vec<u8>, ApiError> {
    Ok(contract::finite::to_vec(value)?)
}

solve_path!(
    /// Static equilibrium of the tether in a steady wind: altitude, downwind
    /// distance, winch and top tension, safety factor, blow-down and shape.
    ///
    /// A heavy, optionally elastic tether under its weight, normal wind drag
    /// and the aerostat's drag, lift and net buoyancy, integrated from the
    /// aerostat down (RK4, shooting on the altitude). Slack (part of the
    /// tether on the ground) is an answer, not an error. Presets
    /// (`cable.preset`, `aerostat.preset`) fill the fields left out.
    compute_equilibrium, "/api/v1/equilibrium", EquilibriumRequest, EquilibriumResponse,
    parse = |body| contract::parse_plain(body),
    |req, _ctx| to_json(&equilibrium::equilibrium(&req)?)
);

solve_path!(
    /// Operating envelope over wind speed × tether length: altitude,
    /// blow-down, tensions, safety factor, slack and stability at each point,
    /// the largest operating wind per length and the highest altitude per wind.
    ///
    /// Each point is judged against slack, the required safety factor, an
    /// optional ceiling and (with `payout_rate_m_s`) stability; the first
    /// violated is its binding limit. Synchronously at most 5 000 points
    /// and 2 CPU-seconds (points × `integration_steps`, about 0.7 µs per
    /// point and step: 5 000 points at 500 steps);
    /// larger envelopes (up to 250 000 points) go to `POST /api/v1/jobs` with
    /// `"kind": "envelope"`.
    compute_envelope, "/api/v1/envelope", EnvelopeRequest, EnvelopeResponse,
    parse = |body| contract::parse_plain(body),
    |req, ctx| {
        req.validate()?;
        let points = req.points();
        if points > MAX_SYNC_ENVELOPE_POINTS {
            return Err(ApiError::too_large(
                &req.tether_lengths_m.count_field("tether_lengths_m"),
                format!(
                    "the envelope has {points} points; synchronous envelopes have at most {MAX_SYNC_ENVELOPE_POINTS} (submit a job with \"kind\": \"envelope\")"
                ),
            ));
        }
        if req.uses_ge() && points > envelope::MAX_SYNC_GE_ENVELOPE_POINTS {
            return Err(ApiError::too_large(
                &req.tether_lengths_m.count_field("tether_lengths_m"),
                format!(
                    "the envelope has {points} points; synchronous envelopes with the quasi-static GE stability have at most {} (submit a job with \"kind\": \"envelope\")",
                    envelope::MAX_SYNC_GE_ENVELOPE_POINTS
                ),
            ));
        }
        let mut price = crate::price::envelope(
            points,
            req.integration_steps,
            &req.tether_lengths_m.count_field("tether_lengths_m"),
        );
        if let Some(contract::envelope::stability::EnvelopeStabilityInput::QuasiStaticGe { elements, .. }) = &req.stability {
            let rows = req.wind_speeds_m_s.as_ref().map_or(1, |g| g.count());
            let ge = crate::price::ge_envelope(rows, points, *elements);
            price.cpu_s += ge.cpu_s;
            if ge.cpu_s > SOLO_SHARE * price.cpu_s {
                price.field = ge.field;
                price.counts = ge.counts;
            }
        }
        let _admitted = ctx.charge(&price, "envelope")?;
        to_json(&envelope::envelope(&req, Parallelism::Rayon, &Deadline::after(ctx))?)
    }
);
