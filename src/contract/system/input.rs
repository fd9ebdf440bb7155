//! The request parts every domain shares (SPEC §9): the system with its
//! model and accuracy ([`SystemInput`], [`ModelInput`], [`NumericsInput`]),
//! the deployment profile L(t) ([`ProfileInput`]), the keys that split a
//! flattened body into its system and its parameters ([`SYSTEM_KEYS`],
//! [`SystemRequest`]), and their conversion to the numerical core's
//! [`AerostatSystem`], [`StringModel`] and [`Profile`]. The string, the
//! transient runs, the GE dispatch, the plan and the bands import them
//! from here, not from one another's folders.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::{AerostatInput, CableInput, WinchInput, WindInput};
use crate::numerics::params::{AerostatSystem, InvalidInput};
use crate::numerics::profile::Profile;
use crate::numerics::string::StringModel;
use crate::numerics::string::chart;
use crate::numerics::string::converged;

/// Which cable model, and its discretisation.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct ModelInput {
    /// Model kind.
    #[serde(default)]
    pub kind: ModelKind,
    /// Number of uniform finite elements (2..=2000). Omitted: every
    /// stability answer (t*, h*, safe rate, chart points) is converged to
    /// `numerics.relative_tolerance` on meshes graded toward the roller and
    /// given on the safe side of its error bound; the spectrum of
    /// `/stability` and transient runs use 50 elements. Given: that mesh's
    /// values, with their estimated error.
    #[serde(default)]
    #[schema(example = 50, minimum = 2, maximum = 2000)]
    pub elements: Option<usize>,
}

impl Default for ModelInput {
    fn default() -> Self {
        Self {
            kind: ModelKind::LinearString,
            elements: None,
        }
    }
}

/// Elements of the uniform mesh used for spectra and transient runs when
/// `model.elements` is omitted.
pub const DEFAULT_ELEMENTS: usize = 50;

impl ModelInput {
    /// The uniform mesh size: the one asked for, or [`DEFAULT_ELEMENTS`].
    pub fn mesh_elements(&self) -> usize {
        self.elements.unwrap_or(DEFAULT_ELEMENTS)
    }
}

/// Accuracy of converged answers.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
pub struct NumericsInput {
    /// Relative tolerance of converged answers (t*, h*, safe rate) when
    /// `model.elements` is omitted.
    #[serde(default = "default_relative_tolerance")]
    #[schema(example = 1e-4, minimum = 1e-8, maximum = 1e-2)]
    pub relative_tolerance: f64,
}

impl Default for NumericsInput {
    fn default() -> Self {
        Self {
            relative_tolerance: default_relative_tolerance(),
        }
    }
}

fn default_relative_tolerance() -> f64 {
    crate::numerics::string::converged::DEFAULT_RELATIVE_TOLERANCE
}

#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, ToSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum ModelKind {
    /// Linear string with end mass (thesis ch. 2–4).
    #[default]
    LinearString,
}

/// The keys of [`SystemInput`]: a flattened request gives these to the
/// system part and the rest to its parameters.
pub const SYSTEM_KEYS: &[&str] = &[
    "cable",
    "aerostat",
    "initial_length_m",
    "gravity_m_s2",
    "numerics",
    "model",
    "wind",
    "winch",
    "required_safety_factor_nondim",
    "lift_reserve_nondim",
];

/// The physical system and its model: common to every request.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct SystemInput {
    pub cable: CableInput,
    pub aerostat: AerostatInput,
    /// Initial cable length L0 (m), the length scale.
    #[serde(default = "default_initial_length")]
    #[schema(example = 1.0, minimum = 0.001, maximum = 10000.0)]
    pub initial_length_m: f64,
    /// Gravitational acceleration (m/s²).
    #[serde(default = "default_gravity")]
    #[schema(example = 9.81, minimum = 0.01, maximum = 100.0)]
    pub gravity_m_s2: f64,
    #[serde(default)]
    pub model: ModelInput,
    /// Accuracy of converged answers.
    #[serde(default)]
    pub numerics: NumericsInput,
    /// The air: accepted with the whole system, but this analysis is in calm
    /// air, so a non-zero wind is refused (naming `wind.flow`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wind: Option<WindInput>,
    /// The winch limits (used by the plan; checked here).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub winch: Option<WinchInput>,
    /// Safety factor required on the breaking strength (default 5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 5.0, minimum = 1.0, maximum = 100.0)]
    pub required_safety_factor_nondim: Option<f64>,
    /// Lift reserve (used by the plan; checked here).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 0.05, minimum = 0.0, maximum = 0.9)]
    pub lift_reserve_nondim: Option<f64>,
}

fn default_initial_length() -> f64 {
    1.0
}

fn default_gravity() -> f64 {
    9.81
}

/// A deployment profile L(t). Positive rates lengthen, negative shorten.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(tag = "kind", rename_all = "snake_case")]
#[serde(deny_unknown_fields)]
pub enum ProfileInput {
    /// L = L0 + v t.
    ConstantRate {
        /// Winch rate v (m/s); negative retrieves.
        #[schema(example = 10.0, minimum = -1000.0, maximum = 1000.0)]
        rate_m_s: f64,
        /// Length at which the winch stops (m); none: never stops.
        #[serde(default)]
        #[schema(minimum = 0.001, maximum = 1e5)]
        target_length_m: Option<f64>,
    },
    /// From rest: L = L0 + a t²/2.
    ConstantAcceleration {
        /// Winch acceleration a (m/s²); negative retrieves.
        #[schema(example = 0.5, minimum = -1000.0, maximum = 1000.0)]
        acceleration_m_s2: f64,
        /// Length at which the winch stops (m); none: never stops.
        #[serde(default)]
        #[schema(minimum = 0.001, maximum = 1e5)]
        target_length_m: Option<f64>,
    },
    /// Rate ramps linearly from 0 to the cruise rate, holds, and ramps back
    /// to 0, arriving at rest at the target length (thesis Figs 4.8–4.9).
    Trapezoidal {
        /// Cruise rate (m/s); negative retrieves.
        #[schema(example = 10.0, minimum = -1000.0, maximum = 1000.0)]
        cruise_rate_m_s: f64,
        /// Ramp-up time (s), > 0: short is sharp, long is gradual.
        #[schema(example = 5.0, minimum = 1e-6, maximum = 1e7)]
        ramp_up_s: f64,
        /// Ramp-down time (s), > 0.
        #[schema(example = 5.0, minimum = 1e-6, maximum = 1e7)]
        ramp_down_s: f64,
        /// Length at which the winch comes to rest (m).
        #[schema(example = 1100.0, minimum = 0.001, maximum = 1e5)]
        target_length_m: f64,
    },
    /// Rate interpolated linearly in a table of (time, rate), first time 0;
    /// the last rate is held after the table.
    PiecewiseLinearRate {
        /// The table, times strictly increasing (at most 10000 points).
        points: Vec<RatePointInput>,
        /// Length at which the winch stops (m); none: the table decides.
        #[serde(default)]
        #[schema(minimum = 0.001, maximum = 1e5)]
        target_length_m: Option<f64>,
    },
}

/// One point of a rate table.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct RatePointInput {
    /// Time (s).
    #[schema(example = 0.0, minimum = 0.0, maximum = 1e7)]
    pub time_s: f64,
    /// Winch rate at that time (m/s).
    #[schema(example = 10.0, minimum = -1000.0, maximum = 1000.0)]
    pub rate_m_s: f64,
}

/// A request made of the common system part and its own parameters;
/// the two are parsed separately so that every error names its field
/// (serde loses the path inside `#[serde(flatten)]`).
pub trait SystemRequest: Sized {
    type Params: serde::de::DeserializeOwned;
    fn from_parts(system: SystemInput, params: Self::Params) -> Self;
    /// The plausible-magnitude checks of both parts (field and range named).
    fn check_ranges(&self) -> Result<(), crate::numerics::params::InvalidInput> {
        Ok(())
    }
}

impl SystemInput {
    pub fn system(&self) -> Result<AerostatSystem, InvalidInput> {
        let sys = AerostatSystem::new(
            self.cable.mass_per_length()?,
            self.aerostat.net_buoyancy("aerostat")?,
            self.aerostat.mass("aerostat")?,
            self.initial_length_m,
            self.gravity_m_s2,
        )?;
        self.check_calm_system("the string model")?;
        check_scales(&sys)?;
        Ok(sys)
    }

    /// The whole system is accepted; its parts this calm-air analysis does
    /// not use are checked against their bounds, and a non-zero wind is
    /// refused (naming `wind.flow`).
    pub fn check_calm_system(&self, analysis: &str) -> Result<(), InvalidInput> {
        use crate::contract::system::validate as v;
        self.cable.check_given("cable")?;
        self.aerostat.check_given("aerostat")?;
        if let Some(w) = &self.wind {
            w.check()?;
        }
        WindInput::require_calm(self.wind.as_ref(), analysis)?;
        if let Some(w) = &self.winch {
            w.check("winch")?;
        }
        if let Some(f) = self.required_safety_factor_nondim {
            v::required_safety_factor(f)?;
        }
        if let Some(r) = self.lift_reserve_nondim {
            v::lift_reserve(r)?;
        }
        Ok(())
    }

    pub fn model(&self) -> Result<StringModel, InvalidInput> {
        let system = self.system()?;
        match self.model.kind {
            ModelKind::LinearString => StringModel::new(system, self.model.mesh_elements()),
        }
    }

    /// Converged (elements omitted) or that uniform mesh.
    pub fn discretisation(&self) -> Result<chart::Discretisation, InvalidInput> {
        let tolerance = converged::validate_tolerance(
            "numerics.relative_tolerance",
            self.numerics.relative_tolerance,
        )?;
        Ok(match self.model.elements {
            Some(n) => chart::Discretisation::Elements(n),
            None => chart::Discretisation::Converged {
                relative_tolerance: tolerance,
            },
        })
    }
}

impl ProfileInput {
    pub fn profile(&self, initial_length_m: f64) -> Result<Profile, InvalidInput> {
        match *self {
            Self::Trapezoidal {
                cruise_rate_m_s,
                ramp_up_s,
                ramp_down_s,
                target_length_m,
            } => Profile::trapezoidal(
                initial_length_m,
                cruise_rate_m_s,
                ramp_up_s,
                ramp_down_s,
                target_length_m,
            ),
            Self::PiecewiseLinearRate {
                ref points,
                target_length_m,
            } => {
                let table: Vec<(f64, f64)> =
                    points.iter().map(|p| (p.time_s, p.rate_m_s)).collect();
                Profile::piecewise_linear_rate(initial_length_m, &table, target_length_m)
            }
            Self::ConstantRate {
                rate_m_s,
                target_length_m,
            } => Profile::constant_rate(initial_length_m, rate_m_s, target_length_m),
            Self::ConstantAcceleration {
                acceleration_m_s2,
                target_length_m,
            } => {
                Profile::constant_acceleration(initial_length_m, acceleration_m_s2, target_length_m)
            }
        }
    }
}

/// Backstop against parameters so far apart that the scales of the
/// problem overflow or vanish in f64 (ρA = 1e308 kg/m with F = 1e-216 N):
/// every answer would carry infinities or zeros where numbers belong.
fn check_scales(sys: &AerostatSystem) -> Result<(), InvalidInput> {
    let scales = [
        ("wave speed", sys.wave_speed_m_s()),
        ("time scale", sys.time_scale_s()),
        ("buoyancy ratio", sys.buoyancy_ratio()),
        ("static lift limit", sys.static_lift_limit_m()),
    ];
    for (name, v) in scales {
        if !(v.is_finite() && v > 1e-150 && v < 1e150) {
            return Err(InvalidInput::new(
                "cable.mass_per_length_kg_m",
                format!(
                    "with this cable, net buoyancy, length and gravity the {name} is {v:e}: \
                     the parameters are too far apart to compute with"
                ),
            ));
        }
    }
    let m = sys.mass_ratio();
    if !(m.is_finite() && m < 1e150) {
        return Err(InvalidInput::new(
            "aerostat.mass_kg",
            format!("the mass ratio m/(ρA L0) is {m:e}: too large to compute with"),
        ));
    }
    Ok(())
}
