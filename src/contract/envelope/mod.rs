//! `POST /api/v1/envelope`, `tetherplan envelope` and the `envelope` job:
//! equilibria over wind speed × tether length with their limits
//! ([`crate::numerics::tether::envelope`]). Each point is the answer of
//! `POST /api/v1/equilibrium` for the same inputs (a test checks it).

pub mod chunks;
pub mod dto;
pub mod kind;
pub mod price;
pub mod stability;

use crate::contract::equilibrium::dto::WindFlowInput;
use crate::contract::equilibrium::dto::{ResolvedAerostatOutput, ResolvedCableOutput};
use crate::contract::system::bounds::{self, require_range};
use crate::contract::system::grid::GridBounds;
use crate::contract::system::validate::GustWind;
use crate::contract::{Progress, RequestError};
use crate::numerics::parallel::Parallelism;
use crate::numerics::params::InvalidInput;
use crate::numerics::tether::envelope::{
    EnvelopeProblem, Limit, Limits, MAX_ENVELOPE_POINTS, WindShape,
};
use crate::numerics::tether::gust::{DynamicTension, dynamic_tension_n};
use crate::numerics::tether::{EquilibriumConfig, EquilibriumProblem, WindProfile};
use dto::*;

/// Points a synchronous envelope may have (about 0.1 s of CPU at 100 steps).
pub const MAX_SYNC_ENVELOPE_POINTS: usize = 5_000;

/// What "stable" means with `stability.method = quasi_static_ge`.
pub const GE_STABILITY_CRITERION: &str = "quasi-static GE stability of the blown-down tether at the payout rate (geometrically exact beam, blown-down equilibrium, local QEP with the payout's rate terms and the linearised air loads): stable iff max Re λ ≤ the spectrum tolerance; slack cells count as unstable";

/// Points a synchronous envelope with the quasi-static GE stability may have.
pub const MAX_SYNC_GE_ENVELOPE_POINTS: usize = 500;

/// What "stable" means in the envelope.
pub const STABILITY_CRITERION: &str = "continuum linear-string criterion of SPEC §1 applied to the blown-down tether: stable while the smallest tension exceeds the kinematic term ρA v² (calm air: h* = (F/ρA − v²)/g)";

const WIND_GRID: GridBounds = crate::contract::system::grid::WindSpeedGrid::BOUNDS;
const LENGTH_GRID: GridBounds = crate::contract::system::grid::LengthGrid::BOUNDS;

impl EnvelopeRequest {
    /// The shape of the flow (scaled by each grid speed) and its own speed.
    pub fn shape(&self) -> Result<(WindShape, f64), InvalidInput> {
        Ok(match &self.wind.flow {
            WindFlowInput::Uniform { speed_m_s } => (WindShape::Uniform, *speed_m_s),
            WindFlowInput::PowerLaw {
                coefficient_m_s,
                exponent_nondim,
                reference_height_m,
            } => (
                WindShape::PowerLaw {
                    exponent: bounds::EXPONENT.check_at("wind.flow", *exponent_nondim)?,
                    reference_height_m: bounds::REFERENCE_HEIGHT_M
                        .check_at("wind.flow", *reference_height_m)?,
                },
                *coefficient_m_s,
            ),
            WindFlowInput::LogLaw {
                speed_m_s,
                reference_height_m,
                roughness_length_m,
            } => {
                let z0 = bounds::ROUGHNESS_LENGTH_M.check_at("wind.flow", *roughness_length_m)?;
                let zr = bounds::REFERENCE_HEIGHT_M.check_at("wind.flow", *reference_height_m)?;
                WindProfile::log_law(0.0, zr, z0, "wind.flow")?;
                (
                    WindShape::LogLaw {
                        roughness_length_m: z0,
                        reference_height_m: zr,
                    },
                    *speed_m_s,
                )
            }
            WindFlowInput::Tabulated { .. } => {
                return Err(InvalidInput::new(
                    "wind.flow.kind",
                    "the envelope scales the wind profile to each grid speed, which a table cannot be: \
                     give a uniform, log-law or power-law flow",
                ));
            }
        })
    }

    /// The wind speeds: the grid, or the flow's own speed. The flow's
    /// speed is checked (0 to 150 m/s) with a grid too: it still sets the
    /// gust ratio of `wind.gust.gust_m_s`, and a field the route took but
    /// did not check would pass any number unseen.
    pub fn wind_speeds(&self) -> Result<Vec<f64>, InvalidInput> {
        let (_, speed) = self.shape()?;
        let field = match &self.wind.flow {
            WindFlowInput::PowerLaw { .. } => "wind.flow.coefficient_m_s",
            _ => "wind.flow.speed_m_s",
        };
        let own = require_range(field, speed, 0.0, false, bounds::WIND_SPEED_M_S.max)?;
        match &self.wind_speeds_m_s {
            Some(g) => g.values("wind_speeds_m_s", WIND_GRID),
            None => Ok(vec![own]),
        }
    }
}

impl EnvelopeRequest {
    /// Number of grid points.
    pub fn points(&self) -> usize {
        self.wind_speeds_m_s
            .as_ref()
            .map_or(1, |g| g.count())
            .saturating_mul(self.tether_lengths_m.count())
    }

    /// The validated sweep and its configuration.
    pub fn problem(&self) -> Result<(EnvelopeProblem, EquilibriumConfig), InvalidInput> {
        let (shape, _) = self.shape()?;
        let winds = self.wind_speeds()?;
        let lengths = self
            .tether_lengths_m
            .values("tether_lengths_m", LENGTH_GRID)?;
        let lmin = lengths.iter().copied().fold(f64::INFINITY, f64::min);
        if self.points() > MAX_ENVELOPE_POINTS {
            return Err(InvalidInput::new(
                self.tether_lengths_m.count_field("tether_lengths_m"),
                format!(
                    "the envelope would have {} points (wind speeds × tether lengths); at most {MAX_ENVELOPE_POINTS}",
                    self.points()
                ),
            ));
        }
        crate::contract::system::validate::check_rest(
            self.winch.as_ref(),
            self.initial_length_m,
            self.lift_reserve_nondim,
        )?;
        let base = EquilibriumProblem {
            cable: self.cable.cable("cable")?,
            body: self.aerostat.body("aerostat")?,
            wind: WindProfile::calm(),
            air_density_kg_m3: self.wind.air_density()?,
            tether_length_m: lmin,
            gravity_m_s2: bounds::GRAVITY_M_S2.check(self.gravity_m_s2)?,
        };
        let required = bounds::REQUIRED_SAFETY_FACTOR.check(self.required_safety_factor_nondim)?;
        if let Some(c) = self.ceiling_m {
            require_range("ceiling_m", c, 0.0, true, 1e5)?;
        }
        if let Some(f) = self.min_altitude_m {
            require_range("min_altitude_m", f, 0.0, false, 1e5)?;
        }
        self.gust_factor()?;
        if let Some(v) = self.payout_rate_m_s {
            bounds::PAYOUT_RATE_M_S.check(v)?;
        }
        let steps = bounds::INTEGRATION_STEPS.check(self.integration_steps)?;
        Ok((
            EnvelopeProblem {
                base,
                wind: shape,
                wind_speeds_m_s: winds,
                tether_lengths_m: lengths,
                limits: Limits {
                    required_safety_factor: required,
                    ceiling_m: self.ceiling_m,
                    min_altitude_m: self.min_altitude_m,
                    payout_rate_m_s: self.payout_rate_m_s,
                    dynamic_tension: None,
                },
            },
            EquilibriumConfig {
                steps,
                keep_shape: false,
                ..EquilibriumConfig::default()
            },
        ))
    }

    pub fn validate(&self) -> Result<(), RequestError> {
        self.ge_problem()?;
        Ok(())
    }

    /// The sweep, its configuration and the GE settings (`None`: the string criterion).
    #[allow(clippy::type_complexity)]
    pub fn ge_problem(
        &self,
    ) -> Result<
        (
            EnvelopeProblem,
            EquilibriumConfig,
            Option<crate::numerics::tether::envelope_ge::GeStabilitySpec>,
        ),
        InvalidInput,
    > {
        let (problem, config) = self.problem()?;
        let longest = problem.tether_lengths_m.iter().copied().fold(0.0, f64::max);
        let spec = match &self.stability {
            Some(s) => s.spec(
                self.aerostat.mass("aerostat")?,
                longest,
                self.payout_rate_m_s,
                self.cable.bending_stiffness("cable")?,
            )?,
            None => None,
        };
        if let (Some(spec), Some(v)) = (&spec, self.payout_rate_m_s) {
            spec.validate_rate(&problem, v)?;
        }
        Ok((problem, config, spec))
    }

    /// With `wind.gust`: the gust factor `G` on the flow (each row's gust
    /// is its wind times `G`).
    pub fn gust_factor(&self) -> Result<Option<f64>, InvalidInput> {
        Ok(self.gust_wind()?.map(|g| g.factor))
    }

    /// With `wind.gust`: the gust as the plan resolves it (its factor on
    /// the flow and its dynamic tension factor).
    pub fn gust_wind(&self) -> Result<Option<GustWind>, InvalidInput> {
        if self.wind.gust.is_none() {
            return Ok(None);
        }
        let mean = self.wind.flow.profile("wind.flow")?;
        self.wind.gust_wind(&mean)
    }

    /// Whether the quasi-static GE judges stability.
    pub fn uses_ge(&self) -> bool {
        matches!(
            self.stability,
            Some(stability::EnvelopeStabilityInput::QuasiStaticGe { .. })
        )
    }
}

/// Computes the envelope; progress counts wind rows.
pub fn envelope(
    req: &EnvelopeRequest,
    parallelism: Parallelism,
    progress: &dyn Progress,
) -> Result<EnvelopeResponse, RequestError> {
    let (problem, config, spec) = req.ge_problem()?;
    envelope_of(req, &problem, &config, spec.as_ref(), parallelism, progress)
}

/// The envelope of `problem` (the request's, or its rows of one chunk).
pub(crate) fn envelope_of(
    req: &EnvelopeRequest,
    problem: &EnvelopeProblem,
    config: &EquilibriumConfig,
    spec: Option<&crate::numerics::tether::envelope_ge::GeStabilitySpec>,
    parallelism: Parallelism,
    progress: &dyn Progress,
) -> Result<EnvelopeResponse, RequestError> {
    let gust_wind = req.gust_wind()?;
    let gust_factor = gust_wind.as_ref().map(|g| g.factor);
    let tension_factor = gust_wind.as_ref().map_or(1.0, |g| g.tension_factor);
    // With gusts the mean and the gust envelopes report half the progress each.
    let passes = if gust_factor.is_some() { 2 } else { 1 };
    let report = |done: usize, total: usize| progress.report(done, passes * total);
    let cancelled = || progress.cancelled();
    let (env, ge) = match spec {
        None => match problem.solve(config, parallelism, &report, &cancelled)? {
            Some(env) => (env, None),
            None => return Err(RequestError::Cancelled),
        },
        Some(spec) => {
            match crate::numerics::tether::envelope_ge::solve_ge(
                problem,
                spec,
                config,
                parallelism,
                &report,
                &cancelled,
            )? {
                Some(ge) => (ge.envelope.clone(), Some(ge)),
                None => return Err(RequestError::Cancelled),
            }
        }
    };
    let gust_env = match gust_factor {
        Some(g) => {
            let gust_problem = gust_problem(problem, g, tension_factor, spec.is_some());
            let total = problem.wind_speeds_m_s.len();
            let report = |done: usize, _: usize| progress.report(total + done, 2 * total);
            match gust_problem.solve(config, parallelism, &report, &cancelled)? {
                Some(env) => Some(env),
                None => return Err(RequestError::Cancelled),
            }
        }
        None => None,
    };
    let points: Vec<EnvelopePointOutput> = env
        .points
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let e = &p.equilibrium;
            let gust = gust_env.as_ref().map(|g| &g.points[k]);
            let (limit, in_gust) = worst_limit(p.verdict.limit, gust.and_then(|g| g.verdict.limit));
            EnvelopePointOutput {
                wind_speed_m_s: p.wind_speed_m_s,
                tether_length_m: p.tether_length_m,
                aerostat_altitude_m: e.altitude_m,
                aerostat_downwind_m: e.downwind_m,
                blowdown_angle_deg: e.blowdown_angle_deg,
                winch_tension_n: e.winch_tension_n,
                top_tension_n: e.top_tension_n,
                max_tension_n: e.max_tension_n,
                min_tension_n: e.min_tension_n,
                safety_factor_nondim: e.safety_factor,
                slack: e.slack,
                stability_margin_n: p.verdict.stability_margin_n,
                stable: p.verdict.stable,
                feasible: limit.is_none(),
                binding_limit: limit.map(|l| l.name().to_string()),
                max_growth_rate_1_s: ge.as_ref().and_then(|g| g.max_growth_rate_1_s[k]),
                gust: gust.map(|g| gust_point_output(g, problem, tension_factor, in_gust)),
            }
        })
        .collect();
    let max_wind_per_length =
        length_limits(&problem.wind_speeds_m_s, &problem.tether_lengths_m, &points);
    let max_altitude = match gust_env {
        // The cells' verdicts are the worst of mean and gust: from the points.
        Some(_) => max_altitude_per_row(&points, problem.tether_lengths_m.len()),
        None => env.max_altitude_per_wind.clone(),
    };
    let max_altitude_per_wind = problem
        .wind_speeds_m_s
        .iter()
        .zip(&max_altitude)
        .map(|(&u, best)| WindLimitOutput {
            wind_speed_m_s: u,
            max_altitude_m: best.map(|b| b.0),
            tether_length_m: best.map(|b| b.1),
        })
        .collect();
    let c = &problem.base.cable;
    let b = &problem.base.body;
    Ok(EnvelopeResponse {
        wind_speeds_m_s: problem.wind_speeds_m_s.clone(),
        tether_lengths_m: problem.tether_lengths_m.clone(),
        points,
        max_wind_per_length,
        max_altitude_per_wind,
        required_safety_factor_nondim: req.required_safety_factor_nondim,
        ceiling_m: req.ceiling_m,
        min_altitude_m: req.min_altitude_m,
        payout_rate_m_s: req.payout_rate_m_s,
        gust: gust_wind.as_ref().map(|g| EnvelopeGustOutput {
            gust_factor_nondim: g.factor,
            dynamic_tension_factor_nondim: g.tension_factor,
            dynamic_tension_note: g.dynamic_tension_note(),
            rule: if spec.is_some() {
                GUST_RULE_GE
            } else {
                GUST_RULE
            }
            .to_string(),
        }),
        stability_criterion: if spec.is_some() {
            GE_STABILITY_CRITERION
        } else {
            STABILITY_CRITERION
        }
        .to_string(),
        cable: ResolvedCableOutput {
            mass_per_length_kg_m: c.mass_per_length_kg_m,
            diameter_m: c.diameter_m,
            normal_drag_coefficient_nondim: c.normal_drag_coefficient,
            axial_stiffness_n: c.axial_stiffness_n,
            breaking_strength_n: c.breaking_strength_n,
        },
        aerostat: ResolvedAerostatOutput {
            net_buoyancy_n: b.net_buoyancy_n,
            drag_coefficient_nondim: b.drag_coefficient,
            lift_coefficient_nondim: b.lift_coefficient,
            reference_area_m2: b.reference_area_m2,
        },
        integration_steps: config.steps,
        quasi_static_ge: spec
            .zip(ge.as_ref())
            .map(|(spec, ge)| stability::ge_output(spec, &problem, &config, ge)),
    })
}

/// How a cell is judged with gusts.
pub const GUST_RULE: &str = "each cell is judged by the worst of the mean wind and the gust (the row's wind times the gust factor, the static equilibrium at that speed, SPEC §10): slack, tension, ceiling, min_altitude and stability in either put it outside; the first limit met in priority order names it (the mean's on a tie)";

/// [`GUST_RULE`] with the quasi-static GE criterion.
pub const GUST_RULE_GE: &str = "each cell is judged by the worst of the mean wind and the gust (the row's wind times the gust factor, the static equilibrium at that speed, SPEC §10): slack, tension, ceiling and min_altitude in either put it outside; the quasi-static GE stability is judged in the mean wind only";

/// The envelope problem in the gust: each row's wind times `factor`, its
/// largest tension judged at its dynamic value (`tension_factor` on the
/// increment over the calm tension, the net buoyancy); with
/// the GE criterion stability is left to the mean (no payout rate).
fn gust_problem(
    problem: &EnvelopeProblem,
    factor: f64,
    tension_factor: f64,
    ge: bool,
) -> EnvelopeProblem {
    let mut g = problem.clone();
    g.wind_speeds_m_s = problem.wind_speeds_m_s.iter().map(|u| u * factor).collect();
    g.limits.dynamic_tension = Some(DynamicTension {
        factor_nondim: tension_factor,
        calm_max_tension_n: problem.base.body.net_buoyancy_n,
    });
    if ge {
        g.limits.payout_rate_m_s = None;
    }
    g
}

/// Rank of a limit in the order [`crate::numerics::tether::envelope::judge_with`] tests them.
fn rank(l: Limit) -> u8 {
    match l {
        Limit::NotConverged => 0,
        Limit::Slack => 1,
        Limit::Tension => 2,
        Limit::Ceiling => 3,
        Limit::MinAltitude => 4,
        Limit::Stability => 5,
    }
}

/// The worst of the mean's and the gust's limits (the mean's on a tie),
/// and whether it is the gust's.
fn worst_limit(mean: Option<Limit>, gust: Option<Limit>) -> (Option<Limit>, bool) {
    match (mean, gust) {
        (Some(m), Some(g)) if rank(g) < rank(m) => (Some(g), true),
        (Some(m), _) => (Some(m), false),
        (None, Some(g)) => (Some(g), true),
        (None, None) => (None, false),
    }
}

/// One gust cell, its tensions at their dynamic value (`tension_factor` on
/// the increment over calm air: the net buoyancy at the top and along the
/// tether, `F − ρA g L` at the winch).
fn gust_point_output(
    p: &crate::numerics::tether::envelope::EnvelopePoint,
    problem: &EnvelopeProblem,
    tension_factor: f64,
    binds: bool,
) -> EnvelopeGustPointOutput {
    let e = &p.equilibrium;
    let f = problem.base.body.net_buoyancy_n;
    let calm_winch = (f - problem.base.cable.mass_per_length_kg_m
        * problem.base.gravity_m_s2
        * p.tether_length_m)
        .max(0.0);
    let k = |t: f64, calm: f64| dynamic_tension_n(t, calm, tension_factor);
    EnvelopeGustPointOutput {
        wind_speed_m_s: p.wind_speed_m_s,
        aerostat_altitude_m: e.altitude_m,
        aerostat_downwind_m: e.downwind_m,
        blowdown_angle_deg: e.blowdown_angle_deg,
        winch_tension_n: k(e.winch_tension_n, calm_winch),
        top_tension_n: k(e.top_tension_n, f),
        max_tension_n: k(e.max_tension_n, f),
        static_max_tension_n: e.max_tension_n,
        min_tension_n: e.min_tension_n,
        safety_factor_nondim: e
            .safety_factor
            .map(|sf| sf * e.max_tension_n / k(e.max_tension_n, f)),
        slack: e.slack,
        stability_margin_n: p.verdict.stability_margin_n,
        stable: p.verdict.stable,
        binding_limit: p.verdict.limit.map(|l| l.name().to_string()),
        binds,
    }
}

/// Per row (wind), the highest mean altitude of a feasible cell and its
/// length (the rule of [`crate::numerics::tether::envelope::summarise`]).
fn max_altitude_per_row(points: &[EnvelopePointOutput], lengths: usize) -> Vec<Option<(f64, f64)>> {
    points
        .chunks(lengths.max(1))
        .map(|row| {
            row.iter()
                .filter(|p| p.feasible)
                .map(|p| (p.aerostat_altitude_m, p.tether_length_m))
                .max_by(|a, b| a.0.total_cmp(&b.0))
        })
        .collect()
}

/// The largest operating wind per length from the points (row by row, one
/// row per wind): the winds are taken in increasing `|U|` and a length's
/// limit is the last wind before the first point outside the envelope (the
/// same rule as [`crate::numerics::tether::envelope::summarise`]).
pub(crate) fn length_limits(
    winds: &[f64],
    lengths: &[f64],
    points: &[EnvelopePointOutput],
) -> Vec<LengthLimitOutput> {
    let nl = lengths.len();
    let mut order: Vec<usize> = (0..winds.len()).collect();
    order.sort_by(|&a, &b| winds[a].abs().total_cmp(&winds[b].abs()));
    lengths
        .iter()
        .enumerate()
        .map(|(j, &l)| {
            let mut best: Option<usize> = None;
            let mut binding = None;
            for &i in &order {
                let p = &points[i * nl + j];
                if p.feasible {
                    best = Some(i);
                } else {
                    binding = p.binding_limit.clone();
                    break;
                }
            }
            let wind = best.map(|i| winds[i]);
            // The altitude is read at the first grid row of that wind speed.
            let altitude = wind.and_then(|w| {
                winds
                    .iter()
                    .position(|&u| u == w)
                    .map(|i| points[i * nl + j].aerostat_altitude_m)
            });
            LengthLimitOutput {
                tether_length_m: l,
                max_wind_speed_m_s: wind,
                altitude_at_max_wind_m: altitude,
                binding_limit: binding,
            }
        })
        .collect()
}
