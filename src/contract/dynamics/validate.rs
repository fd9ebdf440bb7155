//! A dynamics request checked and turned into the numerical problem
//! ([`crate::numerics::dynamics::DynamicsProblem`]) and its configuration.
//! Every bound is the schema's; every error names its field in plain words.
//! The run's own bounds (segments, steps and work, samples, shapes, ρ∞)
//! are checked by [`crate::numerics::dynamics::limits`], named here by the
//! request's fields; the answer's size (shape nodes) and the run's length
//! are the contract's.

use super::dto::*;
use crate::contract::system::WindFlowInput;
use crate::contract::system::bounds;
use crate::contract::system::validate::{check_rest, require_range};
use crate::numerics::dynamics::converged;
use crate::numerics::dynamics::limits::MIN_SEGMENTS;
use crate::numerics::dynamics::limits::{
    check_sample_count, check_segments, check_shape_count, check_shape_times,
    check_spectral_radius, check_steps, step_count,
};
use crate::numerics::dynamics::{
    Aerostat, DynamicsConfig, DynamicsProblem, GustHistory, LengthSchedule, SpectrumModel, Tether,
    Turbulence,
};
use crate::numerics::params::InvalidInput;
use crate::numerics::tether::{EquilibriumConfig, WindProfile};

/// Most shape nodes kept (shapes × (segments + 1)).
pub const MAX_SHAPE_NODES: usize = 200_000;
/// Longest run (s).
pub const MAX_DURATION_S: f64 = 1e5;
/// Shortest unstretched length a profile may reach (m).
pub const MIN_LENGTH_M: f64 = 1.0;
/// Largest seed (2^53 − 1: exact in every JSON reader).
pub const MAX_SEED: u64 = (1 << 53) - 1;

/// Segments when the request leaves them out.
pub const DEFAULT_SEGMENTS: usize = 50;
/// The coarsest default step (s): the ladder starts here.
pub const BASE_TIME_STEP_S: f64 = 0.2;
/// Steps of the default ladder: the base, halved, halved again (0.2, 0.1,
/// 0.05 s): its finest is the former fixed default, so a default answer
/// costs at most 2.25 times what the former default run did (its runs
/// at 0.2 + 0.1 + 0.05 s and the segment check at 0.05 s on half the
/// segments: 1 + 2 + 4 + 2 units of the 0.2 s run, against 4).
pub const DEFAULT_LEVELS: usize = 3;
/// Rungs the default ladder may add below its finest step for a damped
/// tether whose winch changes its rate or acceleration (down to
/// [`AXIAL_STEPS_PER_PERIOD`] steps per axial period at the shortest
/// length: 0.05 s / 2⁶ = 0.78 ms at most).
pub const MAX_EXTRA_LEVELS: usize = 6;
/// Steps per period of the first axial mode that resolve the waves a
/// change of the winch rings (measured on a 2 s ramp, see
/// `tests/verification_dynamics_converged.rs`).
pub const AXIAL_STEPS_PER_PERIOD: f64 = 32.0;
/// The step of `/dynamics/peaks` samples without a `numerics.time_step_s` (s).
pub const PEAKS_TIME_STEP_S: f64 = 0.05;

/// How the step and segments are chosen ([`super::converged`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Ladder {
    /// Steps of the runs, coarse to fine, each half the one before
    /// (default: from [`BASE_TIME_STEP_S`], stopping at the first that
    /// agrees with the one before; fixed: twice the request's, the
    /// request's).
    pub time_steps_s: Vec<f64>,
    /// The ladder may stop only at a step at most this long (s): the step
    /// that resolves the axial waves a winch change rings, when the ladder
    /// was extended for them (agreement above it can be by chance);
    /// otherwise infinite.
    pub stop_at_or_below_s: f64,
    /// Segments of every run but the segment check.
    pub segments: usize,
    /// Segments of the segment check at the answer's step (half, at least
    /// 2; equal to `segments`: no check).
    pub check_segments: usize,
    pub tolerance: f64,
    /// Whether the tolerance chooses the step (the request fixed neither
    /// `numerics.segments` nor `numerics.time_step_s`).
    pub enforced: bool,
}

/// A validated request: the problem, the configuration, and what the
/// answer needs beside them.
#[derive(Clone, Debug)]
pub struct Prepared {
    pub problem: DynamicsProblem,
    /// The configuration of the finest run (the answer's when fixed).
    pub config: DynamicsConfig,
    pub breaking_strength_n: Option<f64>,
    /// Steps of the finest run.
    pub steps: usize,
    pub ladder: Ladder,
}

impl Prepared {
    /// Segment-steps of the finest run.
    pub fn work(&self) -> f64 {
        self.steps as f64 * self.config.segments as f64
    }

    /// Every run the request may make, `(steps, segments)`: the ladder's
    /// steps and the segment check at the finest.
    pub fn planned_runs(&self) -> Vec<(usize, usize)> {
        let d = self.config.duration_s;
        let mut runs: Vec<(usize, usize)> = self
            .ladder
            .time_steps_s
            .iter()
            .map(|&h| (step_count(d, h) as usize, self.ladder.segments))
            .collect();
        if self.ladder.check_segments != self.ladder.segments {
            runs.push((self.steps, self.ladder.check_segments));
        }
        runs
    }

    /// Segment-steps of every run the request may make.
    pub fn total_work(&self) -> f64 {
        self.planned_runs()
            .iter()
            .map(|&(s, n)| s as f64 * n as f64)
            .sum()
    }
}

/// The default ladder of a damped tether whose winch changes its rate or
/// acceleration within the run: the changes ring the axial waves, which
/// the default steps do not resolve (a 2 s ramp's peak changes by 3–8 %
/// per halving down to 0.0125 s), so the ladder goes on halving until a
/// step resolves them ([`AXIAL_STEPS_PER_PERIOD`] per period at the
/// shortest length), at most [`MAX_EXTRA_LEVELS`] more rungs and within
/// the step limits, and may stop only at that finest rung: above it the
/// figures can agree by chance (a 1 s stop in 8 m/s agreed within 1 % at
/// 0.0125 s, where the 32nd of the period is 0.0088 s, and the minimum
/// winch tension then moved by 5.3 N at half the step against an
/// estimate of 4.2 N). Undamped, the waves ring on: the figures of the same 2 s ramp
/// still move by 0.3 % of their scale between 0.003125 and 0.0016 s, three
/// times the change the estimate gave, so finer steps are not offered as
/// converged (the refusal names the waves and the damping). The new finest step and its
/// count, when rungs were added.
fn extend_for_winch_changes(
    ladder: &mut Ladder,
    problem: &DynamicsProblem,
    duration_s: f64,
) -> Option<(f64, usize)> {
    if !ladder.enforced
        || problem.tether.internal_damping_n_s <= 0.0
        || problem.length.breakpoints_s(duration_s).is_empty()
    {
        return None;
    }
    let needed = problem.shortest_axial_period_s(duration_s) / AXIAL_STEPS_PER_PERIOD;
    if *ladder.time_steps_s.last().expect("a step") <= needed {
        return None;
    }
    let mut added = None;
    for _ in 0..MAX_EXTRA_LEVELS {
        let h = *ladder.time_steps_s.last().expect("a step");
        if h <= needed {
            break;
        }
        let Ok(n) = check_steps(
            "duration_s",
            "numerics.time_step_s",
            duration_s,
            0.5 * h,
            ladder.segments,
        ) else {
            break;
        };
        ladder.time_steps_s.push(0.5 * h);
        ladder.stop_at_or_below_s = 0.5 * h;
        added = Some((0.5 * h, n));
    }
    added
}

/// The reference height of a flow (m): where a time history's "speed" is
/// read; `None` for a tabulated flow (the aerostat's starting altitude).
fn reference_height(flow: &WindFlowInput) -> Option<f64> {
    match flow {
        WindFlowInput::Uniform { .. } => Some(0.0),
        WindFlowInput::PowerLaw {
            reference_height_m, ..
        }
        | WindFlowInput::LogLaw {
            reference_height_m, ..
        } => Some(*reference_height_m),
        WindFlowInput::Tabulated { .. } => None,
    }
}

impl DynamicsRequest {
    /// The unstretched length in time.
    fn schedule(&self) -> Result<LengthSchedule, InvalidInput> {
        match (&self.tether_length_m, &self.profile) {
            (Some(l), None) => Ok(LengthSchedule::Fixed(require_range(
                "tether_length_m",
                *l,
                MIN_LENGTH_M,
                false,
                20_000.0,
            )?)),
            (None, Some(p)) => {
                let Some(l0) = self.initial_length_m else {
                    return Err(InvalidInput::new(
                        "initial_length_m",
                        "is needed with a profile: the unstretched length at t = 0 in metres",
                    ));
                };
                let l0 = require_range("initial_length_m", l0, MIN_LENGTH_M, false, 10_000.0)?;
                let profile = p.profile(l0)?;
                let schedule = LengthSchedule::Profile(profile);
                // The length must stay on the mesh: sampled finely, profiles
                // being monotone between their knots.
                let n = 4096;
                for i in 0..=n {
                    let t = self.duration_s * i as f64 / n as f64;
                    let l = schedule.at(t).length_m;
                    if !(l.is_finite() && (MIN_LENGTH_M..=20_000.0).contains(&l)) {
                        return Err(InvalidInput::new(
                            "profile",
                            format!(
                                "takes the length to {l:.3} m at t = {t:.2} s; the dynamics needs it between {MIN_LENGTH_M} m and 20000 m over the run (shorten duration_s or add a target_length_m)"
                            ),
                        ));
                    }
                }
                Ok(schedule)
            }
            (Some(_), Some(_)) => Err(InvalidInput::new(
                "profile",
                "give either tether_length_m (a fixed length) or a profile (from initial_length_m), not both",
            )),
            (None, None) => Err(InvalidInput::new(
                "tether_length_m",
                "is required: give the unstretched length in metres, or a profile with initial_length_m",
            )),
        }
    }

    /// The tether (EA is required: the elastic response sets the tension).
    fn tether(&self) -> Result<(Tether, Option<f64>), InvalidInput> {
        let cable = self.cable.cable("cable")?;
        let Some(ea) = cable.axial_stiffness_n else {
            return Err(InvalidInput::new(
                "cable.axial_stiffness_n",
                "is needed by the dynamics (the tether's elastic response sets the peak tension): give EA in newtons, or a cable preset",
            ));
        };
        Ok((
            Tether {
                mass_per_length_kg_m: cable.mass_per_length_kg_m,
                diameter_m: cable.diameter_m,
                normal_drag_coefficient: cable.normal_drag_coefficient,
                tangential_drag_coefficient: require_range(
                    "tangential_drag_coefficient_nondim",
                    self.tangential_drag_coefficient_nondim,
                    0.0,
                    false,
                    1.0,
                )?,
                axial_stiffness_n: ea,
                internal_damping_n_s: require_range(
                    "internal_damping_n_s",
                    self.internal_damping_n_s,
                    0.0,
                    false,
                    1e12,
                )?,
                drag_on_stretched_length: true,
            },
            cable.breaking_strength_n,
        ))
    }

    fn aerostat(&self) -> Result<Aerostat, InvalidInput> {
        let body = self.aerostat.body("aerostat")?;
        Ok(Aerostat {
            net_buoyancy_n: body.net_buoyancy_n,
            mass_kg: self.aerostat.mass("aerostat")?,
            reference_area_m2: body.reference_area_m2,
            drag_coefficient: body.drag_coefficient,
            lift_coefficient: body.lift_coefficient,
            added_mass_coefficient: self.aerostat.added_mass_coefficient("aerostat")?,
        })
    }

    /// Checks the time history's fields (bounds of the schema).
    fn check_time_history(&self, time_step_s: f64) -> Result<(), InvalidInput> {
        let at = |n: &str| format!("wind.time_history.{n}");
        let time = |n: &str, v: f64| require_range(&at(n), v, 0.0, false, 1e6);
        let span = |n: &str, v: f64| require_range(&at(n), v, 0.0, true, 1e6);
        match self.wind.time_history {
            None => {}
            Some(TimeHistoryInput::Step { time_s, speed_m_s }) => {
                time("time_s", time_s)?;
                require_range(&at("speed_m_s"), speed_m_s, -150.0, false, 150.0)?;
            }
            Some(TimeHistoryInput::Ramp {
                start_time_s,
                duration_s,
                speed_m_s,
            }) => {
                time("start_time_s", start_time_s)?;
                span("duration_s", duration_s)?;
                require_range(&at("speed_m_s"), speed_m_s, -150.0, false, 150.0)?;
            }
            Some(TimeHistoryInput::OneMinusCosine {
                start_time_s,
                duration_s,
                amplitude_m_s,
            }) => {
                time("start_time_s", start_time_s)?;
                span("duration_s", duration_s)?;
                require_range(&at("amplitude_m_s"), amplitude_m_s, -100.0, false, 100.0)?;
                // A gust shorter than the steps falls between them: the run
                // would never see the wind it is compared with.
                if duration_s < 4.0 * time_step_s {
                    return Err(InvalidInput::new(
                        at("duration_s"),
                        format!(
                            "must be at least four time steps ({} s) for the gust to be resolved, got {duration_s}",
                            4.0 * time_step_s
                        ),
                    ));
                }
            }
            Some(TimeHistoryInput::Sinusoid {
                amplitude_m_s,
                period_s,
            }) => {
                require_range(&at("amplitude_m_s"), amplitude_m_s, -100.0, false, 100.0)?;
                span("period_s", period_s)?;
                if period_s < 4.0 * time_step_s {
                    return Err(InvalidInput::new(
                        at("period_s"),
                        format!(
                            "must be at least four time steps ({} s) to be resolved, got {period_s}",
                            4.0 * time_step_s
                        ),
                    ));
                }
            }
            Some(TimeHistoryInput::Turbulence {
                turbulence_intensity_nondim,
                length_scale_m,
                seed,
                ..
            }) => {
                require_range(
                    &at("turbulence_intensity_nondim"),
                    turbulence_intensity_nondim,
                    0.0,
                    false,
                    1.0,
                )?;
                require_range(&at("length_scale_m"), length_scale_m, 0.0, true, 1e5)?;
                if seed > MAX_SEED {
                    return Err(InvalidInput::new(
                        at("seed"),
                        format!("must be at most {MAX_SEED} (2^53 − 1), got {seed}"),
                    ));
                }
            }
        }
        Ok(())
    }

    /// The coarsest default step (s): [`BASE_TIME_STEP_S`], or a quarter
    /// of the shortest gust or sinusoid period when that is shorter (each
    /// step of the ladder then resolves it with at least four steps).
    fn base_time_step(&self) -> f64 {
        let feature = match self.wind.time_history {
            Some(TimeHistoryInput::OneMinusCosine { duration_s, .. }) => duration_s,
            Some(TimeHistoryInput::Sinusoid { period_s, .. }) => period_s,
            _ => f64::INFINITY,
        };
        BASE_TIME_STEP_S.min(0.25 * feature).max(1e-4)
    }

    /// The gusts and turbulence of the time history over `flow`;
    /// `start_altitude_m` is where a tabulated flow's speed is read.
    fn wind_in_time(
        &self,
        flow: &WindProfile,
        start_altitude_m: f64,
    ) -> (Vec<GustHistory>, Option<Turbulence>) {
        let z_ref = reference_height(&self.wind.flow).unwrap_or(start_altitude_m);
        let change_to = |speed: f64| speed - flow.speed_m_s(z_ref);
        match self.wind.time_history.clone() {
            None => (vec![], None),
            Some(TimeHistoryInput::Step { time_s, speed_m_s }) => (
                vec![GustHistory::Step {
                    time_s,
                    change_m_s: change_to(speed_m_s),
                }],
                None,
            ),
            Some(TimeHistoryInput::Ramp {
                start_time_s,
                duration_s,
                speed_m_s,
            }) => (
                vec![GustHistory::Ramp {
                    start_time_s,
                    duration_s,
                    change_m_s: change_to(speed_m_s),
                }],
                None,
            ),
            Some(TimeHistoryInput::OneMinusCosine {
                start_time_s,
                duration_s,
                amplitude_m_s,
            }) => (
                vec![GustHistory::OneMinusCosine {
                    start_time_s,
                    duration_s,
                    amplitude_m_s,
                }],
                None,
            ),
            Some(TimeHistoryInput::Sinusoid {
                amplitude_m_s,
                period_s,
            }) => (
                vec![GustHistory::Sinusoid {
                    amplitude_m_s,
                    period_s,
                }],
                None,
            ),
            Some(TimeHistoryInput::Turbulence {
                model,
                turbulence_intensity_nondim,
                length_scale_m,
                seed,
            }) => (
                vec![],
                Some(Turbulence {
                    model: match model {
                        TurbulenceModelInput::VonKarman => SpectrumModel::VonKarman,
                        TurbulenceModelInput::Kaimal => SpectrumModel::Kaimal,
                    },
                    intensity: turbulence_intensity_nondim,
                    length_scale_m,
                    seed,
                }),
            ),
        }
    }

    /// The validated problem and configuration (no dynamic step taken; the
    /// §6 equilibrium at the start is solved for a tabulated flow's
    /// reference).
    pub fn prepare(&self) -> Result<Prepared, InvalidInput> {
        let (tether, breaking_strength_n) = self.tether()?;
        let aerostat = self.aerostat()?;
        let flow = self.wind.flow.profile("wind.flow")?;
        let air = bounds::AIR_DENSITY_KG_M3.check_at("wind", self.wind.air_density_kg_m3)?;
        let gravity = bounds::GRAVITY_M_S2.check(self.gravity_m_s2)?;
        bounds::REQUIRED_SAFETY_FACTOR.check(self.required_safety_factor_nondim)?;
        check_rest(self.winch.as_ref(), None, self.lift_reserve_nondim)?;
        let duration = require_range("duration_s", self.duration_s, 0.0, true, MAX_DURATION_S)?;
        let n = &self.numerics;
        let segments = check_segments("numerics.segments", n.segments.unwrap_or(DEFAULT_SEGMENTS))?;
        let tolerance = require_range(
            "numerics.tolerance_nondim",
            n.tolerance_nondim.unwrap_or(converged::DEFAULT_TOLERANCE),
            converged::MIN_TOLERANCE,
            false,
            converged::MAX_TOLERANCE,
        )?;
        let enforced = n.segments.is_none() && n.time_step_s.is_none();
        let time_steps_s = match n.time_step_s {
            Some(dt) => {
                let dt = require_range("numerics.time_step_s", dt, 1e-4, false, 10.0)?;
                vec![2.0 * dt, dt]
            }
            None => {
                let h0 = self.base_time_step();
                if enforced {
                    (0..DEFAULT_LEVELS)
                        .map(|k| h0 * 0.5f64.powi(k as i32))
                        .collect()
                } else {
                    // Segments fixed, the step not: the finest default step.
                    let h = h0 * 0.5f64.powi(DEFAULT_LEVELS as i32 - 1);
                    vec![2.0 * h, h]
                }
            }
        };
        let mut dt = *time_steps_s.last().expect("a step");
        let rho_inf =
            check_spectral_radius("numerics.spectral_radius_nondim", n.spectral_radius_nondim)?;
        let mut steps = check_steps("duration_s", "numerics.time_step_s", duration, dt, segments)?;
        let mut ladder = Ladder {
            time_steps_s,
            stop_at_or_below_s: f64::INFINITY,
            segments,
            check_segments: (segments / 2).max(MIN_SEGMENTS),
            tolerance,
            enforced,
        };
        let count = check_sample_count("sample_count", self.sample_count)?;
        let sample_interval = duration / (count - 1) as f64;
        let shape_times = match &self.shape_times_s {
            Some(_) if self.shape_count.is_some() => {
                return Err(InvalidInput::new(
                    "shape_count",
                    "give either `shape_count` (evenly spaced shapes) or `shape_times_s` (the \
                     times of the shapes), not both: the two contradict each other unless they \
                     say the same",
                ));
            }
            Some(times) => {
                check_shape_times("shape_times_s", times)?;
                for (i, t) in times.iter().enumerate() {
                    require_range(&format!("shape_times_s[{i}]"), *t, 0.0, false, duration)?;
                }
                times.clone()
            }
            None => {
                let k = check_shape_count(
                    "shape_count",
                    self.shape_count.unwrap_or(super::dto::DEFAULT_SHAPE_COUNT),
                )?;
                match k {
                    0 => vec![],
                    1 => vec![duration],
                    k => (0..k)
                        .map(|i| duration * i as f64 / (k - 1) as f64)
                        .collect(),
                }
            }
        };
        if shape_times.len() * (segments + 1) > MAX_SHAPE_NODES {
            return Err(InvalidInput::new(
                if self.shape_times_s.is_some() {
                    "shape_times_s"
                } else {
                    "shape_count"
                },
                format!(
                    "{} shapes of {} nodes exceed {MAX_SHAPE_NODES} nodes: keep fewer shapes or segments",
                    shape_times.len(),
                    segments + 1
                ),
            ));
        }
        self.check_time_history(dt)?;
        let length = self.schedule()?;
        let mut problem = DynamicsProblem {
            tether,
            aerostat,
            flow,
            gusts: vec![],
            turbulence: None,
            air_density_kg_m3: air,
            gravity_m_s2: gravity,
            length,
        };
        problem.validate()?;
        if let Some((h, n)) = extend_for_winch_changes(&mut ladder, &problem, duration) {
            (dt, steps) = (h, n);
        }
        // A tabulated flow's "speed" is read at the aerostat's starting altitude.
        let start_altitude =
            if reference_height(&self.wind.flow).is_none() && self.wind.time_history.is_some() {
                let l0 = problem.length.at(0.0).length_m;
                problem
                    .static_problem(l0)
                    .solve(&EquilibriumConfig {
                        steps: segments.max(50),
                        max_iterations: 60,
                        keep_shape: false,
                    })?
                    .altitude_m
            } else {
                0.0
            };
        let (gusts, turbulence) = self.wind_in_time(&problem.flow, start_altitude);
        problem.gusts = gusts;
        problem.turbulence = turbulence;
        let config = DynamicsConfig {
            segments,
            time_step_s: dt,
            duration_s: duration,
            spectral_radius: rho_inf,
            sample_interval_s: sample_interval,
            shape_times_s: shape_times,
            wind_probe_height_m: self
                .wind_probe_height_m
                .map(|z| require_range("wind_probe_height_m", z, 0.0, false, 30_000.0))
                .transpose()?,
            ..DynamicsConfig::default()
        };
        Ok(Prepared {
            problem,
            config,
            breaking_strength_n,
            steps,
            ladder,
        })
    }
}
