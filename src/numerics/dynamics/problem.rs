//! What a dynamic run is asked (SPEC §11): the tether, the aerostat, the
//! steady flow and its changes in time, the unstretched length in time
//! ([`DynamicsProblem`]); the mesh, step, outputs and iteration settings
//! ([`DynamicsConfig`]); and their checks (fields named as in the JSON
//! contract).

use super::limits;
use super::model::{Length, Parameters};
use super::wind::{GustHistory, Turbulence};
use crate::numerics::params::{InvalidInput, require_non_negative, require_positive};
use crate::numerics::profile::Profile;
use crate::numerics::tether::equilibrium::{Body, Cable, EquilibriumProblem};
use crate::numerics::tether::wind::WindProfile;

/// The tether's properties.
#[derive(Clone, Debug, PartialEq)]
pub struct Tether {
    /// ρA (kg/m).
    pub mass_per_length_kg_m: f64,
    /// Diameter `d` (m).
    pub diameter_m: f64,
    /// Normal drag coefficient `C_n`.
    pub normal_drag_coefficient: f64,
    /// Tangential (skin-friction) drag coefficient `C_t` on `π d`; 0: none.
    pub tangential_drag_coefficient: f64,
    /// `EA` (N).
    pub axial_stiffness_n: f64,
    /// Kelvin–Voigt damping `c` (N s): `T = EA ε + c ε̇`.
    pub internal_damping_n_s: f64,
    /// Drag on the stretched length (SPEC §6) or on the unstretched one (MoorDyn).
    pub drag_on_stretched_length: bool,
}

/// The aerostat.
#[derive(Clone, Debug, PartialEq)]
pub struct Aerostat {
    /// Net buoyancy `F` (N).
    pub net_buoyancy_n: f64,
    /// Structural mass `m` (kg).
    pub mass_kg: f64,
    pub reference_area_m2: f64,
    pub drag_coefficient: f64,
    pub lift_coefficient: f64,
    /// `C_a` on the displaced air mass.
    pub added_mass_coefficient: f64,
}

impl Aerostat {
    /// Displaced volume `V = (F + m g)/(ρ g)` (m³).
    pub fn displaced_volume_m3(&self, air_density: f64, gravity: f64) -> f64 {
        (self.net_buoyancy_n + self.mass_kg * gravity) / (air_density * gravity)
    }
}

/// The unstretched length in time.
#[derive(Clone, Debug, PartialEq)]
pub enum LengthSchedule {
    Fixed(f64),
    Profile(Profile),
}

impl LengthSchedule {
    pub fn at(&self, t: f64) -> Length {
        match self {
            Self::Fixed(l) => Length {
                length_m: *l,
                rate_m_s: 0.0,
                acceleration_m_s2: 0.0,
            },
            Self::Profile(p) => {
                let k = p.kinematics(t);
                Length {
                    length_m: k.length_m,
                    rate_m_s: k.rate_m_s,
                    acceleration_m_s2: k.acceleration_m_s2,
                }
            }
        }
    }

    /// The times in `(0, until]` at which the rate or the acceleration may
    /// jump (a profile's stop, a rate table's knots), increasing: the run
    /// steps onto each (see `Stepper::rate_jump`).
    pub fn breakpoints_s(&self, until_s: f64) -> Vec<f64> {
        let Self::Profile(p) = self else {
            return vec![];
        };
        let mut times: Vec<f64> = match p {
            Profile::Trapezoidal { schedule, .. }
            | Profile::PiecewiseLinearRate { schedule, .. } => schedule.knot_times_s().to_vec(),
            _ => vec![],
        };
        times.extend(p.stop_time_s());
        times.retain(|t| t.is_finite() && *t > 0.0 && *t <= until_s);
        times.sort_by(f64::total_cmp);
        times.dedup();
        times
    }

    /// The rate just before `t` (m/s): the left limit at a breakpoint.
    pub fn rate_before_m_s(&self, t_s: f64) -> f64 {
        let dt = 1e-9 * t_s.abs().max(1.0);
        let k = self.at(t_s - dt);
        k.rate_m_s + k.acceleration_m_s2 * dt
    }

    /// The longest length over `[0, until]` (sampled; profiles are monotone between knots).
    pub fn longest_m(&self, until_s: f64) -> f64 {
        self.sampled(until_s).fold(0.0, f64::max)
    }

    /// The shortest length over `[0, until]` (sampled as [`Self::longest_m`]).
    pub fn shortest_m(&self, until_s: f64) -> f64 {
        self.sampled(until_s).fold(f64::INFINITY, f64::min)
    }

    fn sampled(&self, until_s: f64) -> impl Iterator<Item = f64> + '_ {
        (0..=512).map(move |i| self.at(until_s * i as f64 / 512.0).length_m)
    }
}

/// One dynamic problem (SI).
#[derive(Clone, Debug, PartialEq)]
pub struct DynamicsProblem {
    pub tether: Tether,
    pub aerostat: Aerostat,
    /// The steady flow `U(z)`.
    pub flow: WindProfile,
    /// Uniform changes `ΔU(t)`, summed.
    pub gusts: Vec<GustHistory>,
    pub turbulence: Option<Turbulence>,
    pub air_density_kg_m3: f64,
    pub gravity_m_s2: f64,
    pub length: LengthSchedule,
}

/// Discretisation, output and iteration settings.
#[derive(Clone, Debug, PartialEq)]
pub struct DynamicsConfig {
    pub segments: usize,
    /// The step `h` (s). The default 0.1 s is set by accuracy on the
    /// reference tether (`benches/dynamics.rs`, `step_study`): one hour of
    /// von Kármán turbulence gives the peak winch tension within 0.03 % of
    /// h = 0.0125 s (512.44 against 512.60 N; 0.004 % at 0.05 s, 0.17 % at
    /// 0.2 s) and every 1 s sample within 4.1 N (0.8 % of the peak; 3.4 N
    /// at 0.05 s); the gust case stays within the MoorDyn tolerance of
    /// `tests/peer_moordyn.rs`.
    pub time_step_s: f64,
    pub duration_s: f64,
    /// Spectral radius at infinite frequency `ρ∞ ∈ [0, 1]`.
    pub spectral_radius: f64,
    /// Time between kept samples (s); every step is still checked for peaks and slack.
    pub sample_interval_s: f64,
    /// Times at which the shape is kept (s).
    pub shape_times_s: Vec<f64>,
    /// Newton stops when its estimated velocity error is below this (m/s):
    /// the largest velocity correction, times `θ/(1 − θ)` with `θ` the
    /// observed contraction (Hairer & Wanner; see the integrator), or the
    /// correction itself; positions are then off by about `tol · β h/γ`.
    pub newton_tolerance_m_s: f64,
    pub max_newton_iterations: usize,
    /// Sample spacing of a turbulence series (s).
    pub turbulence_time_step_s: f64,
    /// Level spacing of a turbulence field (m), at most.
    pub turbulence_level_spacing_m: f64,
    /// Height of the fixed point where the wind is probed (m), above the
    /// aerostat's starting station downwind; `None`: the aerostat's
    /// starting altitude.
    pub wind_probe_height_m: Option<f64>,
}

impl Default for DynamicsConfig {
    fn default() -> Self {
        Self {
            segments: 50,
            time_step_s: 0.1,
            duration_s: 600.0,
            spectral_radius: 0.8,
            sample_interval_s: 1.0,
            shape_times_s: vec![],
            newton_tolerance_m_s: 1e-6,
            max_newton_iterations: 30,
            turbulence_time_step_s: 0.2,
            turbulence_level_spacing_m: 50.0,
            wind_probe_height_m: None,
        }
    }
}

impl DynamicsProblem {
    /// The period of the tether's first axial mode at its shortest length
    /// over `[0, until]`, `4 L/c` with `c = √(EA/ρA)` (s): the waves a
    /// change of the winch's rate or acceleration rings.
    pub fn shortest_axial_period_s(&self, until_s: f64) -> f64 {
        let c = (self.tether.axial_stiffness_n / self.tether.mass_per_length_kg_m).sqrt();
        4.0 * self.length.shortest_m(until_s) / c
    }

    /// `ΔU(t)`, the sum of the gusts (m/s).
    pub fn gust_change_m_s(&self, t: f64) -> f64 {
        self.gusts.iter().map(|g| g.change_m_s(t)).sum()
    }

    /// Checks the problem (fields as named in the JSON contract).
    pub fn validate(&self) -> Result<(), InvalidInput> {
        let t = &self.tether;
        require_positive("cable.mass_per_length_kg_m", t.mass_per_length_kg_m)?;
        require_positive("cable.diameter_m", t.diameter_m)?;
        require_non_negative(
            "cable.normal_drag_coefficient_nondim",
            t.normal_drag_coefficient,
        )?;
        require_non_negative(
            "cable.tangential_drag_coefficient_nondim",
            t.tangential_drag_coefficient,
        )?;
        require_positive("cable.axial_stiffness_n", t.axial_stiffness_n)?;
        require_non_negative("cable.internal_damping_n_s", t.internal_damping_n_s)?;
        let a = &self.aerostat;
        require_positive("aerostat.net_buoyancy_n", a.net_buoyancy_n)?;
        require_non_negative("aerostat.mass_kg", a.mass_kg)?;
        require_positive("aerostat.reference_area_m2", a.reference_area_m2)?;
        require_non_negative("aerostat.drag_coefficient_nondim", a.drag_coefficient)?;
        if !a.lift_coefficient.is_finite() {
            return Err(InvalidInput::new(
                "aerostat.lift_coefficient_nondim",
                "must be a finite number",
            ));
        }
        require_non_negative(
            "aerostat.added_mass_coefficient_nondim",
            a.added_mass_coefficient,
        )?;
        require_positive("wind.air_density_kg_m3", self.air_density_kg_m3)?;
        require_positive("gravity_m_s2", self.gravity_m_s2)?;
        if let LengthSchedule::Fixed(l) = self.length {
            require_positive("tether_length_m", l)?;
        }
        Ok(())
    }

    /// The discretised parameters.
    pub fn parameters(&self, segments: usize) -> Parameters {
        let rho = self.air_density_kg_m3;
        let t = &self.tether;
        let a = &self.aerostat;
        let volume = a.displaced_volume_m3(rho, self.gravity_m_s2);
        Parameters {
            segments,
            mass_per_length_kg_m: t.mass_per_length_kg_m,
            gravity_m_s2: self.gravity_m_s2,
            axial_stiffness_n: t.axial_stiffness_n,
            damping_n_s: t.internal_damping_n_s,
            normal_drag: 0.5 * rho * t.normal_drag_coefficient * t.diameter_m,
            tangential_drag: 0.5
                * rho
                * t.tangential_drag_coefficient
                * std::f64::consts::PI
                * t.diameter_m,
            drag_on_stretched_length: t.drag_on_stretched_length,
            net_buoyancy_n: a.net_buoyancy_n,
            aerostat_inertia_kg: a.mass_kg + a.added_mass_coefficient * rho * volume,
            aerostat_drag: 0.5 * rho * a.drag_coefficient * a.reference_area_m2,
            aerostat_lift: 0.5 * rho * a.lift_coefficient * a.reference_area_m2,
        }
    }

    /// The §6 problem of the steady flow at length `length_m`.
    pub fn static_problem(&self, length_m: f64) -> EquilibriumProblem {
        EquilibriumProblem {
            cable: Cable {
                mass_per_length_kg_m: self.tether.mass_per_length_kg_m,
                diameter_m: self.tether.diameter_m,
                normal_drag_coefficient: self.tether.normal_drag_coefficient,
                axial_stiffness_n: Some(self.tether.axial_stiffness_n),
                breaking_strength_n: None,
            },
            body: Body {
                net_buoyancy_n: self.aerostat.net_buoyancy_n,
                drag_coefficient: self.aerostat.drag_coefficient,
                lift_coefficient: self.aerostat.lift_coefficient,
                reference_area_m2: self.aerostat.reference_area_m2,
            },
            wind: self.flow.clone(),
            air_density_kg_m3: self.air_density_kg_m3,
            tether_length_m: length_m,
            gravity_m_s2: self.gravity_m_s2,
        }
    }
}

/// Why no run was made.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DynamicsError {
    #[error(transparent)]
    Invalid(#[from] InvalidInput),
    /// The steady equilibrium is slack: the lumped model has no ground.
    #[error("the tether is slack in the steady flow at the start (it rests on the ground)")]
    SlackStart,
    #[error("the static Newton iteration did not converge (residual {residual_n} N)")]
    NoStaticEquilibrium { residual_n: f64 },
}

pub(super) fn validate_config(config: &DynamicsConfig) -> Result<(), InvalidInput> {
    limits::check_segments("segments", config.segments)?;
    require_positive("time_step_s", config.time_step_s)?;
    require_positive("duration_s", config.duration_s)?;
    require_positive("sample_interval_s", config.sample_interval_s)?;
    limits::check_spectral_radius("spectral_radius", config.spectral_radius)?;
    limits::check_steps(
        "duration_s",
        "time_step_s",
        config.duration_s,
        config.time_step_s,
        config.segments,
    )?;
    limits::check_sample_interval(
        "sample_interval_s",
        config.duration_s,
        config.sample_interval_s,
    )?;
    limits::check_shape_times("shape_times_s", &config.shape_times_s)
}
