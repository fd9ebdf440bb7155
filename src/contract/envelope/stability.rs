//! The `stability` section of `POST /api/v1/envelope`: the string tension
//! criterion (default) or the quasi-static GE stability of
//! [`crate::numerics::tether::envelope_ge`], and the GE part of the answer
//! (per wind speed: the maximum safe length and altitude at the payout
//! rate, and the critical payout rate at one length).

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::contract::equilibrium::require_range;
use crate::numerics::ge::qs_critical::{QsOnset, QsSearch};
use crate::numerics::params::InvalidInput;
use crate::numerics::tether::envelope_ge::{
    DEFAULT_ELEMENTS, GeEnvelope, GeStabilitySpec, MAX_ELEMENTS,
};

fn default_ge_elements() -> usize {
    DEFAULT_ELEMENTS
}

/// How stability is judged (needs `payout_rate_m_s`).
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(tag = "method", rename_all = "snake_case", deny_unknown_fields)]
pub enum EnvelopeStabilityInput {
    /// The continuum string criterion: stable while the smallest tension
    /// exceeds ρA v² (the default).
    String,
    /// The quasi-static GE stability of the blown-down tether at the payout
    /// rate: stable iff max Re λ of its local QEP ≤ the spectrum tolerance.
    /// Adds per wind speed the critical length and the critical payout rate.
    QuasiStaticGe {
        /// Bending stiffness EI of the tether (N m²); a braided tether is
        /// nearly flexible (≈ 0.01–10 N m²).
        #[schema(example = 1.0, exclusive_minimum = 0.0, maximum = 1e9)]
        bending_stiffness_n_m2: f64,
        /// Finite elements of the GE model (default 20).
        #[serde(default = "default_ge_elements")]
        #[schema(example = 20, minimum = 2, maximum = 80)]
        elements: usize,
        /// Length (m) at which the critical payout rate is searched;
        /// default the longest grid length.
        #[serde(default)]
        #[schema(example = 3000.0, exclusive_minimum = 0.0, maximum = 100000.0)]
        critical_rate_length_m: Option<f64>,
    },
}

impl EnvelopeStabilityInput {
    /// The GE settings, validated (`None` for the string criterion).
    pub fn spec(
        &self,
        aerostat_mass_kg: f64,
        longest_length_m: f64,
        payout_rate_m_s: Option<f64>,
    ) -> Result<Option<GeStabilitySpec>, InvalidInput> {
        let Self::QuasiStaticGe {
            bending_stiffness_n_m2,
            elements,
            critical_rate_length_m,
        } = *self
        else {
            return Ok(None);
        };
        if payout_rate_m_s.is_none() {
            return Err(InvalidInput::new(
                "payout_rate_m_s",
                "is required with stability.method = quasi_static_ge (the rate the stability is judged at)",
            ));
        }
        let ei = require_range(
            "stability.bending_stiffness_n_m2",
            bending_stiffness_n_m2,
            0.0,
            true,
            1e9,
        )?;
        if !(2..=MAX_ELEMENTS).contains(&elements) {
            return Err(InvalidInput::new(
                "stability.elements",
                format!("must be between 2 and {MAX_ELEMENTS}, got {elements}"),
            ));
        }
        let at = match critical_rate_length_m {
            Some(l) => require_range("stability.critical_rate_length_m", l, 0.0, true, 1e5)?,
            None => longest_length_m,
        };
        Ok(Some(GeStabilitySpec {
            bending_stiffness_n_m2: ei,
            aerostat_mass_kg,
            elements,
            critical_rate_length_m: at,
            converge: None,
        }))
    }
}

/// One wind speed's quasi-static GE limits.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct GeWindLimitOutput {
    pub wind_speed_m_s: f64,
    /// `during` (an onset in the searched range), `never` (stable up to
    /// `length_search_max_m`), `immediate` (unstable at the shortest grid
    /// length), `equilibrium_failed`, `spectrum_failed`.
    pub critical_length_outcome: String,
    /// Maximum safe tether length at the payout rate (m): the onset.
    pub critical_length_m: Option<f64>,
    /// Altitude of the blown-down aerostat at the onset (m): the maximum safe altitude.
    pub critical_altitude_m: Option<f64>,
    /// Its downwind distance at the onset (m).
    pub critical_downwind_m: Option<f64>,
    /// Upper end of the length search (m): the static lift limit or the longest grid length.
    pub length_search_max_m: f64,
    /// With `never`: altitude of the blown-down aerostat at `length_search_max_m` (m),
    /// stable up to there.
    pub stable_up_to_altitude_m: Option<f64>,
    /// Length of the rate search (m).
    pub critical_rate_length_m: f64,
    /// As `critical_length_outcome`, along the payout rate.
    pub critical_rate_outcome: String,
    /// Smallest unstable payout rate at `critical_rate_length_m` (m/s).
    pub critical_rate_m_s: Option<f64>,
    /// Upper end of the rate search (m/s); it starts at 10⁻³ of it.
    pub rate_search_max_m_s: f64,
}

/// The quasi-static GE part of the envelope answer.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct GeStabilityOutput {
    pub bending_stiffness_n_m2: f64,
    pub aerostat_mass_kg: f64,
    pub elements: usize,
    /// Rotary inertia per length used by the model (kg m): ρA · (0.1 m)².
    pub rotary_inertia_kg_m: f64,
    /// Per grid wind speed.
    pub per_wind: Vec<GeWindLimitOutput>,
}

fn outcome(s: &QsSearch) -> (&'static str, Option<f64>) {
    match s.onset {
        QsOnset::During { at } => ("during", Some(at)),
        QsOnset::Never { .. } => ("never", None),
        QsOnset::Immediate { .. } => ("immediate", None),
        QsOnset::EquilibriumFailed { .. } => ("equilibrium_failed", None),
        QsOnset::SpectrumFailed { .. } => ("spectrum_failed", None),
        QsOnset::Cancelled => ("cancelled", None),
    }
}

/// The GE output of a solved envelope.
pub fn ge_output(
    spec: &GeStabilitySpec,
    mass_per_length_kg_m: f64,
    diameter_m: f64,
    winds: &[f64],
    ge: &GeEnvelope,
) -> GeStabilityOutput {
    let per_wind = winds
        .iter()
        .zip(&ge.wind_limits)
        .map(|(&u, w)| {
            let (lo, at) = outcome(&w.critical_length);
            let (ro, rate) = outcome(&w.critical_rate);
            let state = at.and(w.critical_length.at_onset);
            GeWindLimitOutput {
                wind_speed_m_s: u,
                critical_length_outcome: lo.into(),
                critical_length_m: at,
                critical_altitude_m: state.map(|s| s.tip_altitude_m),
                critical_downwind_m: state.map(|s| s.tip_downwind_m),
                length_search_max_m: w.length_search_max_m,
                stable_up_to_altitude_m: match w.critical_length.onset {
                    QsOnset::Never { .. } => w.critical_length.at_onset.map(|s| s.tip_altitude_m),
                    _ => None,
                },
                critical_rate_length_m: spec.critical_rate_length_m,
                critical_rate_outcome: ro.into(),
                critical_rate_m_s: rate,
                rate_search_max_m_s: w.rate_search_max_m_s,
            }
        })
        .collect();
    GeStabilityOutput {
        bending_stiffness_n_m2: spec.bending_stiffness_n_m2,
        aerostat_mass_kg: spec.aerostat_mass_kg,
        elements: spec.elements,
        rotary_inertia_kg_m: if spec.converge.is_some() {
            crate::numerics::ge::tether_system::solid_rotary_inertia_kg_m(
                mass_per_length_kg_m,
                diameter_m,
            )
        } else {
            mass_per_length_kg_m
                * crate::numerics::tether::envelope_ge::ROTARY_INERTIA_RADIUS_M
                * crate::numerics::tether::envelope_ge::ROTARY_INERTIA_RADIUS_M
        },
        per_wind,
    }
}
