//! Tension outputs of the string-model answers (`critical`, `charts`):
//! the roller and aerostat tensions of the vertical cable at a deployment
//! state, with its rate and acceleration terms
//! ([`crate::numerics::tether::string_tension`]).

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::numerics::params::{AerostatSystem, Kinematics};
use crate::numerics::tether::string_tension::StringTension;

/// Tensions of the vertical cable at one deployment state.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct TensionOutput {
    /// Cable length of the state (m).
    pub length_m: f64,
    /// At the aerostat: F − m a (N).
    pub top_tension_n: f64,
    /// At the winch roller: F − m a − ρA(g + a)L (N); linear in between.
    pub winch_tension_n: f64,
    /// Kinematic term ρA v² (N).
    pub kinematic_tension_n: f64,
    /// Winch tension − ρA v² (N): zero at the continuum stability limit.
    pub effective_winch_tension_n: f64,
    /// Breaking strength / largest tension; null without `cable.breaking_strength_n`.
    pub safety_factor_nondim: Option<f64>,
    /// Tension vanishes somewhere along the cable (an outcome, not an error).
    pub slack: bool,
}

impl TensionOutput {
    pub fn at(sys: &AerostatSystem, k: Kinematics, breaking_strength_n: Option<f64>) -> Self {
        let t = StringTension::at(sys, k);
        Self {
            length_m: k.length_m,
            top_tension_n: t.top_n,
            winch_tension_n: t.winch_n,
            kinematic_tension_n: t.kinematic_n,
            effective_winch_tension_n: t.effective_winch_n,
            safety_factor_nondim: breaking_strength_n
                .filter(|_| t.max_n > 0.0)
                .map(|b| b / t.max_n),
            slack: t.slack,
        }
    }
}

impl crate::contract::dto::CableInput {
    /// `breaking_strength_n`, checked (positive, at most 1e9 N).
    pub fn breaking_strength(&self) -> Result<Option<f64>, crate::numerics::params::InvalidInput> {
        self.breaking_strength_n
            .map(|b| {
                crate::contract::equilibrium::require_range(
                    "cable.breaking_strength_n",
                    b,
                    0.0,
                    true,
                    1e9,
                )
            })
            .transpose()
    }
}
