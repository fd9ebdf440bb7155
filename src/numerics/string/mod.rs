//! Linear-string model of the cable (SPEC §1, thesis ch. 2, 4, app. A):
//! operators, matrices at a state, the stability spectrum, and the
//! critical-time and safe-rate searches built on them.

pub mod chart;
pub mod converged;
pub mod convergence;
pub mod critical;
pub mod frequency_response;
pub mod operators;
pub mod reduced;
pub mod rest_modes;
pub mod transient;

use std::sync::Arc;

use crate::numerics::params::{AerostatSystem, InvalidInput, NondimState};
use crate::numerics::qep::{self, QepError, Spectrum};
use operators::{MatrixCoefficients, SecondOrderSystem, StringOperators};

/// Smallest and largest element counts accepted.
pub const MIN_ELEMENTS: usize = 2;
pub const MAX_ELEMENTS: usize = 2000;

/// Checks an element count against `MIN_ELEMENTS..=MAX_ELEMENTS`.
pub fn validate_elements(field: &str, elements: usize) -> Result<usize, InvalidInput> {
    if !(MIN_ELEMENTS..=MAX_ELEMENTS).contains(&elements) {
        return Err(InvalidInput::new(
            field,
            format!("must be between {MIN_ELEMENTS} and {MAX_ELEMENTS}, got {elements}"),
        ));
    }
    Ok(elements)
}

/// Coefficients of `M, C, K` of the cable–aerostat system at the
/// non-dimensional state (app. A, with the `l̇` factor of `C` restored):
/// `T(ζ) = 1/l − m̃ l̈/l − (1/F̃ + l̈)(1−ζ)`.
pub fn state_coefficients(system: &AerostatSystem, s: NondimState) -> MatrixCoefficients {
    let ft = system.buoyancy_ratio();
    let mt = system.mass_ratio();
    MatrixCoefficients {
        mass_scale: s.length,
        tip_mass: mt,
        damping_scale: 2.0 * s.rate,
        conv_stiffness: s.acceleration,
        quad_stiffness: s.rate * s.rate / s.length,
        tension_top: (1.0 - mt * s.acceleration) / s.length,
        tension_slope: -(1.0 / ft + s.acceleration),
    }
}

/// A discretised cable–aerostat system.
#[derive(Clone, Debug)]
pub struct StringModel {
    pub system: AerostatSystem,
    pub operators: Arc<StringOperators>,
}

impl StringModel {
    pub fn new(system: AerostatSystem, elements: usize) -> Result<Self, InvalidInput> {
        validate_elements("model.elements", elements)?;
        Ok(Self {
            system,
            operators: Arc::new(StringOperators::new(elements)),
        })
    }

    /// Shares already assembled operators (sweeps over buoyancy).
    pub fn with_operators(system: AerostatSystem, operators: Arc<StringOperators>) -> Self {
        Self { system, operators }
    }

    pub fn elements(&self) -> usize {
        self.operators.dim()
    }

    /// Coefficients of `M, C, K` at the non-dimensional state: see
    /// [`state_coefficients`].
    pub fn coefficients(&self, s: NondimState) -> MatrixCoefficients {
        state_coefficients(&self.system, s)
    }

    pub fn matrices(&self, s: NondimState) -> SecondOrderSystem {
        self.operators.assemble(&self.coefficients(s))
    }

    /// Full QEP spectrum at a state (non-dimensional eigenvalues, 1/t̄).
    pub fn spectrum(&self, s: NondimState) -> Result<Spectrum, QepError> {
        qep::solve(&self.matrices(s))
    }
}
