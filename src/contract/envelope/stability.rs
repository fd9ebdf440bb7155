//! The `stability` section of `POST /api/v1/envelope`: the string tension
//! criterion (default) or the quasi-static GE stability of
//! [`crate::numerics::tether::envelope_ge`], and the GE part of the answer
//! (per wind speed: the maximum safe length and altitude at the payout
//! rate, and the critical payout rate at one length).

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::contract::equilibrium::require_range;
use crate::numerics::ge::airy_onset::AiryOnset;
use crate::numerics::ge::qs_converged::{ConvergedOutcome, ConvergedSearch, ConvergenceConfig};
use crate::numerics::ge::qs_critical::{QsOnset, QsSearch};
use crate::numerics::ge::wind_criterion::WIND_CRITERION;
use crate::numerics::params::InvalidInput;
use crate::numerics::tether::envelope::EnvelopeProblem;
use crate::numerics::tether::envelope_ge::{
    DEFAULT_ELEMENTS, GeEnvelope, GeStabilitySpec, MAX_ELEMENTS, ge_system,
};
use crate::numerics::tether::equilibrium::EquilibriumConfig;
use crate::numerics::tether::string_onset::{self, StringLengthOnset};
use rayon::prelude::*;

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
        /// Bending stiffness EI of the tether (N m²); default the tether's
        /// (`cable.bending_stiffness_n_m2`, else the full-slip bound of its
        /// preset or of a 12-strand braid of its diameter: ≈ 0.16 N m² for
        /// a 6 mm Dyneema braid). A braided tether is nearly flexible.
        #[serde(default)]
        #[schema(example = 1.0, exclusive_minimum = 0.0, maximum = 1e9)]
        bending_stiffness_n_m2: Option<f64>,
        /// Finite elements of one GE mesh. Omitted (the default): the
        /// critical length and rate of each wind are converged (nested
        /// meshes from 20 elements, Richardson, to
        /// `relative_tolerance_nondim`) and given on the safe side, with
        /// their error estimates; the cells are judged against them.
        #[serde(default)]
        #[schema(example = 20, minimum = 2, maximum = 80)]
        elements: Option<usize>,
        /// Relative tolerance of the converged limits (default 1e-3);
        /// only without `elements`.
        #[serde(default)]
        #[schema(example = 0.001, minimum = 1e-6, maximum = 0.05)]
        relative_tolerance_nondim: Option<f64>,
        /// Length (m) at which the critical payout rate is searched;
        /// default the longest grid length.
        #[serde(default)]
        #[schema(example = 3000.0, exclusive_minimum = 0.0, maximum = 100000.0)]
        critical_rate_length_m: Option<f64>,
    },
}

impl EnvelopeStabilityInput {
    /// The GE settings, validated (`None` for the string criterion).
    /// `tether_bending_stiffness_n_m2`: the tether's own EI (the default).
    pub fn spec(
        &self,
        aerostat_mass_kg: f64,
        longest_length_m: f64,
        payout_rate_m_s: Option<f64>,
        tether_bending_stiffness_n_m2: Option<f64>,
    ) -> Result<Option<GeStabilitySpec>, InvalidInput> {
        let Self::QuasiStaticGe {
            bending_stiffness_n_m2,
            elements,
            relative_tolerance_nondim,
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
        let ei = match bending_stiffness_n_m2.or(tether_bending_stiffness_n_m2) {
            Some(ei) => require_range("stability.bending_stiffness_n_m2", ei, 0.0, true, 1e9)?,
            None => {
                return Err(InvalidInput::new(
                    "stability.bending_stiffness_n_m2",
                    "is needed: give the tether's bending stiffness EI in N m² (or the tether's diameter, from which it defaults)",
                ));
            }
        };
        if let Some(n) = elements
            && !(2..=MAX_ELEMENTS).contains(&n)
        {
            return Err(InvalidInput::new(
                "stability.elements",
                format!("must be between 2 and {MAX_ELEMENTS}, got {n}"),
            ));
        }
        let converge = ConvergenceConfig::requested(elements.is_some(), relative_tolerance_nondim)?;
        let at = match critical_rate_length_m {
            Some(l) => require_range("stability.critical_rate_length_m", l, 0.0, true, 1e5)?,
            None => longest_length_m,
        };
        Ok(Some(GeStabilitySpec {
            bending_stiffness_n_m2: ei,
            aerostat_mass_kg,
            elements: elements.unwrap_or(DEFAULT_ELEMENTS),
            critical_rate_length_m: at,
            converge,
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
    /// Maximum safe tether length at the payout rate (m): the onset;
    /// converged (no `elements`): the safe side, best estimate minus its
    /// error estimate.
    pub critical_length_m: Option<f64>,
    /// Converged only: the best estimate of the continuum critical length (m).
    pub critical_length_estimate_m: Option<f64>,
    /// Converged only: the estimated discretisation error of
    /// `critical_length_estimate_m` (m); `critical_length_m` is below the
    /// estimate by this much.
    pub critical_length_error_m: Option<f64>,
    /// Converged only: whether the error estimate met the tolerance
    /// (else the finest mesh was reached and the answer is still on the safe side).
    pub critical_length_converged: Option<bool>,
    /// Altitude of the blown-down aerostat at the onset (m): the maximum
    /// safe altitude (converged: at the safe length, on the finest mesh).
    pub critical_altitude_m: Option<f64>,
    /// Its downwind distance at the onset (m).
    pub critical_downwind_m: Option<f64>,
    /// Upper end of the length search (m): the static lift limit or the
    /// longest grid length; in wind at most the continuum tether's ground
    /// contact (past it the tether touches the ground: `slack`).
    pub length_search_max_m: f64,
    /// With `never`: altitude of the blown-down aerostat at `length_search_max_m` (m),
    /// stable up to there.
    pub stable_up_to_altitude_m: Option<f64>,
    /// Length of the rate search (m).
    pub critical_rate_length_m: f64,
    /// As `critical_length_outcome`, along the payout rate.
    pub critical_rate_outcome: String,
    /// Smallest unstable payout rate at `critical_rate_length_m` (m/s);
    /// converged: the safe side.
    pub critical_rate_m_s: Option<f64>,
    /// Converged only: the best estimate of the continuum critical rate (m/s).
    pub critical_rate_estimate_m_s: Option<f64>,
    /// Converged only: its estimated discretisation error (m/s).
    pub critical_rate_error_m_s: Option<f64>,
    /// Converged only: whether the error estimate met the tolerance.
    pub critical_rate_converged: Option<bool>,
    /// Upper end of the rate search (m/s); it starts at 10⁻³ of it.
    pub rate_search_max_m_s: f64,
    /// What gives the critical length and rate: `quasi_static_ge` (the GE
    /// onset, on the mesh or converged) or, converged in wind,
    /// `string_in_wind` — the string criterion of the continuum tether in
    /// this wind (min tension = ρA v²), because the local GE onset in wind
    /// is an imperfect bifurcation with no usable limit (the blow-down grows
    /// as T/(T − ρA v²); the GE QEP's first instability, near 175 m/s in
    /// 2 m/s of wind, does not converge). It is below the GE onset (bending
    /// only lifts it) and tends to the calm string criterion.
    pub critical_criterion: String,
    /// The string criterion's critical length at the payout rate (m): where
    /// the static tether's smallest tension in this wind equals ρA v² (in
    /// calm air the closed form (F/ρA − v²)/g). A reference beside the GE
    /// onset, not its safe side: in wind the GE spectrum may flutter first.
    /// `null` when the criterion holds up to `length_search_max_m` or fails
    /// at the shortest grid length (`string_critical_length_outcome`).
    pub string_critical_length_m: Option<f64>,
    /// `during`, `never` or `immediate`, as `critical_length_outcome`.
    pub string_critical_length_outcome: String,
    /// The string criterion's critical payout rate at
    /// `critical_rate_length_m` (m/s): √(T_min/ρA) of the static tether in
    /// this wind (calm air: √((F − ρA g L)/ρA)); `null` when it is slack there.
    pub string_critical_rate_m_s: Option<f64>,
    /// Calm air only: the closed form with the bending layer at the guide
    /// (Airy: F − ρA g L − ρA v² = a₁ (EI_eff b²)^(1/3), a₁ = −2.33811), the
    /// critical length at the payout rate (m), which the converged GE length
    /// tends to.
    pub bending_closed_form_length_m: Option<f64>,
    /// Calm air only: the same closed form's critical rate at
    /// `critical_rate_length_m` (m/s).
    pub bending_closed_form_rate_m_s: Option<f64>,
}

/// The closed forms of one wind row (see [`GeWindLimitOutput`]).
struct ClosedForms {
    string_length: (&'static str, Option<f64>),
    string_rate: Option<f64>,
    bending_length: Option<f64>,
    bending_rate: Option<f64>,
}

fn closed_forms(
    problem: &EnvelopeProblem,
    spec: &GeStabilitySpec,
    wind_speed_m_s: f64,
    length_search_max_m: f64,
    config: &EquilibriumConfig,
) -> ClosedForms {
    let v = problem.limits.payout_rate_m_s.unwrap_or(0.0);
    let shortest = problem
        .tether_lengths_m
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min);
    let base = problem.point_problem(wind_speed_m_s, shortest);
    let string_length = match string_onset::critical_length(
        &base,
        v,
        (shortest, length_search_max_m.max(shortest)),
        config,
    ) {
        Ok(StringLengthOnset::During { length_m }) => ("during", Some(length_m)),
        Ok(StringLengthOnset::Never { .. }) => ("never", None),
        Ok(StringLengthOnset::Immediate) | Err(_) => ("immediate", None),
    };
    let at = problem.point_problem(wind_speed_m_s, spec.critical_rate_length_m);
    let string_rate = string_onset::critical_rate_m_s(&at, config).ok().flatten();
    let calm = wind_speed_m_s == 0.0;
    let airy = calm
        .then(|| ge_system(problem, spec, wind_speed_m_s).ok())
        .flatten()
        .map(|sys| AiryOnset::of_model(&sys.model, problem.base.body.net_buoyancy_n));
    ClosedForms {
        string_length,
        string_rate,
        bending_length: airy.as_ref().and_then(|a| a.critical_length_m(v)),
        bending_rate: airy
            .as_ref()
            .and_then(|a| a.critical_rate_m_s(spec.critical_rate_length_m)),
    }
}

/// The quasi-static GE part of the envelope answer.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct GeStabilityOutput {
    /// EI used (N m²): as given, else the tether's default.
    pub bending_stiffness_n_m2: f64,
    pub aerostat_mass_kg: f64,
    /// Elements of the mesh (converged: of the base mesh; the finest mesh
    /// of each search is in `finest_elements`).
    pub elements: usize,
    /// Whether the critical lengths and rates are converged (`elements` omitted).
    pub converged: bool,
    /// Converged only: the relative tolerance asked.
    pub relative_tolerance_nondim: Option<f64>,
    /// Converged only: the finest mesh any search of the answer reached.
    pub finest_elements: Option<usize>,
    /// Rotary inertia per length used by the model (kg m): the solid
    /// section's ρA d²/16.
    pub rotary_inertia_kg_m: f64,
    /// Per grid wind speed.
    pub per_wind: Vec<GeWindLimitOutput>,
}

/// `(estimate, error, converged, finest elements)` of a converged search.
fn converged_fields(
    c: Option<&ConvergedSearch>,
) -> (Option<f64>, Option<f64>, Option<bool>, usize) {
    match c.map(|c| (&c.outcome, c.flutter.is_some())) {
        Some((ConvergedOutcome::During(o), false)) => (
            Some(o.value),
            Some(o.error_estimate),
            Some(o.converged),
            o.levels.last().map_or(0, |l| l.0),
        ),
        _ => (None, None, None, 0),
    }
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
    problem: &EnvelopeProblem,
    config: &EquilibriumConfig,
    ge: &GeEnvelope,
) -> GeStabilityOutput {
    let mass_per_length_kg_m = problem.base.cable.mass_per_length_kg_m;
    let diameter_m = problem.base.cable.diameter_m;
    let winds = &problem.wind_speeds_m_s;
    let closed: Vec<ClosedForms> = winds
        .par_iter()
        .zip(&ge.wind_limits)
        .map(|(&u, w)| closed_forms(problem, spec, u, w.length_search_max_m, config))
        .collect();
    let mut finest = 0;
    let per_wind = winds
        .iter()
        .zip(&ge.wind_limits)
        .zip(closed)
        .map(|((&u, w), cf)| {
            let (lo, at) = outcome(&w.critical_length);
            let (ro, rate) = outcome(&w.critical_rate);
            let state = at.and(w.critical_length.at_onset);
            let c = w.converged.as_ref();
            let (l_est, l_err, l_conv, l_n) = converged_fields(c.map(|c| &c.critical_length));
            let (r_est, r_err, r_conv, r_n) = converged_fields(c.map(|c| &c.critical_rate));
            finest = finest.max(l_n).max(r_n);
            GeWindLimitOutput {
                wind_speed_m_s: u,
                critical_length_outcome: lo.into(),
                critical_length_m: at,
                critical_length_estimate_m: l_est,
                critical_length_error_m: l_err,
                critical_length_converged: l_conv,
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
                critical_rate_estimate_m_s: r_est,
                critical_rate_error_m_s: r_err,
                critical_rate_converged: r_conv,
                rate_search_max_m_s: w.rate_search_max_m_s,
                critical_criterion: if spec.converge.is_some_and(|c| !c.tracked_wind_onset)
                    && u != 0.0
                    && problem.base.air_density_kg_m3 > 0.0
                {
                    WIND_CRITERION
                } else {
                    "quasi_static_ge"
                }
                .into(),
                string_critical_length_m: cf.string_length.1,
                string_critical_length_outcome: cf.string_length.0.into(),
                string_critical_rate_m_s: cf.string_rate,
                bending_closed_form_length_m: cf.bending_length,
                bending_closed_form_rate_m_s: cf.bending_rate,
            }
        })
        .collect();
    GeStabilityOutput {
        bending_stiffness_n_m2: spec.bending_stiffness_n_m2,
        aerostat_mass_kg: spec.aerostat_mass_kg,
        elements: spec.elements,
        converged: spec.converge.is_some(),
        relative_tolerance_nondim: spec.converge.map(|c| c.relative_tolerance),
        finest_elements: spec.converge.map(|_| finest.max(spec.elements)),
        rotary_inertia_kg_m: crate::numerics::ge::tether_system::solid_rotary_inertia_kg_m(
            mass_per_length_kg_m,
            diameter_m,
        ),
        per_wind,
    }
}
