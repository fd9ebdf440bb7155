//! The GE cable model every GE request shares (`"model"`): the kind, the
//! mesh, and the thesis's groups EI, E* and γ̃ — each omitted one taken
//! from the tether itself (issue 21): its bending stiffness (given, or the
//! full-slip bound of its preset or braid), its axial stiffness (or the
//! inextensible bound) and the rotary inertia of its solid section.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::contract::system::CableInput;
use crate::numerics::ge::Section;
use crate::numerics::ge::tether_system::{INEXTENSIBLE_STRAIN, solid_rotary_inertia_kg_m};
use crate::numerics::params::{InvalidInput, require_positive};

#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, ToSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum GeModelKind {
    /// Planar Simo–Reissner beam sliding out of a guide (thesis ch. 5–7).
    #[default]
    GeometricallyExact,
}

/// The GE model and its discretisation (thesis ch. 5.6 groups).
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct GeModelInput {
    pub kind: GeModelKind,
    /// Number of 2-node elements (1..=2000), default 20. `/critical`
    /// with `method: quasi_static`: omitted, the critical length is
    /// converged (nested meshes from 20 elements, Richardson) and given
    /// on the safe side with its error estimate.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 20, minimum = 1, maximum = 2000)]
    pub elements: Option<usize>,
    /// Bending stiffness EI (N m²). Omitted: the tether's own
    /// (`cable.bending_stiffness_n_m2`, else the full-slip bound of its
    /// preset or of a braid of `cable.diameter_m` and its axial stiffness),
    /// never the thesis table's 1000 N m².
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 1000.0, minimum = 1e-6, maximum = 1e12)]
    pub bending_stiffness_n_m2: Option<f64>,
    /// E* = EA L0²/EI, axial over bending stiffness. Omitted: from the
    /// tether's axial stiffness (`cable.axial_stiffness_n` or its preset's);
    /// without one, an inextensible tether (strain 1e-5 under the net
    /// buoyancy).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 1e5, minimum = 1.0, maximum = 1e12)]
    pub stiffness_ratio: Option<f64>,
    /// G A_s L0²/EI; defaults to the stiffness ratio (the thesis takes GA = EA).
    #[serde(default)]
    #[schema(example = 1e5, minimum = 1.0, maximum = 1e12)]
    pub shear_stiffness_ratio: Option<f64>,
    /// γ̃ = A_ρ L0²/I_ρ, translational over rotary inertia. Omitted: the
    /// solid round section of `cable.diameter_m`, `I_ρ = A_ρ d²/16`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 1.0, minimum = 1e-6, maximum = 1e12)]
    pub inertia_ratio: Option<f64>,
}

/// Elements of a GE mesh when `model.elements` is omitted (the base mesh
/// of a converged quasi-static search).
pub const DEFAULT_GE_ELEMENTS: usize = 20;

impl GeModelInput {
    /// `model.elements`, or [`DEFAULT_GE_ELEMENTS`].
    pub fn elements(&self) -> usize {
        self.elements.unwrap_or(DEFAULT_GE_ELEMENTS)
    }
}

impl GeModelInput {
    /// The section from the model's ratios (E*, γ̃, optional shear ratio),
    /// the cable (its mass per length, and the tether's own EI, EA and
    /// solid-section I_ρ for the ratios omitted: issue 21) and the length
    /// scale L0 (m). `tension_n` (the net buoyancy, N) sets the axial
    /// stiffness of a tether without one (strain
    /// [`INEXTENSIBLE_STRAIN`] under it).
    pub fn section(
        &self,
        cable: &CableInput,
        initial_length_m: f64,
        tension_n: Option<f64>,
    ) -> Result<Section, InvalidInput> {
        let rho_a = cable.mass_per_length()?;
        let l0 = require_positive("initial_length_m", initial_length_m)?;
        let ei = match self.bending_stiffness_n_m2 {
            Some(ei) => ei,
            None => cable.bending_stiffness("cable")?.ok_or_else(|| {
                InvalidInput::new(
                    "model.bending_stiffness_n_m2",
                    "is needed: give the tether's bending stiffness EI in N m², or the \
                     tether's diameter (cable.diameter_m) to take its own",
                )
            })?,
        };
        let ei = require_positive("model.bending_stiffness_n_m2", ei)?;
        let stiffness_ratio = match self.stiffness_ratio {
            Some(r) => r,
            None => {
                let ea = match (cable.axial_stiffness("cable")?, tension_n) {
                    (Some(ea), _) => ea,
                    (None, Some(t)) if t.abs() > 0.0 => t.abs() / INEXTENSIBLE_STRAIN,
                    (None, _) => {
                        return Err(InvalidInput::new(
                            "model.stiffness_ratio",
                            "is needed: give E* = EA L0²/EI, or the tether's axial \
                             stiffness (cable.axial_stiffness_n)",
                        ));
                    }
                };
                ea * l0 * l0 / ei
            }
        };
        let inertia_ratio = match self.inertia_ratio {
            Some(g) => g,
            None => {
                let d = cable.diameter_m.ok_or_else(|| {
                    InvalidInput::new(
                        "model.inertia_ratio",
                        "is needed: give γ̃ = A_ρ L0²/I_ρ, or the tether's diameter \
                         (cable.diameter_m) for the rotary inertia of its solid section",
                    )
                })?;
                let d = require_positive("cable.diameter_m", d)?;
                rho_a * l0 * l0 / solid_rotary_inertia_kg_m(rho_a, d)
            }
        };
        let mut section = Section::from_ratios(ei, stiffness_ratio, inertia_ratio, rho_a, l0)?;
        if let Some(gs) = self.shear_stiffness_ratio {
            section.shear_stiffness_n =
                require_positive("model.shear_stiffness_ratio", gs)? * ei / (l0 * l0);
        }
        Ok(section)
    }
}

/// E* = EA L0²/EI of a section (the ratio answered back).
pub fn stiffness_ratio_of(section: &Section, initial_length_m: f64) -> f64 {
    section.axial_stiffness_n * initial_length_m * initial_length_m / section.bending_stiffness_n_m2
}
