//! Runs a plan request: validation, the speed-profile pass
//! ([`crate::numerics::plan::schedule`]), the transient check and WKB
//! growth ([`crate::numerics::plan::retrieval`]), the haul-down deadline
//! ([`crate::numerics::plan::deadline`]), and the conversion to SI output.

use std::time::Instant;

use crate::contract::dto::SystemInput;
use crate::contract::plan::dto::*;
use crate::contract::plan::ge::*;
use crate::contract::run::{Progress, RequestError, groups};
use crate::contract::system::WindInput;
use crate::contract::system::validate as system_check;
use crate::numerics::params::{InvalidInput, require_finite, require_positive};
use crate::numerics::plan::air::{Air, SteadyWind};
use crate::numerics::plan::deadline::{self, Forecast};
use crate::numerics::plan::ge_stability::{self as ge_plan, GeCriterion};
use crate::numerics::plan::retrieval::{self, TransientCheck};
use crate::numerics::plan::schedule::{self, PlanOptions, PlanOutcome, Schedule};
use crate::numerics::plan::{BindingLimit, PlanProblem, STABILITY_MARGIN, Winch, validate_jerk};
use crate::numerics::string::StringModel;
use crate::numerics::string::transient::{Observer, RunOutcome, TransientError};
use crate::numerics::tether::EquilibriumConfig;

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

fn from_transient(e: TransientError) -> RequestError {
    match e {
        TransientError::Invalid(e) => RequestError::Invalid(e),
        TransientError::Qep(e) => RequestError::Numerical(e),
    }
}

/// Most schedule samples.
pub const MAX_PLAN_SAMPLES: usize = 10_000;

/// The validated inputs.
struct Validated {
    model: StringModel,
    problem: PlanProblem,
    forecast: Option<(Forecast, f64)>,
    amplification_limit: Option<f64>,
    breaking_strength_n: Option<f64>,
    options: PlanOptions,
    /// In wind: the lift limit (m), the altitude there (m), and the target
    /// altitude when it is out of reach.
    wind: Option<WindTarget>,
}

struct WindTarget {
    lift_limit_m: f64,
    reachable_altitude_m: f64,
    unreachable: Option<BindingLimit>,
}

/// The steady wind of the request, with the tether and aerostat drag data
/// it needs (each refused naming the field when missing).
fn steady_wind(req: &PlanRequest, w: &WindInput) -> Result<SteadyWind, InvalidInput> {
    let profile = w.flow.profile("wind.flow")?;
    let rho = w.air_density()?;
    let cable = req.cable.cable("cable")?;
    let body = req.aerostat.body("aerostat")?;
    Ok(SteadyWind::new(cable, body, profile, rho))
}

/// Shortest target of a plan (m): the shortest length of the system
/// ([`crate::numerics::params::ranges::LENGTH_M`]).
pub const MIN_TARGET_M: f64 = crate::numerics::params::ranges::LENGTH_M.min;

fn bounded(field: &str, value: f64, lo: f64, hi: f64) -> Result<f64, InvalidInput> {
    require_finite(field, value)?;
    if !(lo..=hi).contains(&value) {
        return Err(InvalidInput::new(
            field,
            format!("must be between {lo} and {hi}, got {value}"),
        ));
    }
    Ok(value)
}

fn validate(req: &PlanRequest) -> Result<Validated, InvalidInput> {
    validate_with(req, true)
}

/// `resolve`: find the wind target (equilibria; with the GE criterion its
/// table). Without it (job submission) a GE request's target is only
/// range-checked.
fn validate_with(req: &PlanRequest, resolve: bool) -> Result<Validated, InvalidInput> {
    let system_input = SystemInput {
        cable: req.cable.clone(),
        aerostat: req.aerostat.clone(),
        initial_length_m: req.initial_length_m,
        gravity_m_s2: req.gravity_m_s2,
        model: req.model.clone(),
        numerics: Default::default(),
        wind: None,
        winch: None,
        required_safety_factor_nondim: None,
        lift_reserve_nondim: None,
    };
    let model = system_input.model()?;
    req.winch.check("winch")?;
    let winch = Winch::new(req.winch.max_rate_m_s, req.winch.max_acceleration_m_s2)?;
    let max_jerk_m_s3 = req.winch.max_jerk_m_s3.map(validate_jerk).transpose()?;
    let ge = ge_options(req)?;
    if let Some(w) = &req.wind {
        w.check()?;
    }
    // A wind of zero speed everywhere without drag data is calm air; with
    // them it runs through the wind path (the same plan: tests/verification_plan.rs).
    let wind = req.wind.as_ref().filter(|w| {
        !w.flow.is_calm()
            || (req.cable.cable("cable").is_ok() && req.aerostat.body("aerostat").is_ok())
    });
    let air = match (wind, ge) {
        (Some(w), None) => Air::Wind(Box::new(steady_wind(req, w)?)),
        (None, None) => Air::Calm,
        (w, Some(o)) => {
            let mut sw = match w {
                Some(w) => steady_wind(req, w)?,
                None => calm_wind(model.system.mass_per_length_kg_m),
            };
            sw.ge = Some(GeCriterion::new(o));
            sw.criterion_name = ge_plan::QS_GE_CRITERION;
            Air::Wind(Box::new(sw))
        }
    };
    let sf = system_check::required_safety_factor(req.required_safety_factor_nondim)?;
    system_check::lift_reserve(req.lift_reserve_nondim)?;
    let breaking = req.cable.breaking_strength()?;
    let allowable = breaking.map(|b| b / sf);
    // A target below a millimetre has no finite transient check (the
    // string's length scale goes to zero).
    bounded(
        "target_elevation_m",
        req.target_elevation_m,
        MIN_TARGET_M,
        1e6,
    )?;
    // In wind the target is an altitude: the length that flies there.
    let (target_length, wind) = if air.is_calm() || (!resolve && air.has_ge()) {
        (req.target_elevation_m, None)
    } else {
        bounded("target_elevation_m", req.target_elevation_m, 0.0, 1e6)?;
        require_positive("target_elevation_m", req.target_elevation_m)?;
        let probe = PlanProblem {
            system: model.system,
            target_length_m: req.target_elevation_m,
            winch,
            lift_reserve: req.lift_reserve_nondim,
            allowable_tension_n: allowable,
            grid_segments: crate::numerics::plan::DEFAULT_GRID_SEGMENTS,
        };
        bounded(
            "lift_reserve_nondim",
            req.lift_reserve_nondim,
            0.0,
            crate::numerics::plan::MAX_LIFT_RESERVE,
        )?;
        let lift = air.lift_limit_m(&probe);
        let reachable = air.rest_loads(&probe, lift).altitude_m;
        match air.length_for_altitude(&model.system, req.target_elevation_m, lift) {
            Ok(l) => (
                l,
                Some(WindTarget {
                    lift_limit_m: lift,
                    reachable_altitude_m: reachable,
                    unreachable: None,
                }),
            ),
            Err(top) => (
                // Planned to the limit only to report; the answer is infeasible.
                lift,
                Some(WindTarget {
                    lift_limit_m: lift,
                    reachable_altitude_m: top,
                    unreachable: Some(if air.has_ge() && req.target_elevation_m > lift {
                        BindingLimit::QuasiStaticGe {
                            length_m: req.target_elevation_m,
                            limit_m: lift,
                        }
                    } else {
                        BindingLimit::WindAltitude {
                            altitude_m: req.target_elevation_m,
                            reachable_m: top,
                        }
                    }),
                }),
            ),
        }
    };
    let problem = PlanProblem::new(
        model.system,
        target_length,
        winch,
        req.lift_reserve_nondim,
        allowable,
    )?;
    if !(2..=MAX_PLAN_SAMPLES).contains(&req.samples) {
        return Err(InvalidInput::new(
            "samples",
            format!(
                "must be between 2 and {MAX_PLAN_SAMPLES}, got {}",
                req.samples
            ),
        ));
    }
    require_positive(
        "disturbance_tip_deflection_m",
        req.disturbance_tip_deflection_m,
    )?;
    bounded(
        "disturbance_tip_deflection_m",
        req.disturbance_tip_deflection_m,
        0.0,
        1e3,
    )?;
    let amplification_limit = match req.max_amplification_nondim {
        Some(a) => Some(bounded(
            "max_amplification_nondim",
            require_positive("max_amplification_nondim", a)?,
            0.0,
            1e6,
        )?),
        None => None,
    };
    let forecast = match &req.haul_down {
        Some(h) => {
            let pts: Vec<(f64, f64)> = h
                .forecast
                .iter()
                .map(|p| (p.time_s, p.wind_speed_m_s))
                .collect();
            for (i, p) in h.forecast.iter().enumerate() {
                bounded(
                    &format!("haul_down.forecast[{i}].time_s"),
                    p.time_s,
                    0.0,
                    1e9,
                )?;
                bounded(
                    &format!("haul_down.forecast[{i}].wind_speed_m_s"),
                    p.wind_speed_m_s,
                    0.0,
                    200.0,
                )?;
            }
            let f = Forecast::new(&pts, "haul_down.forecast")?;
            let limit =
                require_positive("haul_down.max_operating_wind_m_s", h.max_operating_wind_m_s)?;
            bounded("haul_down.max_operating_wind_m_s", limit, 0.0, 200.0)?;
            Some((f, limit))
        }
        None => None,
    };
    Ok(Validated {
        model,
        problem,
        forecast,
        amplification_limit,
        breaking_strength_n: breaking,
        options: PlanOptions { air, max_jerk_m_s3 },
        wind,
    })
}

/// Checks a plan request without computing it (job submission).
pub fn validate_plan(req: &PlanRequest) -> Result<(), RequestError> {
    validate_with(req, false)?;
    Ok(())
}

fn outcome_name(o: &RunOutcome) -> &'static str {
    match o {
        RunOutcome::Completed => "completed",
        RunOutcome::Diverged { .. } => "diverged",
        RunOutcome::LengthCollapsed { .. } => "length_collapsed",
        RunOutcome::Cancelled { .. } => "cancelled",
    }
}

fn check_output(c: &TransientCheck) -> TransientCheckOutput {
    TransientCheckOutput {
        elements: c.elements,
        time_step_s: c.time_step_s,
        steps: c.steps,
        run_duration_s: c.run_duration_s,
        initial_tip_deflection_m: c.initial_tip_deflection_m,
        peak_tip_deflection_m: c.peak_tip_deflection_m,
        final_tip_amplitude_m: c.final_tip_amplitude_m,
        amplification_nondim: c.amplification,
        outcome: outcome_name(&c.outcome).into(),
    }
}

fn samples_output(p: &PlanProblem, air: &Air, s: &Schedule, count: usize) -> Vec<PlanSampleOutput> {
    if !air.is_calm() {
        return wind_samples_output(p, air, s, count);
    }
    s.samples(count)
        .into_iter()
        .map(|(t, k)| {
            let ceiling = p.rate_ceiling_m_s(k.length_m, k.acceleration_m_s2);
            PlanSampleOutput {
                time_s: t,
                length_m: k.length_m,
                altitude_m: k.length_m,
                rate_m_s: k.rate_m_s,
                acceleration_m_s2: k.acceleration_m_s2,
                winch_tension_n: p.winch_tension_n(k.length_m, k.acceleration_m_s2),
                max_tension_n: p.max_tension_n(k.length_m, k.acceleration_m_s2),
                rate_ceiling_m_s: ceiling,
                stability_margin_m_s: ceiling - k.rate_m_s.abs(),
                effective_tension_margin_n: p.effective_tension_n(
                    k.length_m,
                    k.rate_m_s,
                    k.acceleration_m_s2,
                ),
            }
        })
        .collect()
}

/// Samples with the loads of the steady-wind equilibrium at each length.
fn wind_samples_output(
    p: &PlanProblem,
    air: &Air,
    s: &Schedule,
    count: usize,
) -> Vec<PlanSampleOutput> {
    use rayon::prelude::*;
    let sy = &p.system;
    s.samples(count)
        .into_par_iter()
        .map(|(t, k)| {
            let (l, a) = (k.length_m, k.acceleration_m_s2);
            let r = air.rest_loads(p, l);
            let ceiling = r.rate_ceiling_m_s(sy, l, a);
            PlanSampleOutput {
                time_s: t,
                length_m: l,
                altitude_m: r.altitude_m,
                rate_m_s: k.rate_m_s,
                acceleration_m_s2: a,
                winch_tension_n: r.winch_tension_at_n(sy, l, a),
                max_tension_n: r.max_tension_at_n(sy, l, a),
                rate_ceiling_m_s: ceiling,
                stability_margin_m_s: ceiling - k.rate_m_s.abs(),
                effective_tension_margin_n: r.effective_tension_n(sy, l, k.rate_m_s, a),
            }
        })
        .collect()
}

/// Largest `|ΔL̈/Δt|` between consecutive knots and inside them (m/s³).
fn peak_jerk(s: &Schedule) -> f64 {
    s.knots
        .iter()
        .map(|k| k.jerk_m_s3.abs())
        .fold(0.0, f64::max)
}

fn phases_output(s: &Schedule) -> Vec<PlanPhaseOutput> {
    s.phases()
        .into_iter()
        .map(|ph| {
            let dt = ph.end.time_s - ph.start.time_s;
            PlanPhaseOutput {
                start_time_s: ph.start.time_s,
                end_time_s: ph.end.time_s,
                start_length_m: ph.start.length_m,
                end_length_m: ph.end.length_m,
                start_rate_m_s: ph.start.rate_m_s,
                end_rate_m_s: ph.end.rate_m_s,
                mean_acceleration_m_s2: if dt > 0.0 {
                    (ph.end.rate_m_s - ph.start.rate_m_s) / dt
                } else {
                    0.0
                },
                limit: ph.limit.name().into(),
                instruction: ph.limit.instruction().into(),
            }
        })
        .collect()
}

const METHOD: &str = "Time-optimal speed-profile pass along the length (forward/backward, as in time-optimal \
path planning): constant acceleration on each of 4000 length segments; a backward pass from rest at the target \
gives the largest viable rate at each length (a two-variable LP per segment), a forward pass from rest takes the \
largest admissible acceleration. Constraints at both ends of every segment (hence on all of it, since they are \
linear in length there): winch rate and acceleration, the tension rating on the largest axial tension F − mL̈, and \
stability with the lift reserve r in its converged continuum form (the FE critical length converges to it from \
above, SPEC §5): effective roller tension (1−r)F − mL̈ − ρA(g+L̈)L − ρA L̇² ≥ ε(1−r)F with ε = 1e-3. The schedule \
is then run on the FE string (Newmark, first-mode disturbance) and the oscillation growth compared with WKB \
(thesis (3.12)).";

/// The method, with the jerk limit and the wind criterion when they apply.
fn method(opts: &PlanOptions) -> String {
    let mut m = METHOD.to_string();
    if opts.max_jerk_m_s3.is_some() {
        m.push_str(
            " Jerk limit: the schedule's velocity is averaged over a sliding window τ, the smallest with \
             |L̈(t) − L̈(t−τ)| ≤ j τ (so |dL̈/dt| ≤ j; for the winch trapezoid this is the classical 7-segment \
             S-curve, duration D/v + v/a + a/j), then checked against every limit at its knots and inside its \
             intervals; while it falls short the pass is rerun with a larger stability margin (and a lower \
             allowable tension).",
        );
    }
    if let Air::Wind(w) = &opts.air {
        m.push_str(&format!(
            " Wind: target_elevation_m is the altitude in this wind (the tether length that flies there is found \
             by bisection on the equilibrium altitude); the tensions are those of the steady-wind equilibrium \
             (winch and aerostat, full buoyancy) less the inertia of the payout; stability: {}. The transient \
             check runs the schedule on the calm-air string.",
            w.criterion_name
        ));
        if let Some(ge) = &w.ge {
            m.push_str(&format!(
                " Quasi-static GE: {} elements for the critical-rate table ({} lengths, each by a scan of {} rates \
                 and {} bisections, divergence by the inertia of the stiffness) and the divergence check, {} \
                 elements for the QEP (flutter) check of the samples; a failed check lowers S by 2 %, 8 %, 32 % of \
                 (1−r)F and re-plans. Without wind the GE criterion runs on the straight tether in still air, the \
                 tether diameter (for its rotary inertia ρA d²/16) from ρA at {} kg/m³.",
                ge.options.elements,
                ge.options.table_lengths,
                ge_plan::SCAN_POINTS,
                ge_plan::BISECTIONS,
                ge.options.check_elements,
                CALM_GE_MATERIAL_DENSITY_KG_M3
            ));
        }
    }
    m
}

/// Answers a plan request.
pub fn plan(req: &PlanRequest, progress: &dyn Progress) -> Result<PlanResponse, RequestError> {
    let started = Instant::now();
    let v = validate(req)?;
    let p = v.problem;
    let observer = ProgressObserver(progress);
    let retrieving = p.direction() < 0.0;
    let direction = if retrieving {
        "retrieval"
    } else {
        "deployment"
    };
    let inputs = serde_json::to_value(req).expect("requests serialise");
    let opts = &v.options;
    let wind_out = v.wind.as_ref().map(|w| {
        let at_target = match (&opts.air, w.unreachable.is_none()) {
            (Air::Wind(sw), true) => sw
                .problem(&p.system, p.system.net_buoyancy_n, p.target_length_m)
                .solve(&EquilibriumConfig::default())
                .ok(),
            _ => None,
        };
        PlanWindOutput {
            target_length_m: w.unreachable.is_none().then_some(p.target_length_m),
            blowdown_angle_deg: at_target.as_ref().map(|e| e.blowdown_angle_deg),
            target_downwind_m: at_target.as_ref().map(|e| e.downwind_m),
            lift_limit_m: w.lift_limit_m,
            reachable_altitude_m: w.reachable_altitude_m,
            stability_criterion: match &opts.air {
                Air::Wind(sw) => sw.criterion_name.to_string(),
                Air::Calm => String::new(),
            },
        }
    });
    // At rest at the end of the plan (or the reachable limit): the tension
    // the answer reports even when no schedule exists.
    let rest = opts.air.rest_loads(&p, p.target_length_m);
    let rest_peak = rest.top_tension_n.max(rest.winch_tension_n);
    let rest_peak = rest_peak.is_finite().then_some(rest_peak);
    let limits_base = PlanLimitsOutput {
        reserve_buoyancy_n: p.reserve_buoyancy_n(),
        lift_limit_m: v.wind.as_ref().map_or(p.lift_limit_m(), |w| w.lift_limit_m),
        allowable_tension_n: p.allowable_tension_n,
        stability_margin_n: STABILITY_MARGIN * p.reserve_buoyancy_n(),
        min_stability_margin_m_s: None,
        min_effective_tension_margin_n: None,
        peak_tension_n: rest_peak,
        min_safety_factor_nondim: v.breaking_strength_n.zip(rest_peak).map(|(b, t)| b / t),
    };
    let tension_checked = v.breaking_strength_n.is_some();
    let unchecked_note = if tension_checked {
        ""
    } else {
        "; tension NOT checked (no cable.breaking_strength_n)"
    };
    let infeasible = |b: BindingLimit, limits: PlanLimitsOutput| PlanResponse {
        feasible: false,
        go: false,
        direction: direction.into(),
        duration_s: None,
        binding_limit: Some(b.name().into()),
        reason: format!("no-go: {}{unchecked_note}", b.reason(p.lift_reserve)),
        tension_checked,
        schedule: vec![],
        phases: vec![],
        constant_rate: None,
        bound: None,
        transient_check: None,
        oscillation: None,
        retrieval: None,
        haul_down: None,
        limits,
        wind: wind_out.clone(),
        jerk: None,
        ge_stability: ge_output(&p, &opts.air, None, 0),
        method: method(opts),
        compute_time_s: started.elapsed().as_secs_f64(),
        inputs: inputs.clone(),
        groups: groups(&v.model.system),
    };
    if let Some(b) = v.wind.as_ref().and_then(|w| w.unreachable.clone()) {
        return Ok(infeasible(b, limits_base));
    }

    let mut ge_check = None;
    let mut ge_tightenings = 0;
    let mut tightened_options: Option<PlanOptions> = None;
    // The schedule (slowed for an amplification limit when retrieving).
    let (sched, check, rate_used, slowed) = match (retrieving, v.amplification_limit) {
        (true, Some(limit)) => {
            match retrieval::bounded_retrieval_with(
                &p,
                &v.model,
                limit,
                req.disturbance_tip_deflection_m,
                &observer,
                opts,
            )
            .map_err(from_transient)?
            {
                Ok(b) => (b.schedule, b.check, b.rate_limit_m_s, b.slowed),
                Err(binding) => {
                    // A static limit takes precedence over the amplification.
                    if let PlanOutcome::Infeasible(b) = schedule::fastest_with(&p, opts) {
                        return Ok(infeasible(b, limits_base));
                    }
                    return Ok(infeasible(binding, limits_base));
                }
            }
        }
        _ => {
            // With the GE criterion: check the schedule by the GE QEP and
            // re-plan with a lowered criterion while a sample fails.
            let mut tightened = v.options.clone();
            let mut tightenings = 0;
            let s = loop {
                let s = match schedule::fastest_with(&p, &tightened) {
                    PlanOutcome::Infeasible(b) => return Ok(infeasible(b, limits_base)),
                    PlanOutcome::Feasible(s) => s,
                };
                let Some(chk) = ge_check_of(&tightened.air, &s, ge_check_count(req)) else {
                    break s;
                };
                if chk.failed == 0 {
                    ge_check = Some(chk);
                    break s;
                }
                if tightenings >= MAX_GE_TIGHTENINGS {
                    return Ok(infeasible(ge_binding(&chk), limits_base));
                }
                tightenings += 1;
                let offset = 0.02 * 4f64.powi(tightenings as i32 - 1) * p.reserve_buoyancy_n();
                if let Air::Wind(w) = &mut tightened.air
                    && let Some(ge) = &w.ge
                {
                    w.ge = Some(ge.with_offset(offset));
                }
            };
            ge_tightenings = tightenings;
            tightened_options = Some(tightened);
            let c = retrieval::check_transient(
                &v.model,
                &s,
                req.disturbance_tip_deflection_m,
                &observer,
            )
            .map_err(from_transient)?;
            (s, c, p.winch.max_rate_m_s, false)
        }
    };
    if ge_check.is_none()
        && let Some(chk) = ge_check_of(&opts.air, &sched, ge_check_count(req))
    {
        // The amplification-bounded retrieval: checked, not tightened.
        if chk.failed > 0 {
            return Ok(infeasible(ge_binding(&chk), limits_base));
        }
        ge_check = Some(chk);
    }
    let opts = tightened_options.as_ref().unwrap_or(opts);
    if progress.cancelled() {
        return Err(RequestError::Cancelled);
    }
    let schedule_out = samples_output(&p, &opts.air, &sched, req.samples);
    let min_of =
        |f: fn(&PlanSampleOutput) -> f64| schedule_out.iter().map(f).fold(f64::INFINITY, f64::min);
    let peak_tension = schedule_out
        .iter()
        .map(|s| s.max_tension_n)
        .fold(f64::NEG_INFINITY, f64::max);
    let limits = PlanLimitsOutput {
        min_stability_margin_m_s: Some(min_of(|s| s.stability_margin_m_s)),
        min_effective_tension_margin_n: Some(min_of(|s| s.effective_tension_margin_n)),
        peak_tension_n: Some(peak_tension),
        min_safety_factor_nondim: v.breaking_strength_n.map(|b| b / peak_tension),
        ..limits_base
    };

    let constant_rate = {
        let mut pc = p;
        pc.winch.max_rate_m_s = rate_used;
        schedule::best_constant_rate_with(&pc, opts).map(|c| ConstantRateOutput {
            rate_m_s: c.rate_m_s,
            duration_s: c.duration_s,
            time_saved_s: c.duration_s - sched.duration_s,
            time_saved_fraction_nondim: (c.duration_s - sched.duration_s) / c.duration_s,
        })
    };
    let bound = schedule::static_ceiling_bound_s_with(&p, &opts.air).map(|b| {
        let excess = sched.duration_s / b - 1.0;
        let explanation = if excess.abs() <= 1e-3 {
            "the plan meets the bound: the stability ceiling does not bind during the acceleration phases".to_string()
        } else if excess < 0.0 {
            format!(
                "the plan is {:.1} % faster than the bound: braking raises the roller tension by (m + ρA L)|L̈|, \
                 so rates above the static ceiling are stable while slowing down",
                -100.0 * excess
            )
        } else if slowed {
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
    });
    let (l_start, l_end) = (p.system.initial_length_m, p.target_length_m);
    let wkb = retrieval::wkb_growth(&v.model, l_start, l_end);
    let oscillation = OscillationOutput {
        wkb_amplification_nondim: wkb.map(|w| w.amplitude),
        wkb_fe_mode_amplification_nondim: retrieval::wkb_growth_fe(&v.model, l_start, l_end),
        wkb_energy_amplification_nondim: wkb.map(|w| w.energy),
        transient_amplification_nondim: Some(check.amplification),
        max_amplification_nondim: v.amplification_limit,
        slowed_for_amplification: slowed,
        rate_limit_used_m_s: rate_used,
    };
    let retrieval_out = retrieving.then(|| {
        let samples = sched.samples(req.samples);
        let (rise, peak) = retrieval::tension_rise_n(&p, &samples);
        RetrievalOutput {
            tension_rise_n: rise,
            peak_winch_tension_n: peak,
            initial_winch_tension_n: p.winch_tension_n(l_start, 0.0),
            note: "Shortening is unstable at every instant (the symmetric part of the damping is −(|L̇|/L)·M: \
                   negative), so a retrieval has no stability verdict; the plan keeps the roller tension positive \
                   (no divergence) and reports how an oscillation grows."
                .into(),
        }
    });

    // Haul-down deadline: from the operating altitude down to the lower end.
    let haul_down = match &v.forecast {
        Some((forecast, limit)) => {
            let (high, low) = (l_start.max(l_end), l_start.min(l_end));
            let duration = if retrieving {
                Some(sched.duration_s)
            } else {
                match schedule::fastest_with(&p.between(high, low), opts) {
                    PlanOutcome::Feasible(s) => Some(s.duration_s),
                    PlanOutcome::Infeasible(_) => None,
                }
            };
            duration.map(|d| {
                let aloft_from = if retrieving { 0.0 } else { sched.duration_s };
                let h = deadline::haul_down(forecast, *limit, d, aloft_from);
                HaulDownOutput {
                    wind_exceeds_limit_at_s: h.exceeds_at_s,
                    retrieval_duration_s: h.retrieval_duration_s,
                    from_length_m: high,
                    to_length_m: low,
                    latest_start_s: h.latest_start_s,
                    go: h.go,
                    reason: h.reason,
                }
            })
        }
        None => None,
    };
    let go = haul_down.as_ref().is_none_or(|h| h.go);
    let mut reason = format!(
        "{}: {direction} from {l_start:.1} m to {l_end:.1} m in {:.1} s, stable with a {:.1} % lift reserve at every instant",
        if go { "go" } else { "no-go" },
        sched.duration_s,
        100.0 * p.lift_reserve
    );
    if let Some(w) = &wind_out
        && let (Some(l), Some(a)) = (w.target_length_m, w.blowdown_angle_deg)
    {
        reason.push_str(&format!(
            " (in this wind {l:.1} m of tether flies the aerostat at {:.1} m, blown down {a:.1}°)",
            req.target_elevation_m
        ));
    }
    if let Some(t) = p.allowable_tension_n {
        reason.push_str(&format!(", tension within {t:.0} N"));
    }
    reason.push_str(unchecked_note);
    if let Some(h) = &haul_down {
        reason.push_str(&format!("; haul-down: {}", h.reason));
    }
    Ok(PlanResponse {
        feasible: true,
        go,
        direction: direction.into(),
        duration_s: Some(sched.duration_s),
        binding_limit: None,
        reason,
        tension_checked,
        schedule: schedule_out,
        phases: phases_output(&sched),
        constant_rate,
        bound,
        transient_check: Some(check_output(&check)),
        oscillation: Some(oscillation),
        retrieval: retrieval_out,
        haul_down,
        limits,
        wind: wind_out,
        jerk: opts.max_jerk_m_s3.map(|j| JerkOutput {
            max_jerk_m_s3: j,
            peak_jerk_m_s3: peak_jerk(&sched),
            averaging_window_s: sched.averaging_window_s,
        }),
        ge_stability: ge_output(&p, &opts.air, ge_check.as_ref(), ge_tightenings),
        method: method(opts),
        compute_time_s: started.elapsed().as_secs_f64(),
        inputs,
        groups: groups(&v.model.system),
    })
}
