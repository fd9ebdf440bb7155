//! Runs a plan request, step by step: validation ([`super::validate`]),
//! the static limits of its ends (the target out of reach in wind, the
//! floor), the schedule (the speed-profile pass of
//! [`crate::numerics::plan::schedule`], slowed for an amplification limit
//! or re-planned after a failed GE check) with its transient check, the
//! schedule's limits and margins (mean and gust), the orientation figures
//! (constant rate, bound, oscillation growth, retrieval), the haul-down
//! deadline ([`crate::numerics::plan::deadline`]: the earlier of the
//! wind's and the gust's exceedance; no-go when no haul-down can be
//! planned) and the verdict. [`plan_verdict`] runs the steps that decide
//! and skips those that only report.

use std::time::Instant;

use crate::contract::error::{Progress, RequestError};
use crate::contract::plan::dto::*;
use crate::contract::plan::ge::*;
use crate::contract::plan::output::*;
use crate::contract::plan::validate::{Validated, validate};
use crate::contract::system::output::groups;
use crate::numerics::plan::air::{Air, calm_tensions_n};
use crate::numerics::plan::deadline::{self, ExceededBy};
use crate::numerics::plan::ge_stability::ScheduleCheck;
use crate::numerics::plan::retrieval::{self, TransientCheck};
use crate::numerics::plan::schedule::{self, PlanOptions, PlanOutcome, Schedule};
use crate::numerics::plan::{BindingLimit, PlanProblem, STABILITY_MARGIN};
use crate::numerics::string::transient::{Observer, TransientError};
use crate::numerics::tether::gust::dynamic_tension_n;
use crate::numerics::tether::{Equilibrium, EquilibriumConfig};

pub use crate::contract::plan::validate::{MAX_PLAN_SAMPLES, MIN_TARGET_M, validate_plan};

/// Progress of the contract seen as a numerics observer.
struct ProgressObserver<'a>(&'a dyn Progress);

impl Observer for ProgressObserver<'_> {
    fn report(&self, done: usize, total: usize) {
        self.0.report(done, total);
    }
    fn cancelled(&self) -> bool {
        self.0.cancelled()
    }
}

/// An observer that forwards cancellation only: the transient check of a
/// re-planned schedule, after the first one already reported its progress
/// to the end (progress never goes back).
struct CancelOnly<'a>(&'a dyn Observer);

impl Observer for CancelOnly<'_> {
    fn cancelled(&self) -> bool {
        self.0.cancelled()
    }
}

fn from_transient(e: TransientError) -> RequestError {
    match e {
        TransientError::Invalid(e) => RequestError::Invalid(e),
        TransientError::Qep(e) => RequestError::Numerical(e),
    }
}

/// What every answer of one request shares, feasible or not.
struct Context<'a> {
    req: &'a PlanRequest,
    v: &'a Validated,
    p: PlanProblem,
    started: Instant,
    direction: &'static str,
    inputs: serde_json::Value,
    tension_checked: bool,
    unchecked_note: &'static str,
    wind_out: Option<PlanWindOutput>,
}

impl<'a> Context<'a> {
    fn new(req: &'a PlanRequest, v: &'a Validated, started: Instant) -> Self {
        Self::with_outputs(req, v, started, true)
    }

    /// With `outputs` false, the context of a verdict only
    /// ([`plan_verdict`]): no echoed inputs and no wind figures, which only
    /// the full answer reports.
    fn with_outputs(
        req: &'a PlanRequest,
        v: &'a Validated,
        started: Instant,
        outputs: bool,
    ) -> Self {
        let p = v.problem;
        let tension_checked = v.breaking_strength_n.is_some();
        Self {
            req,
            v,
            p,
            started,
            direction: if p.direction() < 0.0 {
                "retrieval"
            } else {
                "deployment"
            },
            inputs: if outputs {
                serde_json::to_value(req).expect("requests serialise")
            } else {
                serde_json::Value::Null
            },
            tension_checked,
            unchecked_note: if tension_checked {
                ""
            } else {
                "; tension NOT checked (no cable.breaking_strength_n)"
            },
            wind_out: if outputs { wind_output(v, &p) } else { None },
        }
    }

    fn retrieving(&self) -> bool {
        self.p.direction() < 0.0
    }

    /// After a gust tension limit judged at its dynamic value: what the
    /// factor did (empty otherwise).
    fn dynamic_gust_note(&self, b: BindingLimit) -> String {
        match (&b, self.v.gust.as_ref()) {
            (BindingLimit::GustTension { .. }, Some(g)) if g.tension_factor != 1.0 => format!(
                " (the static gust tension's increment over calm air × {:.2}, the dynamic factor)",
                g.tension_factor
            ),
            _ => String::new(),
        }
    }

    /// The answer when no schedule exists.
    fn infeasible(&self, b: BindingLimit, limits: PlanLimitsOutput) -> PlanResponse {
        let opts = &self.v.options;
        PlanResponse {
            feasible: false,
            go: false,
            direction: self.direction.into(),
            duration_s: None,
            binding_limit: Some(b.name().into()),
            reason: format!(
                "no-go: {}{}{}",
                b.reason(self.p.lift_reserve),
                self.dynamic_gust_note(b),
                self.unchecked_note
            ),
            tension_checked: self.tension_checked,
            schedule: vec![],
            phases: vec![],
            constant_rate: None,
            bound: None,
            transient_check: None,
            oscillation: None,
            retrieval: None,
            haul_down: None,
            limits,
            wind: self.wind_out.clone(),
            jerk: None,
            ge_stability: ge_output(&self.p, &opts.air, None, 0),
            method: method(opts),
            compute_time_s: self.started.elapsed().as_secs_f64(),
            inputs: self.inputs.clone(),
            groups: groups(&self.v.model.system),
        }
    }
}

/// The equilibrium at the target with the full buoyancy, in the mean wind
/// or (`gust`) in the gust; `None` in calm air, without gusts, or when the
/// target is out of reach.
fn target_equilibrium(v: &Validated, p: &PlanProblem, gust: bool) -> Option<Equilibrium> {
    let Air::Wind(sw) = &v.options.air else {
        return None;
    };
    if v.wind.as_ref()?.unreachable.is_some() {
        return None;
    }
    let (s, b, l) = (&p.system, p.system.net_buoyancy_n, p.target_length_m);
    let problem = if gust {
        sw.gust_problem(s, b, l)?
    } else {
        sw.problem(s, b, l)
    };
    problem.solve(&EquilibriumConfig::default()).ok()
}

/// The plan in wind: the target's length, blow-down and tensions, in the
/// mean wind and in the gust side by side.
fn wind_output(v: &Validated, p: &PlanProblem) -> Option<PlanWindOutput> {
    let w = v.wind.as_ref()?;
    let at_target = target_equilibrium(v, p, false);
    let gust = v.gust.as_ref().map(|g| {
        let e = target_equilibrium(v, p, true);
        let (calm_winch, calm_max) = calm_tensions_n(&p.system, p.target_length_m);
        let dynamic = |t: f64, calm: f64| dynamic_tension_n(t, calm, g.tension_factor);
        PlanGustOutput {
            gust_factor_nondim: g.factor,
            reference_height_m: g.reference_height_m,
            reference_speed_m_s: g.reference_speed_m_s,
            target_altitude_m: e.as_ref().map(|e| e.altitude_m),
            target_downwind_m: e.as_ref().map(|e| e.downwind_m),
            blowdown_angle_deg: e.as_ref().map(|e| e.blowdown_angle_deg),
            target_winch_tension_n: e.as_ref().map(|e| dynamic(e.winch_tension_n, calm_winch)),
            target_max_tension_n: e.as_ref().map(|e| dynamic(e.max_tension_n, calm_max)),
            static_target_max_tension_n: e.as_ref().map(|e| e.max_tension_n),
            target_safety_factor_nondim: e.as_ref().and_then(|e| {
                e.safety_factor
                    .map(|sf| sf * e.max_tension_n / dynamic(e.max_tension_n, calm_max))
            }),
            dynamic_tension_factor_nondim: g.tension_factor,
            dynamic_tension_note: g.dynamic_tension_note(),
            reachable_altitude_m: v
                .options
                .air
                .gust_rest_loads(p, w.lift_limit_m)
                .map_or(f64::NAN, |r| r.altitude_m),
        }
    });
    Some(PlanWindOutput {
        target_length_m: w.unreachable.is_none().then_some(p.target_length_m),
        blowdown_angle_deg: at_target.as_ref().map(|e| e.blowdown_angle_deg),
        target_downwind_m: at_target.as_ref().map(|e| e.downwind_m),
        lift_limit_m: w.lift_limit_m,
        reachable_altitude_m: w.reachable_altitude_m,
        stability_criterion: match &v.options.air {
            Air::Wind(sw) => sw.criterion_name.to_string(),
            Air::Calm => String::new(),
        },
        target_winch_tension_n: at_target.as_ref().map(|e| e.winch_tension_n),
        target_max_tension_n: at_target.as_ref().map(|e| e.max_tension_n),
        gust,
    })
}

/// The limits before any schedule: the tensions at rest at the end of the
/// plan (or the reachable limit), which the answer reports even when no
/// schedule exists.
fn rest_limits(v: &Validated, p: &PlanProblem) -> PlanLimitsOutput {
    let air = &v.options.air;
    let peak = |top: f64, winch: f64| {
        let t = top.max(winch);
        t.is_finite().then_some(t)
    };
    let rest = air.rest_loads(p, p.target_length_m);
    let rest_peak = peak(rest.top_tension_n, rest.winch_tension_n);
    let gust_peak = air
        .gust_rest_loads(p, p.target_length_m)
        .and_then(|g| peak(g.top_tension_n, g.winch_tension_n));
    PlanLimitsOutput {
        reserve_buoyancy_n: p.reserve_buoyancy_n(),
        lift_limit_m: v.wind.as_ref().map_or(p.lift_limit_m(), |w| w.lift_limit_m),
        allowable_tension_n: p.allowable_tension_n,
        stability_margin_n: STABILITY_MARGIN * p.reserve_buoyancy_n(),
        min_stability_margin_m_s: None,
        min_effective_tension_margin_n: None,
        peak_tension_n: rest_peak,
        min_safety_factor_nondim: v.breaking_strength_n.zip(rest_peak).map(|(b, t)| b / t),
        gust_peak_tension_n: gust_peak,
        gust_min_safety_factor_nondim: v.breaking_strength_n.zip(gust_peak).map(|(b, t)| b / t),
        min_altitude_m: v.min_altitude_m,
    }
}

/// The static limits of the plan's end: a target out of reach in wind,
/// then the floor (`min_altitude_m`), judged in the gust when there are
/// gusts (the lowest the aerostat is blown down to).
fn end_binding(v: &Validated, p: &PlanProblem) -> Option<BindingLimit> {
    if let Some(b) = v.wind.as_ref().and_then(|w| w.unreachable.clone()) {
        return Some(b);
    }
    let floor = v.min_altitude_m?;
    let l = p.target_length_m;
    let (altitude_m, in_gust) = match v.options.air.gust_rest_loads(p, l) {
        Some(g) => (g.altitude_m, true),
        None => (v.options.air.rest_loads(p, l).altitude_m, false),
    };
    // NaN (no equilibrium) is below any floor.
    (!(altitude_m >= floor)).then_some(BindingLimit::MinAltitude {
        altitude_m,
        floor_m: floor,
        in_gust,
    })
}

/// The schedule found and how.
struct Found {
    schedule: Schedule,
    /// The transient check; `None` when not asked ([`plan_verdict`]: it
    /// reports, it does not decide).
    check: Option<TransientCheck>,
    /// Rate limit the plan used (m/s).
    rate_used: f64,
    /// Slowed below the winch rate for an amplification limit.
    slowed: bool,
    ge_check: Option<ScheduleCheck>,
    ge_tightenings: usize,
    /// The options after the GE tightenings (`None`: the request's).
    tightened: Option<PlanOptions>,
}

/// The schedule: the retrieval slowed for an amplification limit, or the
/// fastest pass (re-planned with a lowered GE criterion while a sample of
/// the GE check fails), with its transient check; `Err` the binding limit
/// when none exists.
fn find_schedule(
    cx: &Context,
    observer: &ProgressObserver,
    with_transient: bool,
) -> Result<Result<Found, BindingLimit>, RequestError> {
    let (req, v, p) = (cx.req, cx.v, &cx.p);
    let opts = &v.options;
    let mut found = match (cx.retrieving(), v.amplification_limit) {
        (true, Some(limit)) => {
            match retrieval::bounded_retrieval_with(
                p,
                &v.model,
                limit,
                req.disturbance_tip_deflection_m,
                observer,
                opts,
            )
            .map_err(from_transient)?
            {
                Ok(b) => Found {
                    schedule: b.schedule,
                    check: Some(b.check),
                    rate_used: b.rate_limit_m_s,
                    slowed: b.slowed,
                    ge_check: None,
                    ge_tightenings: 0,
                    tightened: None,
                },
                Err(binding) => {
                    // A static limit takes precedence over the amplification.
                    if let PlanOutcome::Infeasible(b) = schedule::fastest_with(p, opts) {
                        return Ok(Err(b));
                    }
                    return Ok(Err(binding));
                }
            }
        }
        _ => {
            let mut tightened = opts.clone();
            let mut tightenings = 0;
            let mut ge_check = None;
            let (s, check) = loop {
                let s = match schedule::fastest_with(p, &tightened) {
                    PlanOutcome::Infeasible(b) => return Ok(Err(b)),
                    PlanOutcome::Feasible(s) => s,
                };
                // The GE check (on rayon) and the transient check (one
                // thread) side by side; a tightening drops the transient.
                let quiet = CancelOnly(observer);
                let (chk, check) = rayon::join(
                    || ge_check_of(&tightened.air, &s, ge_check_count(req)),
                    || {
                        with_transient
                            .then(|| {
                                retrieval::check_transient(
                                    &v.model,
                                    &s,
                                    req.disturbance_tip_deflection_m,
                                    if tightenings == 0 { observer } else { &quiet },
                                )
                            })
                            .transpose()
                    },
                );
                let Some(chk) = chk else {
                    break (s, check);
                };
                if chk.failed == 0 {
                    ge_check = Some(chk);
                    break (s, check);
                }
                if tightenings >= MAX_GE_TIGHTENINGS {
                    return Ok(Err(ge_binding(&chk)));
                }
                tightenings += 1;
                let offset = 0.02 * 4f64.powi(tightenings as i32 - 1) * p.reserve_buoyancy_n();
                if let Air::Wind(w) = &mut tightened.air
                    && let Some(ge) = &w.ge
                {
                    w.ge = Some(ge.with_offset(offset));
                }
            };
            let check = check.map_err(from_transient)?;
            Found {
                schedule: s,
                check,
                rate_used: p.winch.max_rate_m_s,
                slowed: false,
                ge_check,
                ge_tightenings: tightenings,
                tightened: Some(tightened),
            }
        }
    };
    if found.ge_check.is_none()
        && let Some(chk) = ge_check_of(&opts.air, &found.schedule, ge_check_count(req))
    {
        // The amplification-bounded retrieval: checked, not tightened.
        if chk.failed > 0 {
            return Ok(Err(ge_binding(&chk)));
        }
        found.ge_check = Some(chk);
    }
    Ok(Ok(found))
}

/// The limits over the schedule's samples (mean, and gust with gusts).
fn schedule_limits(
    base: PlanLimitsOutput,
    samples: &[PlanSampleOutput],
    breaking_strength_n: Option<f64>,
) -> PlanLimitsOutput {
    let min_of =
        |f: fn(&PlanSampleOutput) -> f64| samples.iter().map(f).fold(f64::INFINITY, f64::min);
    let peak = samples
        .iter()
        .map(|s| s.max_tension_n)
        .fold(f64::NEG_INFINITY, f64::max);
    let gust_peak = samples
        .iter()
        .map(|s| s.gust_max_tension_n)
        .try_fold(f64::NEG_INFINITY, |a, t| t.map(|t| a.max(t)));
    PlanLimitsOutput {
        min_stability_margin_m_s: Some(min_of(|s| s.stability_margin_m_s)),
        min_effective_tension_margin_n: Some(min_of(|s| s.effective_tension_margin_n)),
        peak_tension_n: Some(peak),
        min_safety_factor_nondim: breaking_strength_n.map(|b| b / peak),
        gust_peak_tension_n: gust_peak,
        gust_min_safety_factor_nondim: breaking_strength_n.zip(gust_peak).map(|(b, t)| b / t),
        ..base
    }
}

/// The best constant-rate plan with the same limits.
fn constant_rate_output(
    p: &PlanProblem,
    opts: &PlanOptions,
    found: &Found,
) -> Option<ConstantRateOutput> {
    let mut pc = *p;
    pc.winch.max_rate_m_s = found.rate_used;
    let d = found.schedule.duration_s;
    schedule::best_constant_rate_with(&pc, opts).map(|c| ConstantRateOutput {
        rate_m_s: c.rate_m_s,
        duration_s: c.duration_s,
        time_saved_s: c.duration_s - d,
        time_saved_fraction_nondim: (c.duration_s - d) / c.duration_s,
    })
}

/// The SPEC §7 orientation bound and why the plan differs from it.
fn bound_output(p: &PlanProblem, opts: &PlanOptions, found: &Found) -> Option<PlanBoundOutput> {
    schedule::static_ceiling_bound_s_with(p, &opts.air).map(|b| {
        let excess = found.schedule.duration_s / b - 1.0;
        let explanation = if excess.abs() <= 1e-3 {
            "the plan meets the bound: the stability ceiling does not bind during the acceleration phases".to_string()
        } else if excess < 0.0 {
            format!(
                "the plan is {:.1} % faster than the bound: braking raises the roller tension by (m + ρA L)|L̈|, \
                 so rates above the static ceiling are stable while slowing down",
                -100.0 * excess
            )
        } else if found.slowed {
            format!(
                "the plan is {:.1} % slower than the bound: the winch was slowed to keep the oscillation growth within the limit",
                100.0 * excess
            )
        } else {
            format!(
                "the plan is {:.1} % slower than the bound: speeding up lowers the roller tension by (m + ρA L)L̈ \
                 (the bound ignores it), the tension rating limits braking, and ε keeps a margin",
                100.0 * excess
            )
        };
        PlanBoundOutput {
            duration_s: b,
            plan_excess_fraction_nondim: excess,
            explanation,
        }
    })
}

/// The oscillation growth over the plan (WKB and the transient run).
fn oscillation_output(v: &Validated, p: &PlanProblem, found: &Found) -> OscillationOutput {
    let (l_start, l_end) = (p.system.initial_length_m, p.target_length_m);
    let wkb = retrieval::wkb_growth(&v.model, l_start, l_end);
    OscillationOutput {
        wkb_amplification_nondim: wkb.map(|w| w.amplitude),
        wkb_fe_mode_amplification_nondim: retrieval::wkb_growth_fe(&v.model, l_start, l_end),
        wkb_energy_amplification_nondim: wkb.map(|w| w.energy),
        transient_amplification_nondim: found.check.as_ref().map(|c| c.amplification),
        max_amplification_nondim: v.amplification_limit,
        slowed_for_amplification: found.slowed,
        rate_limit_used_m_s: found.rate_used,
    }
}

/// Retrieval only: the tension rise from hauling in.
fn retrieval_output(cx: &Context, found: &Found) -> Option<RetrievalOutput> {
    let p = &cx.p;
    cx.retrieving().then(|| {
        let samples = found.schedule.samples(cx.req.samples);
        let (rise, peak) = retrieval::tension_rise_n(p, &samples);
        RetrievalOutput {
            tension_rise_n: rise,
            peak_winch_tension_n: peak,
            initial_winch_tension_n: p.winch_tension_n(p.system.initial_length_m, 0.0),
            note: "Shortening is unstable at every instant (the symmetric part of the damping is −(|L̇|/L)·M: \
                   negative), so a retrieval has no stability verdict; the plan keeps the roller tension positive \
                   (no divergence) and reports how an oscillation grows."
                .into(),
        }
    })
}

/// The haul-down of a plan.
enum HaulDown {
    /// No forecast: no deadline asked.
    NotAsked,
    Planned(HaulDownOutput),
    /// No safe haul-down schedule exists from `from_m` to `to_m`: the plan
    /// is no-go, since the aerostat could not be brought down.
    Impossible {
        from_m: f64,
        to_m: f64,
        binding: BindingLimit,
    },
}

impl HaulDown {
    /// Whether the haul-down lets the plan go.
    fn go(&self) -> bool {
        match self {
            Self::NotAsked => true,
            Self::Planned(h) => h.go,
            Self::Impossible { .. } => false,
        }
    }

    fn output(self) -> Option<HaulDownOutput> {
        match self {
            Self::Planned(h) => Some(h),
            _ => None,
        }
    }
}

/// The haul-down deadline: from the operating altitude down to the lower
/// end, before the wind passes its limit or the gust passes its own,
/// whichever comes first.
fn haul_down_output(cx: &Context, opts: &PlanOptions, found: &Found) -> HaulDown {
    let Some(f) = cx.v.forecast.as_ref() else {
        return HaulDown::NotAsked;
    };
    let p = &cx.p;
    let (l_start, l_end) = (p.system.initial_length_m, p.target_length_m);
    let (high, low) = (l_start.max(l_end), l_start.min(l_end));
    let duration = if cx.retrieving() {
        found.schedule.duration_s
    } else {
        match schedule::fastest_with(&p.between(high, low), opts) {
            PlanOutcome::Feasible(s) => s.duration_s,
            PlanOutcome::Infeasible(binding) => {
                return HaulDown::Impossible {
                    from_m: high,
                    to_m: low,
                    binding,
                };
            }
        }
    };
    let aloft_from = if cx.retrieving() {
        0.0
    } else {
        found.schedule.duration_s
    };
    let gust = f.gust.as_ref().map(|(g, limit)| (g, *limit));
    let (h, by) = deadline::haul_down_with_gusts(&f.mean, f.limit_m_s, gust, duration, aloft_from);
    HaulDown::Planned(HaulDownOutput {
        wind_exceeds_limit_at_s: h.exceeds_at_s,
        retrieval_duration_s: h.retrieval_duration_s,
        from_length_m: high,
        to_length_m: low,
        latest_start_s: h.latest_start_s,
        go: h.go,
        reason: h.reason,
        exceeded_by: by.map(|b| {
            match b {
                ExceededBy::Mean => "mean",
                ExceededBy::Gust => "gust",
            }
            .to_string()
        }),
        gust_exceeds_limit_at_s: gust.and_then(|(g, limit)| g.first_exceedance_s(limit)),
    })
}

/// The go/no-go and its plain-language reason.
fn verdict(
    cx: &Context,
    found: &Found,
    limits: &PlanLimitsOutput,
    haul_down: &HaulDown,
) -> (bool, String) {
    let p = &cx.p;
    let go = haul_down.go();
    let mut reason = format!(
        "{}: {} from {:.1} m to {:.1} m in {:.1} s, stable with a {:.1} % lift reserve at every instant",
        if go { "go" } else { "no-go" },
        cx.direction,
        p.system.initial_length_m,
        p.target_length_m,
        found.schedule.duration_s,
        100.0 * p.lift_reserve
    );
    if let Some(w) = &cx.wind_out
        && let (Some(l), Some(a)) = (w.target_length_m, w.blowdown_angle_deg)
    {
        reason.push_str(&format!(
            " (in this wind {l:.1} m of tether flies the aerostat at {:.1} m, blown down {a:.1}°)",
            cx.req.target_elevation_m
        ));
    }
    if let Some(t) = p.allowable_tension_n {
        reason.push_str(&format!(", tension within {t:.0} N"));
    }
    reason.push_str(cx.unchecked_note);
    match haul_down {
        HaulDown::NotAsked => {}
        HaulDown::Planned(h) => reason.push_str(&format!("; haul-down: {}", h.reason)),
        HaulDown::Impossible {
            from_m,
            to_m,
            binding,
        } => reason.push_str(&format!(
            "; haul-down: no-go: no safe haul-down from {from_m:.1} m to {to_m:.1} m exists in this wind ({})",
            binding.reason(p.lift_reserve)
        )),
    }
    if let Some(g) = cx.wind_out.as_ref().and_then(|w| w.gust.as_ref()) {
        reason.push_str(&format!(
            "; in the gust ({:.1} m/s at {:.0} m, {:.2}× the mean)",
            g.reference_speed_m_s, g.reference_height_m, g.gust_factor_nondim
        ));
        if let Some(a) = g.target_altitude_m {
            reason.push_str(&format!(" the aerostat is blown down to {a:.1} m"));
        }
        if let Some(t) = limits.gust_peak_tension_n {
            reason.push_str(&format!(", peak tension {t:.0} N"));
            if g.dynamic_tension_factor_nondim != 1.0 {
                reason.push_str(&format!(
                    " (the static gust tension's increment over calm air × {:.2}, the dynamic factor)",
                    g.dynamic_tension_factor_nondim
                ));
            }
        }
        if let Some(t) = p.allowable_tension_n {
            reason.push_str(&format!(", within {t:.0} N"));
        }
    }
    (go, reason)
}

/// Answers a plan request.
pub fn plan(req: &PlanRequest, progress: &dyn Progress) -> Result<PlanResponse, RequestError> {
    let started = Instant::now();
    let v = validate(req)?;
    let cx = Context::new(req, &v, started);
    let p = cx.p;
    let limits_base = rest_limits(&v, &p);
    if let Some(b) = end_binding(&v, &p) {
        return Ok(cx.infeasible(b, limits_base));
    }
    let found = match find_schedule(&cx, &ProgressObserver(progress), true)? {
        Ok(f) => f,
        Err(b) => return Ok(cx.infeasible(b, limits_base)),
    };
    let opts = found.tightened.as_ref().unwrap_or(&v.options);
    if progress.cancelled() {
        return Err(RequestError::Cancelled);
    }
    let schedule_out = samples_output(&p, &opts.air, &found.schedule, req.samples);
    let limits = schedule_limits(limits_base, &schedule_out, v.breaking_strength_n);
    let haul_down = haul_down_output(&cx, opts, &found);
    let (go, reason) = verdict(&cx, &found, &limits, &haul_down);
    let sched = &found.schedule;
    Ok(PlanResponse {
        feasible: true,
        go,
        direction: cx.direction.into(),
        duration_s: Some(sched.duration_s),
        binding_limit: None,
        reason,
        tension_checked: cx.tension_checked,
        schedule: schedule_out,
        phases: phases_output(sched),
        constant_rate: constant_rate_output(&p, opts, &found),
        bound: bound_output(&p, opts, &found),
        transient_check: found.check.as_ref().map(check_output),
        oscillation: Some(oscillation_output(&v, &p, &found)),
        retrieval: retrieval_output(&cx, &found),
        haul_down: haul_down.output(),
        limits,
        wind: cx.wind_out.clone(),
        jerk: opts.max_jerk_m_s3.map(|j| JerkOutput {
            max_jerk_m_s3: j,
            peak_jerk_m_s3: peak_jerk(sched),
            averaging_window_s: sched.averaging_window_s,
        }),
        ge_stability: ge_output(&p, &opts.air, found.ge_check.as_ref(), found.ge_tightenings),
        method: method(opts),
        compute_time_s: started.elapsed().as_secs_f64(),
        inputs: cx.inputs.clone(),
        groups: groups(&v.model.system),
    })
}

/// What a plan decides, without the figures only its full answer reports:
/// [`plan_verdict`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanVerdict {
    /// `/plan`'s `go`.
    pub go: bool,
    /// `/plan`'s `duration_s` (s); `None` when infeasible, or when a
    /// haul-down that must already have started decided the verdict first.
    pub duration_s: Option<f64>,
    /// `/plan`'s `haul_down.retrieval_duration_s` (s), under the same terms.
    pub haul_down_s: Option<f64>,
    /// `/plan`'s `wind.reachable_altitude_m`, in calm air its
    /// `limits.lift_limit_m` (m).
    pub max_altitude_m: f64,
}

/// The verdict of [`plan`] by the same code, without what only reports:
/// the schedule's samples and their limits, the transient check (it
/// decides only a retrieval bounded by an amplification limit, which it
/// still runs), the constant-rate plan, the bound, the oscillation
/// growth, the wind figures at the target and the echoed inputs. Its
/// `go`, durations and altitude are `plan`'s bit for bit (the windows'
/// ensemble members, `tests/windows_verdict.rs`).
///
/// One shortcut: a haul-down forecast whose wind or gust is already past
/// its limit at `t = 0` on a path of positive length makes `plan` no-go
/// whatever the schedule (the haul-down should have started `D > 0` s
/// ago, or cannot be planned at all), so no schedule is searched.
pub fn plan_verdict(
    req: &PlanRequest,
    progress: &dyn Progress,
) -> Result<PlanVerdict, RequestError> {
    let started = Instant::now();
    let v = validate(req)?;
    let cx = Context::with_outputs(req, &v, started, false);
    let p = cx.p;
    let max_altitude_m = v
        .wind
        .as_ref()
        .map_or(p.lift_limit_m(), |w| w.reachable_altitude_m);
    let no_go = PlanVerdict {
        go: false,
        duration_s: None,
        haul_down_s: None,
        max_altitude_m,
    };
    if end_binding(&v, &p).is_some() {
        return Ok(no_go);
    }
    if let Some(f) = &v.forecast {
        let gust = f.gust.as_ref().map(|(g, limit)| (g, *limit));
        let now = deadline::first_limit_exceedance(&f.mean, f.limit_m_s, gust)
            .is_some_and(|(t, _)| t <= 0.0);
        if now && p.system.initial_length_m != p.target_length_m {
            return Ok(no_go);
        }
    }
    let found = match find_schedule(&cx, &ProgressObserver(progress), false)? {
        Ok(f) => f,
        Err(_) => return Ok(no_go),
    };
    if progress.cancelled() {
        return Err(RequestError::Cancelled);
    }
    let opts = found.tightened.as_ref().unwrap_or(&v.options);
    let haul_down = haul_down_output(&cx, opts, &found);
    Ok(PlanVerdict {
        go: haul_down.go(),
        duration_s: Some(found.schedule.duration_s),
        haul_down_s: match &haul_down {
            HaulDown::Planned(h) => Some(h.retrieval_duration_s),
            _ => None,
        },
        max_altitude_m,
    })
}
