//! Input and output shared by the GE critical-time searches (charts,
//! `/critical`) and the GE stability query: the time-stepping scheme and
//! its stated dissipation, the step cuts, and the cable's motion at the
//! start (or at the queried state).

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::contract::ge::simulate::NewtonInput;
use crate::numerics::ge::critical::{CriticalConfig, MAX_STEP_CUTS, StartState};
use crate::numerics::ge::solver::{NewtonConfig, Scheme};
use crate::numerics::params::{InvalidInput, require_non_negative, require_positive};

/// The time-stepping scheme of a GE march.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, ToSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum SchemeInput {
    /// Newmark average acceleration: no numerical dissipation (ρ∞ = 1).
    AverageAcceleration,
    /// Chung–Hulbert generalized-α with spectral radius ρ∞ (default 0):
    /// unresolved (axial) modes lose the fraction 1 − ρ∞ of their
    /// amplitude per step; resolved modes are kept to second order.
    #[default]
    GeneralizedAlpha,
    /// Hilber–Hughes–Taylor α with spectral radius ρ∞ ∈ [0.5, 1] (default 0.5).
    HhtAlpha,
}

/// Default ρ∞ of generalized-α (the critical-time search's default scheme).
pub const DEFAULT_RHO_INFINITY: f64 = 0.0;
/// Default ρ∞ of HHT-α (its most dissipative member).
pub const DEFAULT_HHT_RHO_INFINITY: f64 = 0.5;
/// Default number of step halvings after a Newton failure.
pub const DEFAULT_MAX_STEP_CUTS: u32 = 8;

pub fn default_scheme() -> SchemeInput {
    SchemeInput::GeneralizedAlpha
}
pub fn default_max_step_cuts() -> u32 {
    DEFAULT_MAX_STEP_CUTS
}

/// The core scheme for `scheme` and `rho_infinity_nondim` (fields named
/// under `prefix`, e.g. `numerics`).
pub fn scheme(
    kind: SchemeInput,
    rho_infinity: Option<f64>,
    prefix: &str,
) -> Result<Scheme, InvalidInput> {
    let field = format!("{prefix}.rho_infinity_nondim");
    let s = match kind {
        SchemeInput::AverageAcceleration => {
            if let Some(r) = rho_infinity.filter(|&r| r != 1.0) {
                return Err(InvalidInput::new(
                    field,
                    format!(
                        "average acceleration has no dissipation (ρ∞ = 1), got {r}: choose `generalized_alpha` or `hht_alpha`"
                    ),
                ));
            }
            Scheme::AverageAcceleration
        }
        SchemeInput::GeneralizedAlpha => Scheme::GeneralizedAlpha {
            rho_infinity: rho_infinity.unwrap_or(DEFAULT_RHO_INFINITY),
        },
        SchemeInput::HhtAlpha => Scheme::HhtAlpha {
            rho_infinity: rho_infinity.unwrap_or(DEFAULT_HHT_RHO_INFINITY),
        },
    };
    s.validate(&field)?;
    Ok(s)
}

/// Checks `max_step_cuts`.
pub fn step_cuts(cuts: u32, prefix: &str) -> Result<u32, InvalidInput> {
    if cuts > MAX_STEP_CUTS {
        return Err(InvalidInput::new(
            format!("{prefix}.max_step_cuts"),
            format!("must be at most {MAX_STEP_CUTS}, got {cuts}"),
        ));
    }
    Ok(cuts)
}

/// The scheme used, with its dissipation stated.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct IntegratorOutput {
    pub scheme: SchemeInput,
    /// Spectral radius as ωΔt → ∞: the amplitude fraction of an
    /// unresolved mode left after one step (1: no dissipation).
    pub rho_infinity_nondim: f64,
    /// α_m, α_f, β, γ of the generalized-α family.
    pub alpha_m_nondim: f64,
    pub alpha_f_nondim: f64,
    pub beta_nondim: f64,
    pub gamma_nondim: f64,
    /// Largest number of halvings of one step after a Newton failure.
    pub max_step_cuts: u32,
    /// The same in words.
    pub description: String,
}

impl IntegratorOutput {
    pub fn new(scheme: Scheme, max_step_cuts: u32) -> Self {
        let c = scheme.coefficients();
        let (kind, name) = match scheme {
            Scheme::AverageAcceleration => (
                SchemeInput::AverageAcceleration,
                "Newmark average acceleration",
            ),
            Scheme::GeneralizedAlpha { .. } => (
                SchemeInput::GeneralizedAlpha,
                "generalized-α (Chung–Hulbert)",
            ),
            Scheme::HhtAlpha { .. } => (SchemeInput::HhtAlpha, "HHT-α"),
        };
        let rho = scheme.rho_infinity();
        let description = if rho < 1.0 {
            format!(
                "{name}, ρ∞ = {rho}: a mode far above the step's resolution keeps {:.0} % of its amplitude per step; \
                 resolved modes are second-order accurate. A failed Newton step is halved and retried up to {max_step_cuts} times.",
                100.0 * rho
            )
        } else {
            format!(
                "{name}: no numerical dissipation (ρ∞ = 1). A failed Newton step is halved and retried up to {max_step_cuts} times."
            )
        };
        Self {
            scheme: kind,
            rho_infinity_nondim: rho,
            alpha_m_nondim: c.alpha_m,
            alpha_f_nondim: c.alpha_f,
            beta_nondim: c.beta,
            gamma_nondim: c.gamma,
            max_step_cuts,
            description,
        }
    }
}

/// How the cable moves when the winch starts (or at a queried state).
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, ToSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum StartStateInput {
    /// Straight static equilibrium; every point moves at the reel-out
    /// rate. A stretched cable should move faster (L̇ (1 + ε)), so an
    /// extensible cable starts with an axial transient.
    #[default]
    AtRest,
    /// Already paying out steadily: every point moves at the speed the
    /// guide feeds it out (no start transient); the state the
    /// quasi-static closed forms assume.
    SteadyPayout,
}

impl From<StartStateInput> for StartState {
    fn from(s: StartStateInput) -> Self {
        match s {
            StartStateInput::AtRest => StartState::AtRest,
            StartStateInput::SteadyPayout => StartState::SteadyPayout,
        }
    }
}

/// Settings of each critical-time search.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct GeChartNumericsInput {
    /// Newmark step (s).
    #[serde(default = "default_dt")]
    #[schema(example = 0.02, minimum = 1e-9, maximum = 1000.0)]
    pub time_step_s: f64,
    /// Local QEP every this many steps (the bracket is then retraced step by step).
    #[serde(default = "default_check")]
    #[schema(example = 25, minimum = 1, maximum = 100000)]
    pub check_every_steps: usize,
    /// Stop searching (stable) after this long (s).
    #[serde(default = "default_horizon")]
    #[schema(example = 2000.0, minimum = 1e-6, maximum = 1e7)]
    pub horizon_s: f64,
    /// Floor of the growth-rate tolerance on Re λ (1/s).
    #[serde(default = "default_growth")]
    #[schema(example = 1e-6, minimum = 0.0, maximum = 1e6)]
    pub growth_tolerance_1_s: f64,
    /// Time-stepping scheme; default: generalized-α, which dissipates the
    /// unresolved axial modes a start from rest sets ringing (they
    /// otherwise show as a false early onset).
    #[serde(default = "default_scheme")]
    pub scheme: SchemeInput,
    /// Spectral radius ρ∞ of the scheme as ωΔt → ∞ (default: 0 for generalized-α, 0.5 for HHT-α;
    /// generalized-α: 0–1, HHT-α: 0.5–1, average acceleration: 1).
    #[serde(default)]
    #[schema(example = 0.0, minimum = 0.0, maximum = 1.0)]
    pub rho_infinity_nondim: Option<f64>,
    /// When Newton fails, halve the step and retry, at most this many
    /// levels deep.
    #[serde(default = "default_max_step_cuts")]
    #[schema(example = 8, minimum = 0, maximum = 12)]
    pub max_step_cuts: u32,
}

pub(crate) fn default_dt() -> f64 {
    CriticalConfig::default().time_step_s
}
pub(crate) fn default_check() -> usize {
    CriticalConfig::default().check_every
}
pub(crate) fn default_horizon() -> f64 {
    CriticalConfig::default().horizon_s
}
pub(crate) fn default_growth() -> f64 {
    CriticalConfig::default().growth_tolerance_1_s
}

/// How a point's search ended.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, ToSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum GeOnsetKind {
    /// Unstable at t = 0.
    Immediate,
    /// First unstable at `critical_time_s`.
    During,
    /// Stable over the search horizon.
    Never,
    /// Newton–Raphson failed before any instability.
    NewtonFailed,
    /// The eigenvalue iteration failed.
    SpectrumFailed,
    /// Stopped by the caller.
    Cancelled,
}

/// The Newton settings of a request (defaults when absent), checked.
pub(crate) fn newton_config(input: &Option<NewtonInput>) -> Result<NewtonConfig, InvalidInput> {
    let Some(n) = input else {
        return Ok(NewtonConfig::default());
    };
    let rtol = require_positive("newton.relative_tolerance", n.relative_tolerance)?;
    if rtol > 0.1 {
        return Err(InvalidInput::new(
            "newton.relative_tolerance",
            "must not exceed 0.1",
        ));
    }
    if !(1..=200).contains(&n.max_iterations) {
        return Err(InvalidInput::new(
            "newton.max_iterations",
            format!("must be between 1 and 200, got {}", n.max_iterations),
        ));
    }
    Ok(NewtonConfig {
        relative_tolerance: rtol,
        absolute_tolerance_n: require_non_negative(
            "newton.absolute_tolerance_n",
            n.absolute_tolerance_n,
        )?,
        max_iterations: n.max_iterations,
    })
}
