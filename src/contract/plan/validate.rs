//! Validation of a plan request: the system, the winch, the air (the mean
//! wind and its gusts), the target (in wind an altitude: the length that
//! flies there), the floor, the forecast with its gusts, and the rest of
//! the request's numbers, each refused naming its field.

use crate::contract::error::RequestError;
use crate::contract::plan::dto::*;
use crate::contract::plan::ge::*;
use crate::contract::system::WindInput;
use crate::contract::system::input::SystemInput;
use crate::contract::system::validate::{self as system_check, GustWind};
use crate::numerics::params::{InvalidInput, require_finite, require_positive};
use crate::numerics::plan::air::{Air, SteadyWind};
use crate::numerics::plan::deadline::Forecast;
use crate::numerics::plan::ge_stability::{self as ge_plan, GeCriterion};
use crate::numerics::plan::schedule::PlanOptions;
use crate::numerics::plan::{BindingLimit, PlanProblem, Winch, validate_jerk};
use crate::numerics::string::StringModel;

/// Most schedule samples.
pub const MAX_PLAN_SAMPLES: usize = 10_000;

/// The validated inputs.
pub(super) struct Validated {
    pub model: StringModel,
    pub problem: PlanProblem,
    pub forecast: Option<HaulDownForecast>,
    pub amplification_limit: Option<f64>,
    pub breaking_strength_n: Option<f64>,
    pub options: PlanOptions,
    /// In wind: the lift limit (m), the altitude there (m), and the target
    /// altitude when it is out of reach.
    pub wind: Option<WindTarget>,
    /// With `wind.gust`: the gust on the mean flow.
    pub gust: Option<GustWind>,
    /// The floor where the plan ends (m).
    pub min_altitude_m: Option<f64>,
}

pub(super) struct WindTarget {
    pub lift_limit_m: f64,
    pub reachable_altitude_m: f64,
    pub unreachable: Option<BindingLimit>,
}

/// The forecast of the haul-down deadline: the wind with its limit, and
/// the gusts with theirs.
pub(super) struct HaulDownForecast {
    pub mean: Forecast,
    pub limit_m_s: f64,
    pub gust: Option<(Forecast, f64)>,
}

/// The steady wind of the request, with the tether and aerostat drag data
/// it needs (each refused naming the field when missing), and its gusts.
fn steady_wind(
    req: &PlanRequest,
    w: &WindInput,
) -> Result<(SteadyWind, Option<GustWind>), InvalidInput> {
    let profile = w.flow.profile("wind.flow")?;
    let rho = w.air_density()?;
    let cable = req.cable.cable("cable")?;
    let body = req.aerostat.body("aerostat")?;
    let gust = w.gust_wind(&profile)?;
    let mut sw = SteadyWind::new(cable, body, profile, rho);
    if let Some(g) = &gust {
        sw = sw
            .with_gust(g.profile.clone())
            .with_gust_tension_factor(g.tension_factor);
    }
    Ok((sw, gust))
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

pub(super) fn validate(req: &PlanRequest) -> Result<Validated, InvalidInput> {
    validate_with(req, true)
}

impl PlanRequest {
    /// The plan's system as the string model takes it (cable, aerostat,
    /// initial length, gravity, model): the one plan-to-system conversion,
    /// used by the plan and its bands.
    pub fn system_input(&self) -> SystemInput {
        SystemInput {
            cable: self.cable.clone(),
            aerostat: self.aerostat.clone(),
            initial_length_m: self.initial_length_m,
            gravity_m_s2: self.gravity_m_s2,
            model: self.model.clone(),
            numerics: Default::default(),
            wind: None,
            winch: None,
            required_safety_factor_nondim: None,
            lift_reserve_nondim: None,
        }
    }
}

/// `resolve`: find the wind target (equilibria; with the GE criterion its
/// table). Without it (job submission) a GE request's target is only
/// range-checked.
pub(super) fn validate_with(req: &PlanRequest, resolve: bool) -> Result<Validated, InvalidInput> {
    let model = req.system_input().model()?;
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
        !w.is_calm() || (req.cable.cable("cable").is_ok() && req.aerostat.body("aerostat").is_ok())
    });
    let (air, gust) = match (wind, ge) {
        (Some(w), None) => {
            let (sw, gust) = steady_wind(req, w)?;
            (Air::Wind(Box::new(sw)), gust)
        }
        (None, None) => (Air::Calm, None),
        (w, Some(o)) => {
            let (mut sw, gust) = match w {
                Some(w) => steady_wind(req, w)?,
                None => (calm_wind(model.system.mass_per_length_kg_m), None),
            };
            let ge = GeCriterion::new(o);
            sw.criterion_name = if ge.string_in_wind(&sw) {
                ge_plan::QS_GE_WIND_CRITERION
            } else {
                ge_plan::QS_GE_CRITERION
            };
            sw.ge = Some(ge);
            (Air::Wind(Box::new(sw)), gust)
        }
    };
    let min_altitude_m = req
        .min_altitude_m
        .map(|f| bounded("min_altitude_m", f, 0.0, 1e6))
        .transpose()?;
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
    let forecast = req
        .haul_down
        .as_ref()
        .map(|h| haul_down_forecast(h, gust.as_ref(), req.target_elevation_m))
        .transpose()?;
    Ok(Validated {
        model,
        problem,
        forecast,
        amplification_limit,
        breaking_strength_n: breaking,
        options: PlanOptions { air, max_jerk_m_s3 },
        wind,
        gust,
        min_altitude_m,
    })
}

/// The forecast of `h`: the wind, and with `max_gust_m_s` the gusts (each
/// point's `gust_m_s`, or its wind times the gust factor of `wind.gust`).
fn haul_down_forecast(
    h: &HaulDownInput,
    gust: Option<&GustWind>,
    height_m: f64,
) -> Result<HaulDownForecast, InvalidInput> {
    let at = |i: usize, name: &str| format!("haul_down.forecast[{i}].{name}");
    let from_source;
    let forecast = match (&h.source, h.forecast.is_empty()) {
        (Some(_), false) => {
            return Err(InvalidInput::new(
                "haul_down.source",
                "give either `forecast` (the points) or `source` (a forecast as it comes), not both",
            ));
        }
        (Some(s), true) => {
            from_source = crate::contract::windows::haul_down_points(s, height_m)?;
            &from_source
        }
        (None, _) => &h.forecast,
    };
    for (i, p) in forecast.iter().enumerate() {
        bounded(&at(i, "time_s"), p.time_s, 0.0, 1e9)?;
        bounded(&at(i, "wind_speed_m_s"), p.wind_speed_m_s, 0.0, 200.0)?;
        if let Some(g) = p.gust_m_s {
            bounded(&at(i, "gust_m_s"), g, 0.0, 200.0)?;
            if g < p.wind_speed_m_s {
                return Err(InvalidInput::new(
                    at(i, "gust_m_s"),
                    format!(
                        "must be at least the wind speed of the point, {} m/s, got {g}",
                        p.wind_speed_m_s
                    ),
                ));
            }
        }
    }
    let pts: Vec<(f64, f64)> = forecast
        .iter()
        .map(|p| (p.time_s, p.wind_speed_m_s))
        .collect();
    let mean = Forecast::new(&pts, "haul_down.forecast")?;
    let limit = require_positive("haul_down.max_operating_wind_m_s", h.max_operating_wind_m_s)?;
    bounded("haul_down.max_operating_wind_m_s", limit, 0.0, 200.0)?;
    let gust = match h.max_gust_m_s {
        None => {
            if let Some(i) = forecast.iter().position(|p| p.gust_m_s.is_some()) {
                return Err(InvalidInput::new(
                    "haul_down.max_gust_m_s",
                    format!(
                        "is needed when the forecast carries gusts (haul_down.forecast[{i}].gust_m_s): \
                         give the largest gust in which the aerostat may stay aloft, in m/s"
                    ),
                ));
            }
            None
        }
        Some(g) => {
            let g = require_positive("haul_down.max_gust_m_s", g)?;
            bounded("haul_down.max_gust_m_s", g, 0.0, 200.0)?;
            let mut gpts = Vec::with_capacity(pts.len());
            for (i, p) in forecast.iter().enumerate() {
                let u = match (p.gust_m_s, gust) {
                    (Some(u), _) => u,
                    (None, Some(gw)) => p.wind_speed_m_s * gw.factor,
                    (None, None) if h.source.is_some() => {
                        return Err(InvalidInput::new(
                            "haul_down.source.data",
                            "gives no gust, which haul_down.max_gust_m_s needs: leave the gust limit \
                             out, or give wind.gust (its gust factor then scales the forecast wind)",
                        ));
                    }
                    (None, None) => {
                        return Err(InvalidInput::new(
                            at(i, "gust_m_s"),
                            "is needed with haul_down.max_gust_m_s: give the forecast gust in m/s \
                             (or wind.gust, whose gust factor then scales the forecast wind)",
                        ));
                    }
                };
                gpts.push((p.time_s, u));
            }
            Some((Forecast::new(&gpts, "haul_down.forecast")?, g))
        }
    };
    Ok(HaulDownForecast {
        mean,
        limit_m_s: limit,
        gust,
    })
}

/// Checks a plan request without computing it (job submission).
pub fn validate_plan(req: &PlanRequest) -> Result<(), RequestError> {
    validate_with(req, false)?;
    Ok(())
}
