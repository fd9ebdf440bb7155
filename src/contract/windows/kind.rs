//! The `windows` analysis kind (SPEC §12, issue 32, [`Analysis`]): launch
//! windows from a forecast; distinct winds beyond what the synchronous
//! budget pays for ([`PLAN_S`] each) go to the job queue (progress in
//! plans).

use crate::contract::analysis::{Analysis, too_large};
use crate::contract::error::{Progress, RequestError};
use crate::contract::estimate::{self as est, Estimate};
use crate::contract::price::Price;
use crate::contract::windows::{self, WindowsRequest, WindowsResponse};
use crate::limits::Limits;

/// Distinct plans a synchronous windows request may need (a 48-hour
/// forecast of 51 members has up to 2 448).
pub const MAX_SYNC_PLANS: usize = 2_500;
/// One period of the answer: its wind, reason and a dozen numbers.
pub const PER_PERIOD: u64 = 24 * est::PER_NUMBER + 1200;

/// One plan of a distinct wind with its stability in that wind (measured
/// through the route: 5 distinct hours 1.60 CPU-s, 10 hours 3.20, 30 hours
/// 9.67: 0.32 s a plan), s.
pub const PLAN_S: f64 = 0.4;
/// The share of [`PLAN_S`] an ensemble member's verdict costs (the plan's
/// deciding steps only, `plan_verdict`: measured 0.38–0.47 of a full plan
/// for a GO verdict in 3–7 m/s at 10 m, less when a haul-down already past
/// its limit decides it).
pub const VERDICT_SHARE: f64 = 0.5;

impl Analysis for WindowsRequest {
    const NAME: &'static str = "windows";
    const SUMMARY: &'static str = "Launch windows by the hour from a forecast (SPEC §12): each period\n\
        of the forecast (an hour of Open-Meteo or CSV, a METAR, a TAF\n\
        group) judged exactly as `/plan` judges its wind, and the runs of\n\
        periods in which the deployment, `operation_s` aloft and the\n\
        haul-down fit, the `haul_down` limits shrunk by a lead-time factor.";
    const DESCRIPTION: &'static str = "`forecast.format` is `open_meteo` (`data` the JSON object of an\n\
        hourly forecast, or of its ensemble API with `_memberNN` keys),\n\
        `metar`, `taf` or `csv` (`data` the text). Each period's speeds at\n\
        their heights become a power law (two or more heights) or a log law\n\
        (one), its gust the mean times its gust ratio; the answer echoes\n\
        that §9 `wind` per hour. With an ensemble each hour has\n\
        `probability_go` (Wilson interval) and the 10/50/90 % of\n\
        `max_altitude_m`, each window its probability. Synchronously as\n\
        many distinct winds as 2 CPU-seconds allow (a plan each for the\n\
        first member, priced at 0.4 s: 5; half that for each other\n\
        member's verdict); more: a job with `\"kind\": \"windows\"`.";
    const ABOUT: &'static str = "Launch windows by the hour from a forecast (Open-Meteo JSON, METAR, TAF or CSV): each period judged as the plan judges its wind (progress bar in plans).";
    type Response = WindowsResponse;
    fn parse(body: &[u8]) -> Result<Self, RequestError> {
        windows::parse_windows(body)
    }
    fn prepare(&self) -> Result<(), RequestError> {
        windows::prepare(self).map(drop)
    }
    fn check_sync(&self, _: &Limits) -> Result<(), RequestError> {
        let prepared = windows::prepare(self)?;
        if prepared.plan_count() > MAX_SYNC_PLANS {
            return Err(too_large(
                "forecast.data",
                format!(
                    "{} distinct winds take too long to answer synchronously (at most {MAX_SYNC_PLANS}): submit a job with \"kind\": \"windows\"",
                    prepared.plan_count()
                ),
            ));
        }
        Ok(())
    }
    /// A plan (its stability in the hour's wind) per distinct wind of the
    /// first member, a verdict per other distinct wind.
    fn price(&self) -> Option<Price> {
        let prepared = windows::prepare(self).ok()?;
        let plans = prepared.plan_count();
        let full = prepared.full_plan_count();
        let verdicts = plans - full;
        Some(Price {
            cpu_s: (full as f64 + VERDICT_SHARE * verdicts as f64) * PLAN_S,
            field: "forecast.data".into(),
            counts: format!(
                "{plans} distinct winds ({full} planned in full, {verdicts} members' verdicts at {VERDICT_SHARE} of a plan),"
            ),
        })
    }
    fn run(&self, progress: &dyn Progress) -> Result<WindowsResponse, RequestError> {
        windows::windows(self, progress)
    }
    fn estimate(&self) -> Estimate {
        // The answer lists the first member's periods (parsing is cheap;
        // an unparsable forecast is refused by `prepare`).
        let periods = windows::source::parse_forecast(&self.forecast)
            .map_or(0, |f| f.members.first().map_or(0, |m| m.periods.len()))
            as u64;
        Estimate::new(
            "forecast.data",
            est::SMALL_ANSWER + periods.saturating_mul(PER_PERIOD),
        )
    }
}
