//! The wind on the aerostat of a transient run or frequency response
//! (SPEC §2): the air flow (steady, sinusoidal, power law, tabulated,
//! turbulent) and the aerostat as an aerodynamic body, with their
//! conversion to [`crate::numerics::aero`].

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::numerics::aero::{Aerodynamics, AerostatBody, AirFlow, ForceModel, SteadyFlow};
use crate::numerics::params::{InvalidInput, require_non_negative, require_positive};

fn default_air_density() -> f64 {
    1.205
}

fn default_wavenumber() -> f64 {
    0.01
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
