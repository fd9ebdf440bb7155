//! Runs a windows request: the forecast parsed ([`super::source`]), each
//! period's winds fitted to a flow ([`crate::numerics::forecast::profile`]),
//! each distinct wind planned once by the plan's own code (on rayon: in
//! full, [`crate::contract::plan::plan`], for the first member, whose hours
//! the answer reports; for the other members its verdict only,
//! [`crate::contract::plan::plan_verdict`], the same `go`, durations and
//! altitude without the figures only `/plan` reports), the periods judged against
//! the limits shrunk by the lead-time factor, the windows found
//! ([`crate::numerics::forecast::windows`]) and, with an ensemble, the
//! members' shares of GO.
//!
//! The plan of a period is `/plan` with the request's system and target and
//! the period's §9 `wind`; with `haul_down` it carries the haul-down
//! deadline of that wind at the target held from now (a wind or gust past
//! the limit makes it no-go, and says so). Without `haul_down` the plan is
//! run with a limit no wind reaches (200 m/s) to learn the haul-down's
//! duration; its verdict is `/plan`'s without a forecast (whether a
//! schedule exists) and its reason given without that clause, so each
//! hour's answer is `/plan`'s exactly.

use std::collections::HashMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use rayon::prelude::*;
use serde_json::{Map, Value};

use crate::contract::plan::dto::{HaulDownInput, PlanResponse, WindForecastPointInput};
use crate::contract::plan::{PlanRequest, PlanVerdict, plan_verdict};
use crate::contract::system::{GustInput, WindFlowInput, WindInput};
use crate::contract::windows::dto::*;
use crate::contract::windows::source::{ParsedForecast, RawPeriod, parse_forecast};
use crate::contract::{Progress, RequestError};
use crate::numerics::forecast::profile::{FitError, FittedFlow, FittedHour, fit_hour};
use crate::numerics::forecast::windows::{
    LeadTimeFactor, Period, Window, deciles_10_50_90, share_go, supports, windows as find_windows,
};
use crate::numerics::params::InvalidInput;

/// The haul-down limit of the internal deadline when the request has none:
/// above every wind the flow accepts (150 m/s).
const NO_LIMIT_M_S: f64 = 200.0;

/// One period of one member, ready to plan.
#[derive(Clone, Debug)]
struct Case {
    wind: WindInput,
    wind_at_target_m_s: f64,
    gust_at_target_m_s: Option<f64>,
    /// Index of its plan among the distinct ones.
    plan: usize,
}

/// A request parsed and checked, its distinct plans listed (no plan run).
pub struct Prepared {
    forecast: ParsedForecast,
    roughness_length_m: f64,
    factor: LeadTimeFactor,
    /// Per member, per period.
    cases: Vec<Vec<Case>>,
    /// The distinct plan requests.
    plans: Vec<PlanRequest>,
    /// The first period of each (its time as written), for errors.
    plan_times: Vec<String>,
}

impl Prepared {
    /// Distinct plans to run.
    pub fn plan_count(&self) -> usize {
        self.plans.len()
    }
    /// Per distinct plan, whether it runs in full: those of the first
    /// member's periods; the others are verdicts only.
    fn in_full(&self) -> Vec<bool> {
        let mut full = vec![false; self.plans.len()];
        for c in self.cases.first().into_iter().flatten() {
            full[c.plan] = true;
        }
        full
    }
    /// Distinct plans run in full ([`Self::in_full`]).
    pub fn full_plan_count(&self) -> usize {
        self.in_full().iter().filter(|&&f| f).count()
    }
    /// Periods over all members.
    pub fn period_count(&self) -> usize {
        self.cases.iter().map(Vec::len).sum()
    }
}

fn bounded(field: &str, v: f64, lo: f64, hi: f64) -> Result<f64, InvalidInput> {
    if !(v.is_finite() && (lo..=hi).contains(&v)) {
        return Err(InvalidInput::new(
            field,
            format!("must be between {lo} and {hi}, got {v}"),
        ));
    }
    Ok(v)
}

/// The plan request of the system and target, without a wind.
fn base_plan(req: &WindowsRequest) -> Result<PlanRequest, RequestError> {
    let mut m = Map::new();
    let mut put = |k: &str, v: Value| {
        m.insert(k.to_string(), v);
    };
    put("cable", json(&req.cable));
    put("aerostat", json(&req.aerostat));
    put("winch", json(&req.winch));
    put("target_elevation_m", Value::from(req.target_elevation_m));
    for (k, v) in [
        ("initial_length_m", req.initial_length_m),
        ("gravity_m_s2", req.gravity_m_s2),
        ("lift_reserve_nondim", req.lift_reserve_nondim),
        (
            "required_safety_factor_nondim",
            req.required_safety_factor_nondim,
        ),
        ("min_altitude_m", req.min_altitude_m),
    ] {
        if let Some(v) = v {
            put(k, Value::from(v));
        }
    }
    if let Some(s) = &req.stability {
        put("stability", json(s));
    }
    crate::contract::parse_value(&Value::Object(m))
}

/// A request part as JSON (plain data: never fails).
fn json<T: serde::Serialize>(v: &T) -> Value {
    serde_json::to_value(v).unwrap_or(Value::Null)
}

fn fit_error(p: &RawPeriod, e: FitError) -> InvalidInput {
    let at = format!("forecast.data ({})", p.time);
    match e {
        FitError::NoWind => InvalidInput::new(at, "has no wind speed"),
        FitError::Invalid { what, .. } => {
            InvalidInput::new(at, format!("has a {what} that is not a finite number ≥ 0"))
        }
        FitError::BelowRoughness {
            height_m,
            roughness_length_m,
        } => InvalidInput::new(
            "forecast.roughness_length_m",
            format!(
                "the wind of {} is given at {height_m} m, at or below the roughness length {roughness_length_m} m",
                p.time
            ),
        ),
    }
}

/// The §9 wind of a fitted hour.
fn wind_input(h: &FittedHour, air_density_kg_m3: f64) -> WindInput {
    let flow = match h.flow {
        FittedFlow::Uniform { speed_m_s } => WindFlowInput::Uniform { speed_m_s },
        FittedFlow::PowerLaw {
            coefficient_m_s,
            exponent_nondim,
            reference_height_m,
        } => WindFlowInput::PowerLaw {
            coefficient_m_s,
            exponent_nondim,
            reference_height_m,
        },
        FittedFlow::LogLaw {
            speed_m_s,
            reference_height_m,
            roughness_length_m,
        } => WindFlowInput::LogLaw {
            speed_m_s,
            reference_height_m,
            roughness_length_m,
        },
    };
    WindInput {
        flow,
        air_density_kg_m3,
        gust: h.gust_at_reference_m_s.map(|g| GustInput {
            gust_m_s: Some(g),
            ..Default::default()
        }),
    }
}

/// Parses and checks a request and lists its distinct plans.
pub fn prepare(req: &WindowsRequest) -> Result<Prepared, RequestError> {
    let base = base_plan(req)?;
    bounded("operation_s", req.operation_s, 0.0, 1e7)?;
    if let Some(h) = &req.haul_down {
        bounded(
            "haul_down.max_operating_wind_m_s",
            h.max_operating_wind_m_s,
            f64::MIN_POSITIVE,
            200.0,
        )?;
        if let Some(g) = h.max_gust_m_s {
            bounded("haul_down.max_gust_m_s", g, f64::MIN_POSITIVE, 200.0)?;
        }
    }
    let factor = match &req.lead_time_factor {
        None => LeadTimeFactor::default(),
        Some(f) => LeadTimeFactor {
            per_hour: bounded(
                "lead_time_factor.per_hour_nondim",
                f.per_hour_nondim,
                0.0,
                1.0,
            )?,
            floor: bounded("lead_time_factor.min_nondim", f.min_nondim, 0.0, 1.0)?,
        },
    };
    let z0 = bounded(
        "forecast.roughness_length_m",
        req.forecast
            .roughness_length_m
            .unwrap_or(DEFAULT_ROUGHNESS_LENGTH_M),
        1e-6,
        10.0,
    )?;
    let rho = match req.wind.as_ref().and_then(|w| w.air_density_kg_m3) {
        Some(r) => bounded("wind.air_density_kg_m3", r, f64::MIN_POSITIVE, 5.0)?,
        None => 1.225,
    };
    let forecast = parse_forecast(&req.forecast)?;
    let target = req.target_elevation_m;
    let mut keys: HashMap<String, usize> = HashMap::new();
    let mut plans = Vec::new();
    let mut plan_times = Vec::new();
    let mut cases = Vec::with_capacity(forecast.members.len());
    let mut calm_gusts: Vec<String> = Vec::new();
    let mut low_gusts: Vec<String> = Vec::new();
    let mut clamped: Vec<String> = Vec::new();
    for member in &forecast.members {
        let mut mc = Vec::with_capacity(member.periods.len());
        for p in &member.periods {
            let fitted = fit_hour(&p.winds, p.gust, z0).map_err(|e| fit_error(p, e))?;
            if p.gust.is_some_and(|g| g.1 > 0.0) && fitted.gust_at_reference_m_s.is_none() {
                calm_gusts.push(format!("{} {}", member.name, p.time));
            }
            if fitted.gust_below_mean {
                low_gusts.push(format!("{} {}", member.name, p.time));
            }
            if fitted.exponent_clamped {
                clamped.push(format!("{} {}", member.name, p.time));
            }
            let wind = wind_input(&fitted, rho);
            let u_t = fitted.flow.speed_m_s(target);
            let g_t = match (fitted.gust_ratio_nondim, fitted.gust_at_reference_m_s) {
                (Some(r), _) => Some(r * u_t),
                (None, Some(g)) => Some(g),
                (None, None) => None,
            };
            let haul_down = match &req.haul_down {
                Some(h) => HaulDownInput {
                    forecast: vec![WindForecastPointInput {
                        time_s: 0.0,
                        wind_speed_m_s: u_t,
                        gust_m_s: h.max_gust_m_s.map(|_| g_t.unwrap_or(u_t)),
                    }],
                    source: None,
                    max_operating_wind_m_s: h.max_operating_wind_m_s,
                    max_gust_m_s: h.max_gust_m_s,
                },
                None => HaulDownInput {
                    forecast: vec![WindForecastPointInput {
                        time_s: 0.0,
                        wind_speed_m_s: u_t.min(NO_LIMIT_M_S),
                        gust_m_s: None,
                    }],
                    source: None,
                    max_operating_wind_m_s: NO_LIMIT_M_S,
                    max_gust_m_s: None,
                },
            };
            let key = serde_json::to_string(&(&wind, &haul_down)).unwrap_or_default();
            let plan = *keys.entry(key).or_insert_with(|| {
                let mut r = base.clone();
                r.wind = Some(wind.clone());
                r.haul_down = Some(haul_down);
                plans.push(r);
                plan_times.push(p.time.clone());
                plans.len() - 1
            });
            mc.push(Case {
                wind,
                wind_at_target_m_s: u_t,
                gust_at_target_m_s: g_t,
                plan,
            });
        }
        cases.push(mc);
    }
    let mut forecast = forecast;
    if !calm_gusts.is_empty() {
        forecast.notes.push(format!(
            "a gust over a calm period is left out (the §9 gust scales the mean flow, which is zero): {}",
            calm_gusts.join(", ")
        ));
    }
    if !low_gusts.is_empty() {
        forecast.notes.push(format!(
            "a gust below the mean wind at its height is taken as the mean (gust ratio 1): {}",
            low_gusts.join(", ")
        ));
    }
    if !clamped.is_empty() {
        forecast.notes.push(format!(
            "the power law fitted through the heights had an exponent outside [0, 2], brought to its nearer end (the speeds refitted): {}",
            clamped.join(", ")
        ));
    }
    Ok(Prepared {
        forecast,
        roughness_length_m: z0,
        factor,
        cases,
        plans,
        plan_times,
    })
}

/// Cancellation passed on, progress counted in plans.
struct PlanProgress<'a> {
    outer: &'a dyn Progress,
}

impl Progress for PlanProgress<'_> {
    fn report(&self, _: usize, _: usize) {}
    fn cancelled(&self) -> bool {
        self.outer.cancelled()
    }
}

/// One distinct plan's answer: its verdict, and `/plan`'s whole answer
/// when a period of the first member (the one whose hours are reported)
/// uses it.
struct Planned {
    verdict: PlanVerdict,
    full: Option<PlanResponse>,
}

impl Planned {
    fn from_full(plan: PlanResponse) -> Self {
        Self {
            verdict: PlanVerdict {
                go: plan.go,
                duration_s: plan.duration_s,
                haul_down_s: plan.haul_down.as_ref().map(|h| h.retrieval_duration_s),
                max_altitude_m: max_altitude(&plan),
            },
            full: Some(plan),
        }
    }
}

/// Runs the distinct plans on rayon, in their order: in full those the
/// first member uses, the verdict only ([`plan_verdict`], the same `go`,
/// durations and altitude) for the others.
fn run_plans(prepared: &Prepared, progress: &dyn Progress) -> Result<Vec<Planned>, RequestError> {
    let done = AtomicUsize::new(0);
    let total = prepared.plans.len();
    let quiet = PlanProgress { outer: progress };
    let full = prepared.in_full();
    prepared
        .plans
        .par_iter()
        .zip(&prepared.plan_times)
        .zip(&full)
        .map(|((r, time), &full)| {
            if progress.cancelled() {
                return Err(RequestError::Cancelled);
            }
            let out = if full {
                crate::contract::plan::plan(r, &quiet).map(Planned::from_full)
            } else {
                plan_verdict(r, &quiet).map(|verdict| Planned {
                    verdict,
                    full: None,
                })
            };
            let out = out.map_err(|e| match e {
                RequestError::Invalid(InvalidInput { field, reason }) => {
                    RequestError::Invalid(InvalidInput {
                        field,
                        reason: format!("{reason} (the wind of the forecast period {time})"),
                    })
                }
                other => other,
            });
            progress.report(done.fetch_add(1, Ordering::Relaxed) + 1, total);
            out
        })
        .collect()
}

/// One member's period as judged.
struct Judged {
    go: bool,
    in_limits: bool,
    max_altitude_m: f64,
    period: Period,
}

/// `/plan`'s `go` for the request: with `haul_down`, the plan's own;
/// without it, whether a schedule exists (the internal haul-down, asked
/// only for its duration, does not decide).
fn go_of(req: &WindowsRequest, v: &PlanVerdict) -> bool {
    if req.haul_down.is_some() {
        v.go
    } else {
        v.duration_s.is_some()
    }
}

fn judge(
    req: &WindowsRequest,
    prepared: &Prepared,
    p: &RawPeriod,
    c: &Case,
    plan: &PlanVerdict,
) -> (Judged, f64) {
    let alpha = prepared.factor.at(p.start_s - prepared.forecast.origin_s);
    let within = req.haul_down.as_ref().is_none_or(|h| {
        c.wind_at_target_m_s <= alpha * h.max_operating_wind_m_s
            && h.max_gust_m_s
                .is_none_or(|g| c.gust_at_target_m_s.unwrap_or(c.wind_at_target_m_s) <= alpha * g)
    });
    let go = go_of(req, plan);
    let durations = plan.duration_s.zip(plan.haul_down_s).map(|(d, h)| d + h);
    let in_limits = go && within && durations.is_some();
    (
        Judged {
            go,
            in_limits,
            max_altitude_m: plan.max_altitude_m,
            period: Period {
                start_s: p.start_s,
                end_s: p.end_s,
                ok: in_limits,
                deploy_and_haul_down_s: durations.unwrap_or(f64::INFINITY),
            },
        },
        alpha,
    )
}

/// `/plan`'s highest reachable altitude: `wind.reachable_altitude_m`, in calm air its lift limit.
fn max_altitude(plan: &PlanResponse) -> f64 {
    plan.wind
        .as_ref()
        .map_or(plan.limits.lift_limit_m, |w| w.reachable_altitude_m)
}

/// The plan's reason; without `haul_down` asked, with the internal
/// haul-down's clause taken out (it runs up to the gust's clause or the
/// end) and the verdict `/plan` gives without it.
fn reason(req: &WindowsRequest, plan: &PlanResponse) -> String {
    if req.haul_down.is_some() {
        return plan.reason.clone();
    }
    let mut r = plan.reason.clone();
    if let Some(at) = r.find("; haul-down: ") {
        let end = r[at + 1..]
            .find("; in the gust (")
            .map_or(r.len(), |e| at + 1 + e);
        r.replace_range(at..end, "");
    }
    if plan.feasible && !plan.go {
        r = r.replacen("no-go: ", "go: ", 1);
    }
    r
}

/// Answers a windows request.
pub fn windows(
    req: &WindowsRequest,
    progress: &dyn Progress,
) -> Result<WindowsResponse, RequestError> {
    let started = Instant::now();
    let prepared = prepare(req)?;
    answer(req, &prepared, progress, started)
}

/// Answers a prepared request.
pub fn answer(
    req: &WindowsRequest,
    prepared: &Prepared,
    progress: &dyn Progress,
    started: Instant,
) -> Result<WindowsResponse, RequestError> {
    let plans = run_plans(prepared, progress)?;
    let f = &prepared.forecast;
    let mut judged: Vec<Vec<Judged>> = Vec::with_capacity(f.members.len());
    let mut first: Vec<(Judged, f64)> = Vec::new();
    for (k, (member, cases)) in f.members.iter().zip(&prepared.cases).enumerate() {
        let mut js = Vec::with_capacity(cases.len());
        for (p, c) in member.periods.iter().zip(cases) {
            let (j, alpha) = judge(req, prepared, p, c, &plans[c.plan].verdict);
            if k == 0 {
                first.push((
                    Judged {
                        go: j.go,
                        in_limits: j.in_limits,
                        max_altitude_m: j.max_altitude_m,
                        period: j.period,
                    },
                    alpha,
                ));
            }
            js.push(j);
        }
        judged.push(js);
    }
    let ensemble = f.members.len() > 1;
    let member_windows: Vec<Vec<Window>> = judged
        .iter()
        .map(|js| {
            let periods: Vec<Period> = js.iter().map(|j| j.period).collect();
            find_windows(&periods, req.operation_s)
        })
        .collect();
    // Members' periods by start time (members may lack hours).
    let by_start: Vec<HashMap<u64, &Judged>> = judged
        .iter()
        .map(|js| js.iter().map(|j| (j.period.start_s.to_bits(), j)).collect())
        .collect();
    let control = &f.members[0];
    let mut hours = Vec::with_capacity(control.periods.len());
    for ((p, c), (j, alpha)) in control.periods.iter().zip(&prepared.cases[0]).zip(&first) {
        // The first member's plans ran in full ([`run_plans`]); were one
        // not, it is planned here rather than trusted.
        let planned_here;
        let plan = match &plans[c.plan].full {
            Some(full) => full,
            None => {
                planned_here = crate::contract::plan::plan(&prepared.plans[c.plan], progress)?;
                &planned_here
            }
        };
        let mut h = WindowsHourOutput {
            time: p.time.clone(),
            end: f.style.format(p.end_s),
            lead_time_s: p.start_s - f.origin_s,
            group: p.group.clone(),
            wind: c.wind.clone(),
            verdict: if j.go { "go" } else { "no-go" }.into(),
            reason: reason(req, plan),
            max_altitude_m: j.max_altitude_m,
            peak_tension_n: plan.limits.peak_tension_n,
            safety_factor_nondim: plan.limits.min_safety_factor_nondim,
            deployment_s: plan.duration_s,
            haul_down_s: plan.haul_down.as_ref().map(|h| h.retrieval_duration_s),
            wind_at_target_m_s: c.wind_at_target_m_s,
            gust_at_target_m_s: c.gust_at_target_m_s,
            limit_factor_nondim: *alpha,
            in_window_limits: j.in_limits,
            probability_go: None,
            probability_go_low: None,
            probability_go_high: None,
            max_altitude_p10_m: None,
            max_altitude_p50_m: None,
            max_altitude_p90_m: None,
        };
        if ensemble {
            let key = p.start_s.to_bits();
            let members: Vec<&Judged> = by_start
                .iter()
                .filter_map(|m| m.get(&key).copied())
                .collect();
            let go: Vec<bool> = members.iter().map(|m| m.go).collect();
            let s = share_go(&go);
            let alts: Vec<f64> = members.iter().map(|m| m.max_altitude_m).collect();
            let [p10, p50, p90] = deciles_10_50_90(&alts);
            h.probability_go = Some(s.value);
            h.probability_go_low = Some(s.low);
            h.probability_go_high = Some(s.high);
            h.max_altitude_p10_m = Some(p10);
            h.max_altitude_p50_m = Some(p50);
            h.max_altitude_p90_m = Some(p90);
        }
        hours.push(h);
    }
    let windows = member_windows[0]
        .iter()
        .map(|w| WindowOutput {
            start: f.style.format(w.start_s),
            end: f.style.format(w.end_s),
            latest_launch: f.style.format(w.latest_launch_s),
            duration_s: w.end_s - w.start_s,
            required_s: w.required_s,
            probability: ensemble.then(|| {
                let n = member_windows
                    .iter()
                    .filter(|mw| supports(mw, w.start_s, w.required_s))
                    .count();
                n as f64 / member_windows.len() as f64
            }),
        })
        .collect();
    Ok(WindowsResponse {
        hours,
        windows,
        members: f.members.len(),
        format: req.forecast.format,
        roughness_length_m: prepared.roughness_length_m,
        lead_time_factor: LeadTimeFactorOutput {
            per_hour_nondim: prepared.factor.per_hour,
            min_nondim: prepared.factor.floor,
            explanation: format!(
                "the haul_down limits of a window are multiplied by α = max({}, 1 − {} × lead hours), the lead \
                 time counted from the forecast's first time (a TAF's issue): the alpha factor of offshore weather \
                 windows (DNV-ST-N001), with this tool's stated default, not DNV's table",
                prepared.factor.floor, prepared.factor.per_hour
            ),
        },
        method: format!(
            "each period's speeds at their heights: a power law fitted through two or more (least squares in \
             ln z, ln U, exponent within [0, 2]), a log law of roughness {} m through one, uniform when calm; \
             the gust the mean times the period's gust ratio at its height; each distinct wind planned once by \
             /plan's own code (the first member's in full, the other members' verdict only: the same go, \
             durations and altitude)",
            prepared.roughness_length_m
        ),
        notes: f.notes.clone(),
        plans_computed: plans.len(),
        compute_time_s: started.elapsed().as_secs_f64(),
    })
}
