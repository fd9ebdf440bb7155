//! Transient runs and frequency responses (SPEC §2): the JSON contract of
//! `POST /api/v1/simulate` and `POST /api/v1/frequency-response` (and the
//! CLI subcommands and job kinds that share it), its validation, and the
//! conversion to and from [`crate::numerics::string::transient`].

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::contract::dto::{EigenvalueOutput, Groups, ProfileInput, SystemInput};
use crate::contract::run::{Progress, RequestError, groups};
use crate::numerics::aero::{Aerodynamics, AerostatBody, AirFlow, ForceModel, SteadyFlow};
use crate::numerics::chart::Parallelism;
use crate::numerics::params::{
    AerostatSystem, InvalidInput, require_finite, require_non_negative, require_positive,
};
use crate::numerics::reduced::ReducedModel;
use crate::numerics::string::transient::{
    self, EigenTracking, InitialState, MAGNITUDE_CAP_LENGTHS, MAX_FREQUENCIES, Observer,
    RunOutcome, TransientConfig, TransientError, TransientRun,
};

/// Most numbers (frequencies × samples) one frequency response returns.
pub const MAX_RESPONSE_VALUES: usize = 2_000_000;

fn default_samples() -> usize {
    1000
}

fn default_response_samples() -> usize {
    200
}

fn default_air_density() -> f64 {
    1.205
}

fn default_wavenumber() -> f64 {
    0.01
}

fn default_eigen_count() -> usize {
    3
}

/// How the cable starts.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(tag = "kind", rename_all = "snake_case")]
#[serde(deny_unknown_fields)]
pub enum InitialStateInput {
    /// Straight and at rest.
    Rest {},
    /// y = a ζ⁴ (ζ = x/L), at rest; a is the tip deflection.
    Shape {
        #[schema(example = 0.01)]
        tip_deflection_m: f64,
    },
    /// A natural mode of the cable at rest at its initial length, at rest.
    Mode {
        /// 1 = the lowest.
        #[schema(example = 1, minimum = 1)]
        mode: usize,
        #[schema(example = 0.01)]
        tip_deflection_m: f64,
    },
    /// From rest, a horizontal force on the aerostat held for a time, then released.
    TipForce {
        #[schema(example = 200.0, minimum = -1e8, maximum = 1e8)]
        force_n: f64,
        #[schema(example = 1.0, minimum = 1e-6, maximum = 1e7)]
        duration_s: f64,
    },
}

impl Default for InitialStateInput {
    fn default() -> Self {
        Self::Rest {}
    }
}

/// A steady wind profile u(z) (z = elevation of the aerostat).
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(tag = "kind", rename_all = "snake_case")]
#[serde(deny_unknown_fields)]
pub enum SteadyFlowInput {
    /// u = U.
    Uniform {
        #[schema(example = 5.0, minimum = -200.0, maximum = 200.0)]
        speed_m_s: f64,
    },
    /// u = a z^p; a is the speed at z = 1 m.
    PowerLaw {
        #[schema(example = 0.1, minimum = -200.0, maximum = 200.0)]
        coefficient_m_s: f64,
        #[schema(example = 0.3333, minimum = 0.0, maximum = 2.0)]
        exponent_nondim: f64,
    },
    /// Linear interpolation in (z, u), constant beyond the ends.
    Tabulated { points: Vec<FlowPointInput> },
}

/// One point of a tabulated wind profile.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct FlowPointInput {
    #[schema(example = 100.0, minimum = 0.0, maximum = 1e5)]
    pub elevation_m: f64,
    #[schema(example = 4.0, minimum = -200.0, maximum = 200.0)]
    pub speed_m_s: f64,
}

/// The horizontal air flow on the aerostat.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(tag = "kind", rename_all = "snake_case")]
#[serde(deny_unknown_fields)]
pub enum AirFlowInput {
    /// u = U.
    Uniform {
        #[schema(example = 5.0, minimum = -200.0, maximum = 200.0)]
        speed_m_s: f64,
    },
    /// u = a z^p; a is the speed at z = 1 m (thesis: 0.1 z^(1/3), z^(1/2)).
    PowerLaw {
        #[schema(example = 0.1, minimum = -200.0, maximum = 200.0)]
        coefficient_m_s: f64,
        #[schema(example = 0.3333, minimum = 0.0, maximum = 2.0)]
        exponent_nondim: f64,
    },
    /// Uniform in space, u = U0 sin(ω t).
    Sinusoidal {
        #[schema(example = 10.0, minimum = -200.0, maximum = 200.0)]
        amplitude_m_s: f64,
        #[schema(example = 2.0, minimum = 0.0, maximum = 10000.0)]
        angular_frequency_rad_s: f64,
    },
    /// Linear interpolation in (z, u), constant beyond the ends.
    Tabulated { points: Vec<FlowPointInput> },
    /// A steady profile with the perturbation of thesis (7.4):
    /// u = u0(z) (1 + A0 sin(k z)).
    Perturbed {
        base: SteadyFlowInput,
        /// A0.
        #[schema(example = 0.5, minimum = -10.0, maximum = 10.0)]
        amplitude_nondim: f64,
        /// k (1/m); the thesis uses 0.01.
        #[serde(default = "default_wavenumber")]
        #[schema(example = 0.01, minimum = 0.0, maximum = 1000.0)]
        wavenumber_1_m: f64,
    },
}

/// Aerodynamic force model of the aerostat.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(tag = "kind", rename_all = "snake_case")]
#[serde(deny_unknown_fields)]
pub enum ForceModelInput {
    /// Inviscid sphere (thesis (4.3)–(4.4)): m_f (u_t + u u_z) + ½ m_f (u_t − ÿ).
    Thesis {},
    /// Quadratic drag ½ ρ_air C_D A |u − ẏ|(u − ẏ) plus the added mass ½ m_f (u_t − ÿ).
    Drag {
        #[schema(example = 0.5, minimum = 0.0, maximum = 100.0)]
        drag_coefficient_nondim: f64,
        /// Reference area (m²); default π r².
        #[serde(default)]
        #[schema(minimum = 1e-6, maximum = 1e6)]
        reference_area_m2: Option<f64>,
    },
}

impl Default for ForceModelInput {
    fn default() -> Self {
        Self::Thesis {}
    }
}

/// The aerostat as an aerodynamic body (a sphere).
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct AeroBodyInput {
    #[serde(default)]
    pub model: ForceModelInput,
    /// Sphere radius r (m): volume, displaced air, default drag area.
    #[schema(example = 0.5, minimum = 0.001, maximum = 1000.0)]
    pub radius_m: f64,
    /// Air density (kg/m³).
    #[serde(default = "default_air_density")]
    #[schema(example = 1.205, minimum = 1e-4, maximum = 100.0)]
    pub air_density_kg_m3: f64,
    /// Lifting-gas density (kg/m³). When given, the displaced air mass is
    /// m ρ_air/ρ_gas (the thesis's ρ̃ in (4.5)); otherwise ρ_air 4/3 π r³.
    #[serde(default)]
    #[schema(minimum = 1e-4, maximum = 100.0)]
    pub gas_density_kg_m3: Option<f64>,
}

/// Wind on the aerostat: flow and body.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct AeroInput {
    pub flow: AirFlowInput,
    /// The force model (the fields below are those of [`AeroBodyInput`],
    /// written out so that unknown fields can be refused).
    #[serde(default)]
    pub model: ForceModelInput,
    /// Sphere radius r (m): volume, displaced air, default drag area.
    #[schema(example = 0.5, minimum = 0.001, maximum = 1000.0)]
    pub radius_m: f64,
    /// Air density (kg/m³).
    #[serde(default = "default_air_density")]
    #[schema(example = 1.205, minimum = 1e-4, maximum = 100.0)]
    pub air_density_kg_m3: f64,
    /// Lifting-gas density (kg/m³); see [`AeroBodyInput`].
    #[serde(default)]
    #[schema(minimum = 1e-4, maximum = 100.0)]
    pub gas_density_kg_m3: Option<f64>,
}

impl AeroInput {
    /// The body part.
    pub fn body(&self) -> AeroBodyInput {
        AeroBodyInput {
            model: self.model.clone(),
            radius_m: self.radius_m,
            air_density_kg_m3: self.air_density_kg_m3,
            gas_density_kg_m3: self.gas_density_kg_m3,
        }
    }
}

/// Eigenvalues along the run.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct EigenTrackingInput {
    /// Time between QEP solves (s).
    #[schema(example = 1.0, minimum = 1e-6, maximum = 1e7)]
    pub interval_s: f64,
    /// How many modes to report (by frequency).
    #[serde(default = "default_eigen_count")]
    #[schema(example = 3, minimum = 1)]
    pub count: usize,
}

/// `POST /api/v1/simulate`: a transient run.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
pub struct SimulateRequest {
    #[serde(flatten)]
    pub system: SystemInput,
    #[serde(flatten)]
    pub params: SimulateParams,
}

impl std::ops::Deref for SimulateRequest {
    type Target = SimulateParams;
    fn deref(&self) -> &SimulateParams {
        &self.params
    }
}

impl std::ops::DerefMut for SimulateRequest {
    fn deref_mut(&mut self) -> &mut SimulateParams {
        &mut self.params
    }
}

/// The fields of a transient run request besides the system.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct SimulateParams {
    pub profile: ProfileInput,
    /// Simulated time (s).
    #[schema(example = 150.0, minimum = 1e-6, maximum = 1e7)]
    pub duration_s: f64,
    /// Time step (s); default: 64 steps per period of the first mode (at the
    /// start and the end) and of the forcing, 8 per profile ramp.
    #[serde(default)]
    #[schema(minimum = 1e-9, maximum = 1000.0)]
    pub time_step_s: Option<f64>,
    /// Output samples, evenly spaced in time (2..=100000).
    #[serde(default = "default_samples")]
    #[schema(example = 1000, minimum = 2, maximum = 100000)]
    pub samples: usize,
    #[serde(default)]
    pub initial: InitialStateInput,
    /// Wind on the aerostat; none: no air.
    #[serde(default)]
    pub aero: Option<AeroInput>,
    /// Eigenvalues along the run; none: not computed.
    #[serde(default)]
    pub eigenvalues: Option<EigenTrackingInput>,
    /// Also return the one-mode reduced model (thesis ch. 3) beside the FE
    /// run; needs a `shape` or `mode` initial state.
    #[serde(default)]
    pub reduced_model: bool,
}

/// Eigenvalues at one instant of a run.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct EigenTrackOutput {
    pub time_s: f64,
    pub length_m: f64,
    /// Largest Re λ (1/s).
    pub max_real_1_s: f64,
    pub stable: bool,
    /// The first modes (Im λ ≥ 0) by frequency.
    pub eigenvalues: Vec<EigenvalueOutput>,
}

/// The one-mode model W = sin(πζ/2) beside the FE run, at the same times.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct ReducedOutput {
    /// WKB frequency ψ (rad/s); null where α/l + γ ≤ 0.
    pub frequency_rad_s: Vec<Option<f64>>,
    /// WKB amplitude A0 ∝ [ψ(2m̃ + l)]^(-1/2) of the tip (m), equal to the
    /// initial tip deflection at t = 0.
    pub wkb_amplitude_m: Vec<Option<f64>>,
    /// Leading-order energy of the mode ¼(α/l + γ)A0² (J).
    pub mode_energy_j: Vec<Option<f64>>,
    /// Tip deflection of the one-mode equation integrated in time (m).
    pub tip_deflection_m: Vec<f64>,
}

/// `POST /api/v1/simulate` answer: time series (SI).
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct SimulateResponse {
    pub time_s: Vec<f64>,
    pub length_m: Vec<f64>,
    pub rate_m_s: Vec<f64>,
    pub tip_deflection_m: Vec<f64>,
    pub tip_velocity_m_s: Vec<f64>,
    /// max |tip deflection| since the previous sample (m).
    pub tip_envelope_m: Vec<f64>,
    /// Total energy (thesis (3.14)) (J).
    pub energy_j: Vec<f64>,
    /// The same without the axial kinetic energy ½(ρA L + m) L̇² (J).
    pub vibration_energy_j: Vec<f64>,
    /// Aerodynamic (and held) force on the aerostat (N).
    pub tip_force_n: Vec<f64>,
    pub eigenvalues: Vec<EigenTrackOutput>,
    pub reduced: Option<ReducedOutput>,
    /// `completed`, `diverged` (deflection beyond 1e100 L0 or a failed
    /// step) or `length_collapsed` (shortened below 0.001 L0).
    pub outcome: String,
    /// When the run ended early (s).
    pub outcome_time_s: Option<f64>,
    pub explanation: String,
    /// First unstable instant of the deployment within the run (s): the
    /// critical time t* of the profile (the QEP criterion of `/critical`),
    /// or, where that search is too costly, the first unstable
    /// `eigenvalues` sample; null when stable over the run (or not known).
    /// The samples after it show growth past onset.
    pub first_unstable_time_s: Option<f64>,
    /// Cable length at `first_unstable_time_s` (m).
    pub first_unstable_length_m: Option<f64>,
    /// Why the run ended: `completed`, `magnitude_cap` (a deflection passed
    /// `magnitude_cap_m`), `step_failed` (non-finite or singular step),
    /// `length_collapsed`.
    pub stopped_reason: String,
    /// The deflection at which a run stops: `magnitude_cap_lengths_nondim`
    /// × the cable length, at the stop (or the end) of the run (m).
    pub magnitude_cap_m: f64,
    /// The cap as a multiple of the current cable length.
    pub magnitude_cap_lengths_nondim: f64,
    pub time_step_s: f64,
    pub steps: usize,
    /// Tension at the winch and the aerostat per output time (with the
    /// rate and acceleration terms), its extremes, slack and safety factor.
    pub tension: crate::contract::tension::TensionSeriesOutput,
    /// Displaced air mass m_f used by the aerodynamics (kg).
    pub displaced_air_mass_kg: Option<f64>,
    pub groups: Groups,
    pub elements: usize,
}

/// An evenly spaced grid of forcing frequencies.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct FrequencyGrid {
    #[schema(example = 0.25, minimum = 0.0, maximum = 10000.0)]
    pub min: f64,
    #[schema(example = 8.0, minimum = 0.0, maximum = 10000.0)]
    pub max: f64,
    #[schema(example = 64, minimum = 1, maximum = 1024)]
    pub count: usize,
}

/// `POST /api/v1/frequency-response`: one run per frequency of a uniform
/// wind u = U0 sin(ω t) on the aerostat; tip envelope against ω and time.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
pub struct FrequencyResponseRequest {
    #[serde(flatten)]
    pub system: SystemInput,
    #[serde(flatten)]
    pub params: FrequencyResponseParams,
}

impl std::ops::Deref for FrequencyResponseRequest {
    type Target = FrequencyResponseParams;
    fn deref(&self) -> &FrequencyResponseParams {
        &self.params
    }
}

impl std::ops::DerefMut for FrequencyResponseRequest {
    fn deref_mut(&mut self) -> &mut FrequencyResponseParams {
        &mut self.params
    }
}

/// The fields of a frequency response request besides the system.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct FrequencyResponseParams {
    pub profile: ProfileInput,
    #[schema(example = 60.0, minimum = 1e-6, maximum = 1e7)]
    pub duration_s: f64,
    /// Time step (s), shared by all runs; default set by the highest frequency.
    #[serde(default)]
    #[schema(minimum = 1e-9, maximum = 1000.0)]
    pub time_step_s: Option<f64>,
    /// Samples of the envelope in time (2..=100000).
    #[serde(default = "default_response_samples")]
    #[schema(example = 200, minimum = 2, maximum = 100000)]
    pub samples: usize,
    #[serde(default)]
    pub initial: InitialStateInput,
    /// The aerostat as an aerodynamic body.
    pub aero: AeroBodyInput,
    /// U0 (m/s).
    #[schema(example = 10.0, minimum = -200.0, maximum = 200.0)]
    pub wind_amplitude_m_s: f64,
    /// ω grid (rad/s).
    pub frequencies_rad_s: FrequencyGrid,
}

#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct FrequencyResponseResponse {
    pub frequencies_rad_s: Vec<f64>,
    pub time_s: Vec<f64>,
    /// `envelope_m[i][j]`: max |tip deflection| for frequency i over the
    /// window ending at time_s[j] (m).
    pub envelope_m: Vec<Vec<f64>>,
    /// Largest tip deflection of each run (m) and when (s).
    pub peak_amplitude_m: Vec<f64>,
    pub peak_time_s: Vec<f64>,
    /// Outcome of each run (`completed`, `diverged`, `length_collapsed`).
    pub outcomes: Vec<String>,
    pub time_step_s: f64,
    pub steps_per_run: usize,
    pub groups: Groups,
    pub elements: usize,
}

impl InitialStateInput {
    pub fn initial_state(&self) -> InitialState {
        match *self {
            Self::Rest {} => InitialState::Rest,
            Self::Shape { tip_deflection_m } => InitialState::Shape { tip_deflection_m },
            Self::Mode {
                mode,
                tip_deflection_m,
            } => InitialState::Mode {
                mode,
                tip_deflection_m,
            },
            Self::TipForce {
                force_n,
                duration_s,
            } => InitialState::TipForce {
                force_n,
                duration_s,
            },
        }
    }
}

fn flow_points(points: &[FlowPointInput], field: &str) -> Result<SteadyFlow, InvalidInput> {
    let table: Vec<(f64, f64)> = points
        .iter()
        .map(|p| (p.elevation_m, p.speed_m_s))
        .collect();
    SteadyFlow::tabulated(&table, field)
}

fn rename(e: InvalidInput, from: &str, to: &str) -> InvalidInput {
    InvalidInput::new(e.field.replacen(from, to, 1), e.reason)
}

impl SteadyFlowInput {
    pub fn flow(&self, field: &str) -> Result<SteadyFlow, InvalidInput> {
        match self {
            Self::Uniform { speed_m_s } => {
                SteadyFlow::uniform(*speed_m_s).map_err(|e| rename(e, "aero.flow", field))
            }
            Self::PowerLaw {
                coefficient_m_s,
                exponent_nondim,
            } => SteadyFlow::power_law(*coefficient_m_s, *exponent_nondim).map_err(|e| {
                rename(
                    rename(
                        e,
                        "aero.flow.coefficient",
                        &format!("{field}.coefficient_m_s"),
                    ),
                    "aero.flow.exponent",
                    &format!("{field}.exponent_nondim"),
                )
            }),
            Self::Tabulated { points } => flow_points(points, &format!("{field}.points")),
        }
    }
}

impl AirFlowInput {
    pub fn flow(&self) -> Result<AirFlow, InvalidInput> {
        Ok(match self {
            Self::Uniform { speed_m_s } => AirFlow::Steady(
                SteadyFlowInput::Uniform {
                    speed_m_s: *speed_m_s,
                }
                .flow("aero.flow")?,
            ),
            Self::PowerLaw {
                coefficient_m_s,
                exponent_nondim,
            } => AirFlow::Steady(
                SteadyFlowInput::PowerLaw {
                    coefficient_m_s: *coefficient_m_s,
                    exponent_nondim: *exponent_nondim,
                }
                .flow("aero.flow")?,
            ),
            Self::Sinusoidal {
                amplitude_m_s,
                angular_frequency_rad_s,
            } => AirFlow::sinusoidal(*amplitude_m_s, *angular_frequency_rad_s)?,
            Self::Tabulated { points } => AirFlow::Steady(flow_points(points, "aero.flow.points")?),
            Self::Perturbed {
                base,
                amplitude_nondim,
                wavenumber_1_m,
            } => AirFlow::perturbed(
                base.flow("aero.flow.base")?,
                *amplitude_nondim,
                *wavenumber_1_m,
            )?,
        })
    }
}

impl AeroBodyInput {
    /// The aerodynamics with a given flow, for an aerostat of mass `mass_kg`.
    pub fn aerodynamics(
        &self,
        flow: AirFlow,
        mass_kg: f64,
        prefix: &str,
    ) -> Result<Aerodynamics, InvalidInput> {
        let fix = |e: InvalidInput| rename(e, "aero", prefix);
        let body = AerostatBody::new(
            self.radius_m,
            self.air_density_kg_m3,
            self.gas_density_kg_m3,
        )
        .map_err(fix)?;
        let model = match self.model {
            ForceModelInput::Thesis {} => ForceModel::Thesis,
            ForceModelInput::Drag {
                drag_coefficient_nondim,
                reference_area_m2,
            } => {
                require_non_negative(
                    &format!("{prefix}.model.drag_coefficient_nondim"),
                    drag_coefficient_nondim,
                )?;
                let area = match reference_area_m2 {
                    Some(a) => require_positive(&format!("{prefix}.model.reference_area_m2"), a)?,
                    None => body.frontal_area_m2(),
                };
                ForceModel::Drag {
                    drag_coefficient: drag_coefficient_nondim,
                    reference_area_m2: area,
                }
            }
        };
        Aerodynamics::new(flow, model, body, mass_kg).map_err(fix)
    }
}

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

fn outcome_name(o: RunOutcome) -> (&'static str, Option<f64>) {
    match o {
        RunOutcome::Completed => ("completed", None),
        RunOutcome::Diverged { time_s } => ("diverged", Some(time_s)),
        RunOutcome::LengthCollapsed { time_s } => ("length_collapsed", Some(time_s)),
        RunOutcome::Cancelled { time_s } => ("cancelled", Some(time_s)),
    }
}

fn eigen_output(sys: &AerostatSystem, re_1_s: f64, im_1_s: f64) -> EigenvalueOutput {
    let ts = sys.time_scale_s();
    EigenvalueOutput {
        re_1_s,
        im_1_s,
        re_nondim: re_1_s * ts,
        im_nondim: im_1_s * ts,
        frequency_hz: im_1_s / (2.0 * std::f64::consts::PI),
    }
}

fn config_from(
    duration_s: f64,
    time_step_s: Option<f64>,
    samples: usize,
    initial: &InitialStateInput,
    aero: Option<Aerodynamics>,
    eigen: Option<&EigenTrackingInput>,
) -> Result<TransientConfig, InvalidInput> {
    require_finite("duration_s", duration_s)?;
    Ok(TransientConfig {
        duration_s,
        time_step_s,
        samples,
        initial: initial.initial_state(),
        aero,
        eigen: eigen.map(|e| EigenTracking {
            interval_s: e.interval_s,
            count: e.count,
        }),
    })
}

/// Runs a [`SimulateRequest`]. Progress counts time steps.
pub fn simulate(
    req: &SimulateRequest,
    progress: &dyn Progress,
) -> Result<SimulateResponse, RequestError> {
    let model = req.system.model()?;
    let sys = model.system;
    let profile = req.profile.profile(sys.initial_length_m)?;
    let breaking_strength_n = req.system.cable.breaking_strength()?;
    let aero = match &req.aero {
        Some(a) => Some(
            a.body()
                .aerodynamics(a.flow.flow()?, sys.aerostat_mass_kg, "aero")?,
        ),
        None => None,
    };
    let initial_tip = match req.initial {
        InitialStateInput::Shape { tip_deflection_m }
        | InitialStateInput::Mode {
            tip_deflection_m, ..
        } => Some(tip_deflection_m),
        _ => None,
    };
    if req.reduced_model && initial_tip.is_none_or(|a| a == 0.0) {
        return Err(InvalidInput::new(
            "reduced_model",
            "the one-mode model needs an initial amplitude: use a `shape` or `mode` initial state with a nonzero tip deflection",
        )
        .into());
    }
    let displaced_air_mass_kg = aero.as_ref().map(|a| a.displaced_air_mass_kg);
    let config = config_from(
        req.duration_s,
        req.time_step_s,
        req.samples,
        &req.initial,
        aero,
        req.eigenvalues.as_ref(),
    )?;
    let run = transient::simulate(&model, &profile, &config, &ProgressObserver(progress))
        .map_err(from_transient)?;
    if matches!(run.outcome, RunOutcome::Cancelled { .. }) {
        return Err(RequestError::Cancelled);
    }
    let reduced = match initial_tip {
        Some(a0) if req.reduced_model => Some(reduced_output(&sys, &profile, &run, a0)?),
        _ => None,
    };
    let (outcome, outcome_time_s) = outcome_name(run.outcome);
    let explanation = match run.outcome {
        RunOutcome::Completed => format!(
            "ran {} steps of {:.4e} s to t = {} s",
            run.steps, run.time_step_s, req.duration_s
        ),
        RunOutcome::Diverged { time_s } if run.stopped_at_cap => format!(
            "the deflection passed {} × the cable length ({:.4e} m, far beyond the linear model) and the run stopped at t = {time_s:.3} s: the deployment is unstable",
            MAGNITUDE_CAP_LENGTHS,
            MAGNITUDE_CAP_LENGTHS * run.final_kinematics.length_m
        ),
        RunOutcome::Diverged { time_s } => format!(
            "a time step failed (the deflection grew without bound) and the run stopped at t = {time_s:.3} s: the deployment is unstable"
        ),
        RunOutcome::LengthCollapsed { time_s } => {
            format!(
                "the cable was shortened to (almost) zero length at t = {time_s:.3} s; the run stopped there"
            )
        }
        RunOutcome::Cancelled { .. } => unreachable!("handled above"),
    };
    let stopped_reason = match run.outcome {
        RunOutcome::Completed | RunOutcome::Cancelled { .. } => "completed",
        RunOutcome::Diverged { .. } if run.stopped_at_cap => "magnitude_cap",
        RunOutcome::Diverged { .. } => "step_failed",
        RunOutcome::LengthCollapsed { .. } => "length_collapsed",
    };
    let (first_unstable_time_s, first_unstable_length_m) =
        first_unstable(&model, &profile, &run, req.duration_s);
    let col = |f: fn(&transient::Sample) -> f64| run.samples.iter().map(f).collect::<Vec<f64>>();
    Ok(SimulateResponse {
        time_s: col(|s| s.time_s),
        length_m: col(|s| s.length_m),
        rate_m_s: col(|s| s.rate_m_s),
        tip_deflection_m: col(|s| s.tip_deflection_m),
        tip_velocity_m_s: col(|s| s.tip_velocity_m_s),
        tip_envelope_m: col(|s| s.tip_envelope_m),
        energy_j: col(|s| s.energy_j),
        vibration_energy_j: col(|s| s.vibration_energy_j),
        tip_force_n: col(|s| s.tip_force_n),
        eigenvalues: run
            .eigen
            .iter()
            .map(|e| EigenTrackOutput {
                time_s: e.time_s,
                length_m: e.length_m,
                max_real_1_s: e.max_real_1_s,
                stable: e.stable,
                eigenvalues: e
                    .modes
                    .iter()
                    .map(|m| eigen_output(&sys, m.re_1_s, m.im_1_s))
                    .collect(),
            })
            .collect(),
        reduced,
        outcome: outcome.into(),
        outcome_time_s,
        explanation,
        first_unstable_time_s,
        first_unstable_length_m,
        stopped_reason: stopped_reason.into(),
        magnitude_cap_m: MAGNITUDE_CAP_LENGTHS * run.final_kinematics.length_m,
        magnitude_cap_lengths_nondim: MAGNITUDE_CAP_LENGTHS,
        time_step_s: run.time_step_s,
        steps: run.steps,
        tension: crate::contract::tension::TensionSeriesOutput::of(
            &sys,
            &profile,
            &col(|s| s.time_s),
            breaking_strength_n,
        ),
        displaced_air_mass_kg,
        groups: groups(&sys),
        elements: model.elements(),
    })
}

/// Largest element count at which a simulate answer also runs the
/// critical-time search of its profile (dense QEP probes of size 2n).
pub const MAX_ONSET_SEARCH_ELEMENTS: usize = 400;

/// The first unstable instant of the run and the length then: the
/// profile's critical time when it falls within the run, else the first
/// unstable eigenvalue sample. A failed search is "not known" (null), not
/// an error: the run itself is the answer.
fn first_unstable(
    model: &crate::numerics::string::StringModel,
    profile: &crate::numerics::profile::Profile,
    run: &TransientRun,
    duration_s: f64,
) -> (Option<f64>, Option<f64>) {
    use crate::numerics::string::critical::{self, SearchConfig};
    if model.elements() <= MAX_ONSET_SEARCH_ELEMENTS
        && let Ok(ct) = critical::critical_time(
            model,
            profile,
            SearchConfig {
                confirm_with_qep: false,
            },
        )
    {
        return match ct.time_s() {
            Some(t) if t.is_finite() && t <= duration_s => {
                (Some(t), Some(profile.kinematics(t).length_m))
            }
            _ => (None, None),
        };
    }
    run.eigen
        .iter()
        .find(|e| !e.stable)
        .map_or((None, None), |e| (Some(e.time_s), Some(e.length_m)))
}

fn reduced_output(
    sys: &AerostatSystem,
    profile: &crate::numerics::profile::Profile,
    run: &TransientRun,
    tip_m: f64,
) -> Result<ReducedOutput, RequestError> {
    let reduced = ReducedModel::new(*sys);
    let (l0, ts, e_scale) = (
        sys.initial_length_m,
        sys.time_scale_s(),
        sys.net_buoyancy_n * sys.initial_length_m,
    );
    let l_start = profile.kinematics(0.0).length_m / l0;
    let a0 = tip_m / l0;
    let q = reduced
        .simulate(profile, a0, run.time_step_s, run.steps)
        .map_err(|e| {
            RequestError::Invalid(InvalidInput::new(
                "reduced_model",
                format!("the one-mode run failed: {e}"),
            ))
        })?;
    let mut out = ReducedOutput {
        frequency_rad_s: vec![],
        wkb_amplitude_m: vec![],
        mode_energy_j: vec![],
        tip_deflection_m: vec![],
    };
    for s in &run.samples {
        let l = s.length_m / l0;
        let amp = reduced.wkb_amplitude(l, l_start, a0.abs());
        out.frequency_rad_s
            .push(reduced.frequency(l).map(|w| w / ts));
        out.wkb_amplitude_m.push(amp.map(|a| a * l0));
        out.mode_energy_j
            .push(amp.map(|a| reduced.mode_energy(l, a) * e_scale));
        let step = (s.time_s / run.time_step_s).round() as usize;
        out.tip_deflection_m.push(if step == 0 {
            a0 * l0
        } else {
            q.get(step - 1).copied().unwrap_or(f64::NAN) * l0
        });
    }
    // JSON has no NaN: a sample past the reduced run (cannot happen) is 0.
    for v in &mut out.tip_deflection_m {
        if !v.is_finite() {
            *v = 0.0;
        }
    }
    Ok(out)
}

/// Number of runs a frequency-response request asks for (admission limits).
pub fn frequency_response_runs(req: &FrequencyResponseRequest) -> usize {
    req.frequencies_rad_s.count
}

/// Runs a [`FrequencyResponseRequest`]: the runs fan out on rayon when
/// `parallelism` says so (results identical to serial). Progress counts
/// finished runs.
pub fn frequency_response(
    req: &FrequencyResponseRequest,
    parallelism: Parallelism,
    progress: &dyn Progress,
) -> Result<FrequencyResponseResponse, RequestError> {
    let model = req.system.model()?;
    let sys = model.system;
    let profile = req.profile.profile(sys.initial_length_m)?;
    let grid = &req.frequencies_rad_s;
    require_non_negative("frequencies_rad_s.min", grid.min)?;
    require_non_negative("frequencies_rad_s.max", grid.max)?;
    if grid.max < grid.min {
        return Err(InvalidInput::new(
            "frequencies_rad_s.max",
            format!("must be at least frequencies_rad_s.min = {}", grid.min),
        )
        .into());
    }
    if grid.max > 1e4 {
        return Err(InvalidInput::new(
            "frequencies_rad_s.max",
            format!("must be at most 1e4 rad/s, got {}", grid.max),
        )
        .into());
    }
    if grid.count == 0 || grid.count > MAX_FREQUENCIES {
        return Err(InvalidInput::new(
            "frequencies_rad_s.count",
            format!(
                "must be between 1 and {MAX_FREQUENCIES}, got {}",
                grid.count
            ),
        )
        .into());
    }
    if grid.count.saturating_mul(req.samples) > MAX_RESPONSE_VALUES {
        return Err(InvalidInput::new(
            "samples",
            format!(
                "{} frequencies × {} samples exceed the limit of {MAX_RESPONSE_VALUES} values",
                grid.count, req.samples
            ),
        )
        .into());
    }
    require_finite("wind_amplitude_m_s", req.wind_amplitude_m_s)?;
    let frequencies: Vec<f64> = if grid.count == 1 {
        vec![grid.min]
    } else {
        (0..grid.count)
            .map(|i| grid.min + (grid.max - grid.min) * i as f64 / (grid.count - 1) as f64)
            .collect()
    };
    let aero = req.aero.aerodynamics(
        AirFlow::sinusoidal(req.wind_amplitude_m_s, grid.max)?,
        sys.aerostat_mass_kg,
        "aero",
    )?;
    let config = config_from(
        req.duration_s,
        req.time_step_s,
        req.samples,
        &req.initial,
        Some(aero),
        None,
    )?;
    let fr = transient::frequency_response(
        &model,
        &profile,
        &config,
        req.wind_amplitude_m_s,
        &frequencies,
        parallelism,
        &ProgressObserver(progress),
    )
    .map_err(from_transient)?;
    if progress.cancelled()
        || fr
            .outcomes
            .iter()
            .any(|o| matches!(o, RunOutcome::Cancelled { .. }))
    {
        return Err(RequestError::Cancelled);
    }
    Ok(FrequencyResponseResponse {
        frequencies_rad_s: fr.frequencies_rad_s,
        time_s: fr.time_s,
        envelope_m: fr.envelope_m,
        peak_amplitude_m: fr.peak_m,
        peak_time_s: fr.peak_time_s,
        outcomes: fr
            .outcomes
            .iter()
            .map(|o| outcome_name(*o).0.to_string())
            .collect(),
        time_step_s: fr.time_step_s,
        steps_per_run: fr.steps,
        groups: groups(&sys),
        elements: model.elements(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contract::parse;
    use crate::contract::run::NoProgress;

    const SYSTEM: &str = r#""cable": {"density_kg_m3": 7800, "area_m2": 1e-5},
        "aerostat": {"net_buoyancy_n": 1000, "mass_kg": 10}, "initial_length_m": 1, "model": {"elements": 20}"#;

    #[test]
    fn simulate_round_trip_with_wind_eigenvalues_and_reduced_model() {
        let body = format!(
            r#"{{ {SYSTEM}, "profile": {{"kind": "trapezoidal", "cruise_rate_m_s": 10, "ramp_up_s": 2, "ramp_down_s": 2, "target_length_m": 101}},
                "duration_s": 15, "samples": 50, "initial": {{"kind": "mode", "mode": 1, "tip_deflection_m": 0.01}},
                "aero": {{"flow": {{"kind": "power_law", "coefficient_m_s": 0.1, "exponent_nondim": 0.3333}},
                          "model": {{"kind": "drag", "drag_coefficient_nondim": 0.5}}, "radius_m": 0.5}},
                "eigenvalues": {{"interval_s": 5, "count": 2}}, "reduced_model": true }}"#
        );
        let req: SimulateRequest = parse(body.as_bytes()).unwrap();
        let resp = simulate(&req, &NoProgress).unwrap();
        assert_eq!(resp.outcome, "completed");
        assert_eq!(resp.time_s.len(), 50);
        assert_eq!(resp.eigenvalues.len(), 4); // 0, 5, 10, 15 s
        assert_eq!(resp.eigenvalues[0].eigenvalues.len(), 2);
        let reduced = resp.reduced.as_ref().unwrap();
        assert_eq!(reduced.tip_deflection_m[0], 0.01);
        assert!((reduced.wkb_amplitude_m[0].unwrap() - 0.01).abs() < 1e-15);
        assert!((resp.length_m[49] - 101.0).abs() < 1e-9);
        assert!(resp.displaced_air_mass_kg.unwrap() > 0.6);
        // JSON out and back (floats to within the last digit)
        let json = serde_json::to_string(&resp).unwrap();
        let back: SimulateResponse = serde_json::from_str(&json).unwrap();
        assert_eq!(back.tip_deflection_m.len(), resp.tip_deflection_m.len());
        for (a, b) in back.energy_j.iter().zip(&resp.energy_j) {
            assert!((a - b).abs() <= 1e-15 * b.abs());
        }
    }

    #[test]
    fn simulate_rejects_bad_input_naming_the_field() {
        let field = |extra: &str| {
            let body = format!(
                r#"{{ {SYSTEM}, "profile": {{"kind": "constant_rate", "rate_m_s": 1}}, {extra} }}"#
            );
            // the range checks run at parsing, the rest at the run
            let req: SimulateRequest = match parse(body.as_bytes()) {
                Ok(r) => r,
                Err(RequestError::Invalid(e)) => return e.field,
                Err(e) => panic!("{e:?}"),
            };
            match simulate(&req, &NoProgress) {
                Err(RequestError::Invalid(e)) => e.field,
                other => panic!("expected invalid input, got {other:?}"),
            }
        };
        assert_eq!(field(r#""duration_s": -3"#), "duration_s");
        assert_eq!(field(r#""duration_s": 10, "samples": 1"#), "samples");
        assert_eq!(
            field(r#""duration_s": 1e7, "time_step_s": 1e-4"#),
            "time_step_s"
        );
        assert_eq!(
            field(r#""duration_s": 10, "reduced_model": true"#),
            "reduced_model"
        );
        assert_eq!(
            field(
                r#""duration_s": 10, "aero": {"flow": {"kind": "uniform", "speed_m_s": 1}, "radius_m": -1}"#
            ),
            "aero.radius_m"
        );
        assert_eq!(
            field(
                r#""duration_s": 10, "aero": {"flow": {"kind": "tabulated", "points": [{"elevation_m": 5, "speed_m_s": 1}, {"elevation_m": 1, "speed_m_s": 2}]}, "radius_m": 1}"#
            ),
            "aero.flow.points[1].elevation_m"
        );
        assert_eq!(
            field(
                r#""duration_s": 10, "aero": {"flow": {"kind": "uniform", "speed_m_s": 1}, "radius_m": 1, "model": {"kind": "drag", "drag_coefficient_nondim": -1}}"#
            ),
            "aero.model.drag_coefficient_nondim"
        );
        assert_eq!(
            field(r#""duration_s": 10, "eigenvalues": {"interval_s": 1, "count": 500}"#),
            "eigenvalues.count"
        );
        assert_eq!(
            field(
                r#""duration_s": 10, "initial": {"kind": "mode", "mode": 0, "tip_deflection_m": 0.1}"#
            ),
            "initial.mode"
        );
    }

    #[test]
    fn frequency_response_runs_and_validates() {
        let body = format!(
            r#"{{ {SYSTEM}, "profile": {{"kind": "constant_rate", "rate_m_s": 1}}, "duration_s": 10, "samples": 20,
                "aero": {{"radius_m": 0.5}}, "wind_amplitude_m_s": 10,
                "frequencies_rad_s": {{"min": 1, "max": 4, "count": 4}} }}"#
        );
        let req: FrequencyResponseRequest = parse(body.as_bytes()).unwrap();
        let resp = frequency_response(&req, Parallelism::Rayon, &NoProgress).unwrap();
        assert_eq!(resp.frequencies_rad_s, vec![1.0, 2.0, 3.0, 4.0]);
        assert_eq!(resp.envelope_m.len(), 4);
        assert!(resp.envelope_m.iter().all(|e| e.len() == 20));
        assert!(resp.outcomes.iter().all(|o| o == "completed"));
        let mut bad = req.clone();
        bad.frequencies_rad_s.count = MAX_FREQUENCIES + 1;
        assert!(
            matches!(frequency_response(&bad, Parallelism::Serial, &NoProgress), Err(RequestError::Invalid(e)) if e.field == "frequencies_rad_s.count")
        );
        let mut bad = req;
        bad.frequencies_rad_s.max = 0.5;
        assert!(
            matches!(frequency_response(&bad, Parallelism::Serial, &NoProgress), Err(RequestError::Invalid(e)) if e.field == "frequencies_rad_s.max")
        );
    }

    #[test]
    fn cancellation_is_an_error() {
        struct Cancel;
        impl Progress for Cancel {
            fn report(&self, _: usize, _: usize) {}
            fn cancelled(&self) -> bool {
                true
            }
        }
        let body = format!(
            r#"{{ {SYSTEM}, "profile": {{"kind": "constant_rate", "rate_m_s": 1}}, "duration_s": 10 }}"#
        );
        let req: SimulateRequest = parse(body.as_bytes()).unwrap();
        assert!(matches!(
            simulate(&req, &Cancel),
            Err(RequestError::Cancelled)
        ));
    }
}
