//! The windows route (SPEC §12, issue 32): `POST /api/v1/windows`, the
//! day's launch windows from a forecast. Forecasts needing more than
//! [`MAX_SYNC_PLANS`] distinct plans go to the job queue as `windows`.
//! The wiring of this kind is this file, one `.route` line in
//! [`crate::api`], one path in [`crate::api::openapi`], one job kind in
//! [`crate::jobs::windows`] and one CLI subcommand: ready to move into the
//! kind registry.

use axum::extract::State;
use axum::response::Response;

use crate::api::AppState;
use crate::api::error::{ApiError, JsonBody};
use crate::api::solve::{Deadline, SolveCtx, solve_path};
use crate::contract::dto::ErrorBody;
use crate::contract::windows::{self, WindowsRequest, WindowsResponse};
use crate::contract::{self};

/// Distinct plans a synchronous windows request may need (a 48-hour
/// forecast of 51 members has up to 2 448).
pub const MAX_SYNC_PLANS: usize = 2_500;

solve_path!(
    /// Launch windows by the hour from a forecast (SPEC §12): each period
    /// of the forecast (an hour of Open-Meteo or CSV, a METAR, a TAF
    /// group) judged exactly as `/plan` judges its wind, and the runs of
    /// periods in which the deployment, `operation_s` aloft and the
    /// haul-down fit, the `haul_down` limits shrunk by a lead-time factor.
    ///
    /// `forecast.format` is `open_meteo` (`data` the JSON object of an
    /// hourly forecast, or of its ensemble API with `_memberNN` keys),
    /// `metar`, `taf` or `csv` (`data` the text). Each period's speeds at
    /// their heights become a power law (two or more heights) or a log law
    /// (one), its gust the mean times its gust ratio; the answer echoes
    /// that §9 `wind` per hour. With an ensemble each hour has
    /// `probability_go` (Wilson interval) and the 10/50/90 % of
    /// `max_altitude_m`, each window its probability. Synchronously at
    /// most 2 500 distinct winds; larger: a job with `"kind": "windows"`.
    compute_windows, "/api/v1/windows", WindowsRequest, WindowsResponse,
    parse = |body| windows::parse_windows(body),
    |req, ctx| {
        let started = std::time::Instant::now();
        let prepared = windows::prepare(&req)?;
        if prepared.plan_count() > MAX_SYNC_PLANS {
            return Err(ApiError::too_large(
                "forecast.data",
                format!(
                    "{} distinct winds take too long to answer synchronously (at most {MAX_SYNC_PLANS}): submit a job with \"kind\": \"windows\"",
                    prepared.plan_count()
                ),
            ));
        }
        let out = windows::run::answer(&req, &prepared, &Deadline::after(ctx), started)?;
        Ok(contract::finite::to_vec(&out)?)
    }
);
