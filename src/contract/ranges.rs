//! Range checks of every request (the plausible magnitudes of
//! [`crate::numerics::params::ranges`]), run right after parsing so that the
//! API, the CLI and the job queue refuse the same values with the same
//! message: the field path and the accepted range.

use crate::contract::dto::*;
use crate::contract::ge::simulate::{
    EndLoadInput, GeAerostatInput, GeModelInput, GeSimulateRequest, LoadTimeInput,
};
use crate::contract::ge::stability::GeStabilityRequest;
use crate::contract::ge_charts::{
    self, GeBaseFrequencyResponseRequest, GeChartRequest, GeWindInput,
};
use crate::contract::ge_critical::GeCriticalRequest;
use crate::contract::transient::aero::{
    AeroBodyInput, AirFlowInput, FlowPointInput, ForceModelInput, SteadyFlowInput,
};
use crate::contract::transient::frequency::FrequencyResponseParams;
use crate::contract::transient::simulate::{InitialStateInput, SimulateParams};
use crate::numerics::params::ranges::*;
use crate::numerics::params::{InvalidInput, Range, compact};

type Checked = Result<(), InvalidInput>;

fn at(prefix: &str, name: &str) -> String {
    if prefix.is_empty() {
        name.to_string()
    } else {
        format!("{prefix}.{name}")
    }
}

fn opt(range: Range, field: &str, value: Option<f64>) -> Checked {
    value.map_or(Ok(()), |v| range.check(field, v).map(drop))
}

fn each(range: Range, field: &str, values: &[f64]) -> Checked {
    for (i, v) in values.iter().enumerate() {
        range.check(&format!("{field}[{i}]"), *v)?;
    }
    Ok(())
}

/// The ranges of the parameters of a request, given the initial length
/// `L0` (m) of its system (some bounds are multiples of it).
pub trait CheckRanges {
    fn check_ranges(&self, initial_length_m: f64) -> Checked;
}

/// The system part of a linear-string request.
pub fn check_system(s: &SystemInput) -> Checked {
    s.cable.check_ranges()?;
    s.system().map(drop)
}

impl CableInput {
    /// The ranges of the cable's fields (mass per length checked by the
    /// caller, which knows the model's field name).
    pub fn check_ranges(&self) -> Checked {
        opt(
            MASS_PER_LENGTH_KG_M,
            "cable.mass_per_length_kg_m",
            self.mass_per_length_kg_m,
        )?;
        opt(DENSITY_KG_M3, "cable.density_kg_m3", self.density_kg_m3)?;
        opt(AREA_M2, "cable.area_m2", self.area_m2)?;
        if let (Some(rho), Some(a)) = (self.density_kg_m3, self.area_m2) {
            let rho_a = rho * a;
            if MASS_PER_LENGTH_KG_M.check("", rho_a).is_err() {
                return Err(InvalidInput::new(
                    "cable.area_m2",
                    format!(
                        "gives a mass per length density_kg_m3 × area_m2 = {} kg/m; it must be between {} and {} kg/m",
                        compact(rho_a),
                        compact(MASS_PER_LENGTH_KG_M.min),
                        compact(MASS_PER_LENGTH_KG_M.max)
                    ),
                ));
            }
        }
        Ok(())
    }
}

impl ProfileInput {
    /// The ranges of a profile's fields, named from `prefix` (`profile`).
    pub fn check_ranges(&self, prefix: &str) -> Checked {
        let f = |n: &str| at(prefix, n);
        match self {
            Self::ConstantRate {
                rate_m_s,
                target_length_m,
            } => {
                RATE_M_S.check(&f("rate_m_s"), *rate_m_s)?;
                opt(LENGTH_M, &f("target_length_m"), *target_length_m)
            }
            Self::ConstantAcceleration {
                acceleration_m_s2,
                target_length_m,
            } => {
                ACCELERATION_M_S2.check(&f("acceleration_m_s2"), *acceleration_m_s2)?;
                opt(LENGTH_M, &f("target_length_m"), *target_length_m)
            }
            Self::Trapezoidal {
                cruise_rate_m_s,
                ramp_up_s,
                ramp_down_s,
                target_length_m,
            } => {
                RATE_M_S.check(&f("cruise_rate_m_s"), *cruise_rate_m_s)?;
                DURATION_S.check(&f("ramp_up_s"), *ramp_up_s)?;
                DURATION_S.check(&f("ramp_down_s"), *ramp_down_s)?;
                LENGTH_M
                    .check(&f("target_length_m"), *target_length_m)
                    .map(drop)
            }
            Self::PiecewiseLinearRate {
                points,
                target_length_m,
            } => {
                for (i, p) in points.iter().enumerate() {
                    TIME_S.check(&f(&format!("points[{i}].time_s")), p.time_s)?;
                    RATE_M_S.check(&f(&format!("points[{i}].rate_m_s")), p.rate_m_s)?;
                }
                opt(LENGTH_M, &f("target_length_m"), *target_length_m)
            }
        }
    }
}

impl CheckRanges for StabilityParams {
    fn check_ranges(&self, _: f64) -> Checked {
        LENGTH_M.check("state.length_m", self.state.length_m)?;
        RATE_M_S.check("state.rate_m_s", self.state.rate_m_s)?;
        ACCELERATION_M_S2
            .check("state.acceleration_m_s2", self.state.acceleration_m_s2)
            .map(drop)
    }
}

impl CheckRanges for CriticalParams {
    fn check_ranges(&self, _: f64) -> Checked {
        self.profile.check_ranges("profile")
    }
}

impl CheckRanges for SafeRateParams {
    fn check_ranges(&self, _: f64) -> Checked {
        LENGTH_M
            .check("target_elevation_m", self.target_elevation_m)
            .map(drop)
    }
}

/// The plausible range of every value of a grid (`prefix[i]`, or
/// `prefix.min` and `prefix.max`).
fn check_grid(range: Range, grid: &crate::contract::system::GridInput, prefix: &str) -> Checked {
    use crate::contract::system::GridInput;
    match grid {
        GridInput::Range(r) => {
            range.check(&at(prefix, "min"), r.min)?;
            range.check(&at(prefix, "max"), r.max).map(drop)
        }
        GridInput::List(v) => each(range, prefix, v),
    }
}

fn check_rate_grid(grid: &RateGrid, prefix: &str) -> Checked {
    check_grid(POSITIVE_RATE_M_S, grid, prefix)
}

impl CheckRanges for ChartParams {
    fn check_ranges(&self, _: f64) -> Checked {
        check_rate_grid(&self.rates_m_s, "rates_m_s")?;
        each(NET_BUOYANCY_N, "net_buoyancies_n", &self.net_buoyancies_n)
    }
}

fn check_initial(initial: &InitialStateInput, l0: f64) -> Checked {
    let tip = |a: f64| {
        let cap = TIP_DEFLECTION_LENGTHS * l0;
        Range::new(-cap, cap, "m (a multiple of initial_length_m)")
            .check("initial.tip_deflection_m", a)
            .map(drop)
    };
    match initial {
        InitialStateInput::Rest {} => Ok(()),
        InitialStateInput::Shape { tip_deflection_m } => tip(*tip_deflection_m),
        InitialStateInput::Mode {
            tip_deflection_m, ..
        } => tip(*tip_deflection_m),
        InitialStateInput::TipForce {
            force_n,
            duration_s,
        } => {
            FORCE_N.check("initial.force_n", *force_n)?;
            DURATION_S
                .check("initial.duration_s", *duration_s)
                .map(drop)
        }
    }
}

fn check_steady_flow(flow: &SteadyFlowInput, prefix: &str) -> Checked {
    match flow {
        SteadyFlowInput::Uniform { speed_m_s } => WIND_SPEED_M_S
            .check(&at(prefix, "speed_m_s"), *speed_m_s)
            .map(drop),
        SteadyFlowInput::PowerLaw {
            coefficient_m_s,
            exponent_nondim,
        } => {
            WIND_SPEED_M_S.check(&at(prefix, "coefficient_m_s"), *coefficient_m_s)?;
            EXPONENT_NONDIM
                .check(&at(prefix, "exponent_nondim"), *exponent_nondim)
                .map(drop)
        }
        SteadyFlowInput::Tabulated { points } => check_flow_points(points, prefix),
    }
}

fn check_flow_points(points: &[FlowPointInput], prefix: &str) -> Checked {
    for (i, p) in points.iter().enumerate() {
        ELEVATION_M.check(
            &at(prefix, &format!("points[{i}].elevation_m")),
            p.elevation_m,
        )?;
        WIND_SPEED_M_S.check(&at(prefix, &format!("points[{i}].speed_m_s")), p.speed_m_s)?;
    }
    Ok(())
}

fn check_air_flow(flow: &AirFlowInput) -> Checked {
    let prefix = "aero.flow";
    match flow {
        AirFlowInput::Uniform { speed_m_s } => check_steady_flow(
            &SteadyFlowInput::Uniform {
                speed_m_s: *speed_m_s,
            },
            prefix,
        ),
        AirFlowInput::PowerLaw {
            coefficient_m_s,
            exponent_nondim,
        } => check_steady_flow(
            &SteadyFlowInput::PowerLaw {
                coefficient_m_s: *coefficient_m_s,
                exponent_nondim: *exponent_nondim,
            },
            prefix,
        ),
        AirFlowInput::Sinusoidal {
            amplitude_m_s,
            angular_frequency_rad_s,
        } => {
            WIND_SPEED_M_S.check("aero.flow.amplitude_m_s", *amplitude_m_s)?;
            FREQUENCY_RAD_S
                .check(
                    "aero.flow.angular_frequency_rad_s",
                    *angular_frequency_rad_s,
                )
                .map(drop)
        }
        AirFlowInput::Tabulated { points } => check_flow_points(points, prefix),
        AirFlowInput::Perturbed {
            base,
            amplitude_nondim,
            wavenumber_1_m,
        } => {
            check_steady_flow(base, "aero.flow.base")?;
            AMPLITUDE_NONDIM.check("aero.flow.amplitude_nondim", *amplitude_nondim)?;
            WAVENUMBER_1_M
                .check("aero.flow.wavenumber_1_m", *wavenumber_1_m)
                .map(drop)
        }
    }
}

fn check_force_model(model: &ForceModelInput, prefix: &str) -> Checked {
    match model {
        ForceModelInput::Thesis {} => Ok(()),
        ForceModelInput::Drag {
            drag_coefficient_nondim,
            reference_area_m2,
        } => {
            DRAG_COEFFICIENT_NONDIM.check(
                &at(prefix, "model.drag_coefficient_nondim"),
                *drag_coefficient_nondim,
            )?;
            opt(
                REFERENCE_AREA_M2,
                &at(prefix, "model.reference_area_m2"),
                *reference_area_m2,
            )
        }
    }
}

fn check_body(body: &AeroBodyInput, prefix: &str) -> Checked {
    check_force_model(&body.model, prefix)?;
    RADIUS_M.check(&at(prefix, "radius_m"), body.radius_m)?;
    GAS_DENSITY_KG_M3.check(&at(prefix, "air_density_kg_m3"), body.air_density_kg_m3)?;
    opt(
        GAS_DENSITY_KG_M3,
        &at(prefix, "gas_density_kg_m3"),
        body.gas_density_kg_m3,
    )
}

impl CheckRanges for SimulateParams {
    fn check_ranges(&self, l0: f64) -> Checked {
        self.profile.check_ranges("profile")?;
        DURATION_S.check("duration_s", self.duration_s)?;
        opt(TIME_STEP_S, "time_step_s", self.time_step_s)?;
        check_initial(&self.initial, l0)?;
        if let Some(a) = &self.aero {
            check_air_flow(&a.flow)?;
            check_body(&a.body(), "aero")?;
        }
        if let Some(e) = &self.eigenvalues {
            DURATION_S.check("eigenvalues.interval_s", e.interval_s)?;
        }
        Ok(())
    }
}

impl CheckRanges for FrequencyResponseParams {
    fn check_ranges(&self, l0: f64) -> Checked {
        self.profile.check_ranges("profile")?;
        DURATION_S.check("duration_s", self.duration_s)?;
        opt(TIME_STEP_S, "time_step_s", self.time_step_s)?;
        check_initial(&self.initial, l0)?;
        check_body(&self.aero, "aero")?;
        WIND_SPEED_M_S.check("wind_amplitude_m_s", self.wind_amplitude_m_s)?;
        check_grid(
            FREQUENCY_RAD_S,
            &self.frequencies_rad_s,
            "frequencies_rad_s",
        )
    }
}

// The parameters of each linear-string request checked after parsing
// (`crate::contract::parse`), with its system part.
macro_rules! system_request {
    ($($req:ty => $params:ty),* $(,)?) => {$(
        impl crate::contract::system::input::SystemRequest for $req {
            type Params = $params;
            fn from_parts(system: SystemInput, params: $params) -> Self {
                Self { system, params }
            }
            fn check_ranges(&self) -> Result<(), crate::numerics::params::InvalidInput> {
                check_system(&self.system)?;
                CheckRanges::check_ranges(
                    &self.params,
                    self.system.initial_length_m,
                )
            }
        }
    )*};
}

system_request!(
    StabilityRequest => StabilityParams,
    CriticalRequest => CriticalParams,
    SafeRateRequest => SafeRateParams,
    ChartRequest => ChartParams,
    crate::contract::transient::SimulateRequest => crate::contract::transient::SimulateParams,
    crate::contract::transient::FrequencyResponseRequest => crate::contract::transient::FrequencyResponseParams,
);

// ------------------------------------------------------------------ GE

fn check_ge_system(
    cable: &CableInput,
    aerostat: Option<&GeAerostatInput>,
    initial_length_m: f64,
    gravity_m_s2: f64,
) -> Checked {
    cable.check_ranges()?;
    cable.check_given("cable")?;
    if let Some(a) = aerostat {
        a.net_buoyancy_ge("aerostat")?;
        a.mass("aerostat")?;
        a.link_length("aerostat")?;
        a.check_given("aerostat")?;
    }
    INITIAL_LENGTH_M.check("initial_length_m", initial_length_m)?;
    GE_GRAVITY_M_S2
        .check("gravity_m_s2", gravity_m_s2)
        .map(drop)
}

fn check_ge_model(m: &GeModelInput) -> Checked {
    opt(
        BENDING_STIFFNESS_N_M2,
        "model.bending_stiffness_n_m2",
        m.bending_stiffness_n_m2,
    )?;
    opt(STIFFNESS_RATIO, "model.stiffness_ratio", m.stiffness_ratio)?;
    opt(
        STIFFNESS_RATIO,
        "model.shear_stiffness_ratio",
        m.shear_stiffness_ratio,
    )?;
    opt(INERTIA_RATIO, "model.inertia_ratio", m.inertia_ratio).map(drop)
}

fn check_end_load(e: &EndLoadInput) -> Checked {
    FORCE_N.check("end_load.axial_force_n", e.axial_force_n)?;
    FORCE_N.check("end_load.transverse_force_n", e.transverse_force_n)?;
    MOMENT_N_M.check("end_load.moment_n_m", e.moment_n_m)?;
    match e.time {
        LoadTimeInput::Constant {} => Ok(()),
        LoadTimeInput::Held { ramp_s, hold_s } => {
            TIME_S.check("end_load.time.ramp_s", ramp_s)?;
            TIME_S.check("end_load.time.hold_s", hold_s).map(drop)
        }
        LoadTimeInput::Triangle { peak_s, end_s } => {
            TIME_S.check("end_load.time.peak_s", peak_s)?;
            TIME_S.check("end_load.time.end_s", end_s).map(drop)
        }
    }
}

impl GeSimulateRequest {
    pub fn check_ranges(&self) -> Checked {
        check_ge_system(
            &self.cable,
            Some(&self.aerostat),
            self.initial_length_m,
            self.gravity_m_s2,
        )?;
        check_ge_model(&self.model)?;
        if let Some(p) = &self.profile {
            p.check_ranges("profile")?;
        }
        TIME_STEP_S.check("time_step_s", self.time_step_s)?;
        DURATION_S.check("duration_s", self.duration_s)?;
        if let Some(e) = &self.end_load {
            check_end_load(e)?;
        }
        RATE_1_S.check("damping_per_s", self.damping_per_s)?;
        TIME_S
            .check("damping_from_s", self.damping_from_s)
            .map(drop)
    }
}

fn check_ge_wind(w: &GeWindInput) -> Checked {
    // the §9 flow's bounds, as every route that takes `wind.flow` checks them
    w.flow.profile("wind.flow")?;
    RADIUS_M.check("wind.radius_m", w.radius_m)?;
    GAS_DENSITY_KG_M3.check("wind.air_density_kg_m3", w.air_density_kg_m3)?;
    each(
        AMPLITUDE_NONDIM,
        "wind.amplitudes_nondim",
        &w.amplitudes_nondim,
    )?;
    WAVENUMBER_1_M
        .check("wind.wavenumber_1_m", w.wavenumber_1_m)
        .map(drop)
}

impl GeChartRequest {
    pub fn check_ranges(&self) -> Checked {
        // a chart of elevation limits needs gravity (the closed forms divide by g)
        GRAVITY_M_S2.check("gravity_m_s2", self.gravity_m_s2)?;
        check_ge_system(
            &self.cable,
            Some(&self.aerostat),
            self.initial_length_m,
            self.gravity_m_s2,
        )?;
        BENDING_STIFFNESS_N_M2.check(
            "model.bending_stiffness_n_m2",
            self.model.bending_stiffness_n_m2,
        )?;
        INERTIA_RATIO.check("model.inertia_ratio", self.model.inertia_ratio)?;
        each(STIFFNESS_RATIO, "stiffness_ratios", &self.stiffness_ratios)?;
        check_rate_grid(&self.rates_m_s, "rates_m_s")?;
        each(NET_BUOYANCY_N, "net_buoyancies_n", &self.net_buoyancies_n)?;
        if let Some(p) = &self.perturbation {
            each(FORCE_N, "perturbation.forces_n", &p.forces_n)?;
            TIME_S.check("perturbation.ramp_s", p.ramp_s)?;
            TIME_S.check("perturbation.hold_s", p.hold_s)?;
        }
        if let Some(w) = &self.wind {
            check_ge_wind(w)?;
        }
        if let Some(n) = &self.numerics {
            TIME_STEP_S.check("numerics.time_step_s", n.time_step_s)?;
            DURATION_S.check("numerics.horizon_s", n.horizon_s)?;
            RATE_1_S.check("numerics.growth_tolerance_1_s", n.growth_tolerance_1_s)?;
        }
        Ok(())
    }
}

impl GeBaseFrequencyResponseRequest {
    pub fn check_ranges(&self) -> Checked {
        check_ge_system(
            &self.cable,
            self.aerostat.as_ref(),
            self.initial_length_m,
            self.gravity_m_s2,
        )?;
        check_ge_model(&self.model)?;
        if let Some(p) = &self.profile {
            p.check_ranges("profile")?;
        }
        BASE_AMPLITUDE_M.check("amplitude_m", self.amplitude_m)?;
        check_grid(
            FREQUENCY_RAD_S,
            &self.frequencies_rad_s,
            "frequencies_rad_s",
        )?;
        opt(
            FREQUENCY_RAD_S,
            "reference_frequency_rad_s",
            self.reference_frequency_rad_s,
        )?;
        DURATION_S.check("duration_s", self.duration_s)?;
        TIME_STEP_S.check("time_step_s", self.time_step_s)?;
        EPSILON_NONDIM
            .check(
                "reduced_model_epsilon_nondim",
                self.reduced_model_epsilon_nondim,
            )
            .map(drop)
    }
}

fn check_ge_numerics(n: &ge_charts::GeChartNumericsInput) -> Checked {
    TIME_STEP_S.check("numerics.time_step_s", n.time_step_s)?;
    DURATION_S.check("numerics.horizon_s", n.horizon_s)?;
    RATE_1_S
        .check("numerics.growth_tolerance_1_s", n.growth_tolerance_1_s)
        .map(drop)
}

impl GeCriticalRequest {
    /// The ranges of a GE critical-time request (the same fields as the
    /// GE chart's, so the schema bounds hold on every route).
    pub fn check_ranges(&self) -> Checked {
        check_ge_system(
            &self.cable,
            Some(&self.aerostat),
            self.initial_length_m,
            self.gravity_m_s2,
        )?;
        check_ge_model(&self.model)?;
        self.profile.check_ranges("profile")?;
        match &self.numerics {
            Some(n) => check_ge_numerics(n),
            None => Ok(()),
        }
    }
}

impl GeStabilityRequest {
    /// The ranges of a GE stability request.
    pub fn check_ranges(&self) -> Checked {
        check_ge_system(
            &self.cable,
            Some(&self.aerostat),
            self.initial_length_m,
            self.gravity_m_s2,
        )?;
        check_ge_model(&self.model)?;
        StabilityParams {
            state: self.state.clone(),
            modes: 1,
        }
        .check_ranges(self.initial_length_m)
    }
}
