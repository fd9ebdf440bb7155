//! The operating envelope judged by the quasi-static GE stability (issue
//! 12): each (wind, length) cell at the payout rate `v` is the local
//! stability [`wind_stability`] of the geometrically exact tether model of
//! [`ge_tether_system`] (blown-down equilibrium, then the QEP with the
//! payout's rate terms and the linearised air loads): stable iff
//! `max Re λ ≤` the spectrum's tolerance. Per wind speed the envelope also
//! gives the quasi-static critical length at `v` ([`critical_length`], the
//! maximum safe length and the blown-down altitude at the onset) and the
//! critical payout rate at one length ([`critical_rate`]).
//!
//! **Static limits first.** A cell that is slack or whose static shooting
//! did not converge is judged by the static limits only (no GE solve; a
//! slack cell counts as unstable, as for the string criterion); the other
//! cells get their GE verdict and the binding limit follows the order of
//! [`super::envelope`]. A GE equilibrium or spectrum that cannot be found
//! counts as unstable with no growth rate (as in [`critical_length`]).
//!
//! **Continuation.** Along a wind row the cells are solved in length order
//! and each Newton starts from the previous cell's equilibrium (the GE
//! unknowns live on the mapped interval `ζ ∈ [0, 1]`, so the shape of the
//! neighbouring length is a close guess); rows fan out on rayon.
//!
//! **Rotary inertia.** [`ge_tether_system`] gives the solid-section
//! `I_ρ = ρA d²/16`; its rotation–shear mode `√(GA/I_ρ) ≈ 4·10⁷ 1/s`
//! used to swamp the slow transverse eigenvalues with roundoff (spurious
//! growth rates of 0.05–0.2 1/s in calm air, where the states are stable
//! by the Kelvin–Tait–Chetaev theorem), so a stand-in radius of gyration of
//! 0.1 m was used. The tether's model now solves the slow modes by the
//! inverted problem ([`crate::numerics::ge::stability::slow_spectrum_of`],
//! a shift-invert about `λ = 0`): the spectrum is that of the solid
//! section itself, no stand-in (issue 21), converged or on a given mesh.
//! The rotation wave speed
//! `c_r = √(EI/I_ρ)` still bounds the payout rate (a sliding beam paid out
//! near it is unstable for that reason alone: its effective bending
//! stiffness is `EI − I_ρ L̇²`); with the solid section `c_r = (4/d)√(EI/ρA)`
//! is far above any winch (≈ 1900 m/s for a 6 mm Dyneema braid). Payout
//! rates at or above [`ROTATION_WAVE_FRACTION`] `· c_r` are refused.
//!
//! **Converged** (issue 21, [`GeStabilitySpec::converge`]): the critical
//! length and rate of each wind speed are the converged, conservative
//! onsets of [`crate::numerics::ge::qs_converged`] (nested meshes,
//! Richardson, safe side; in wind every level on the branch reached by
//! paying out, [`crate::numerics::ge::qs_wind`], and the length search
//! ends at the continuum tether's ground contact, where the cells turn
//! `slack`), the maximum safe altitude the blown-down
//! altitude at the safe length on the finest mesh. A cell longer than the
//! safe critical length of its wind is unstable; when the base mesh's QEP
//! search confirms that the onset along the length is a divergence, every
//! shorter cell is stable with no further eigenvalue solve (its growth rate
//! is not reported); otherwise each cell also needs its base-mesh QEP.
//! In wind (unless `tracked_wind_onset`) both limits are the string
//! criterion of the continuum tether in that wind
//! ([`crate::numerics::ge::wind_criterion`]: the GE onset there is an
//! imperfect bifurcation), so no cell needs a QEP: the 40 × 50 converged
//! envelope's median fell from 7.70 s to 82 ms (the plain envelope is 49 ms).

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use rayon::prelude::*;

use crate::numerics::ge::GeModel;
use crate::numerics::ge::air_load::AirLoads;
use crate::numerics::ge::element::TipLoad;
use crate::numerics::ge::qs_converged::{
    ConvergedOutcome, ConvergedSearch, ConvergenceConfig, converged_critical_length,
    converged_critical_rate,
};
use crate::numerics::ge::qs_critical::{
    OnsetState, QsOnset, QsSearch, QsSearchConfig, critical_length, critical_rate_from,
    lift_limit_length_m,
};
use crate::numerics::ge::qs_wind::airborne_length_m;
use crate::numerics::ge::quasi_static::{QsConfig, WindStateStability, wind_stability};
use crate::numerics::ge::stability::{GeStateFailure, StateMotion};
use crate::numerics::ge::tether_system::{GeTetherOptions, GeTetherSystem, ge_tether_system};
use crate::numerics::ge::wind_criterion;
use crate::numerics::parallel::Parallelism;
use crate::numerics::params::{InvalidInput, Kinematics, require_positive};
use crate::numerics::tether::envelope::{
    Envelope, EnvelopePoint, EnvelopeProblem, judge_with, summarise,
};
use crate::numerics::tether::equilibrium::EquilibriumConfig;

/// Fastest payout (and top of the rate search) as a fraction of the rotation
/// wave speed `√(EI/I_ρ)` (see the module docs).
pub const ROTATION_WAVE_FRACTION: f64 = 0.5;

/// The rotation wave speed `√(EI/I_ρ)` of a GE model (m/s).
pub fn rotation_wave_speed_m_s(model: &GeModel) -> f64 {
    (model.section.bending_stiffness_n_m2 / model.section.rotary_inertia_kg_m).sqrt()
}
/// Default elements of the envelope's GE model.
pub const DEFAULT_ELEMENTS: usize = 20;
/// Largest elements of the envelope's GE model.
pub const MAX_ELEMENTS: usize = 80;

/// What the quasi-static GE verdict needs beyond the envelope problem.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GeStabilitySpec {
    /// Bending stiffness `EI` (N m²).
    pub bending_stiffness_n_m2: f64,
    /// Aerostat mass (kg).
    pub aerostat_mass_kg: f64,
    /// Elements of the GE model.
    pub elements: usize,
    /// Length (m) at which the critical payout rate is searched.
    pub critical_rate_length_m: f64,
    /// Converge the critical length and rate (module docs); `None`: on the
    /// `elements` mesh as given.
    pub converge: Option<ConvergenceConfig>,
}

/// Per wind speed: the quasi-static critical length at the payout rate and
/// the critical payout rate at [`GeStabilitySpec::critical_rate_length_m`].
#[derive(Clone, Debug, PartialEq)]
pub struct GeWindLimits {
    /// Searched over `[shortest grid length, length_search_max_m]`.
    pub critical_length: QsSearch,
    pub length_search_max_m: f64,
    /// Searched over `[10⁻³, 1] · rate_search_max_m_s`.
    pub critical_rate: QsSearch,
    pub rate_search_max_m_s: f64,
    /// The converged searches (with [`GeStabilitySpec::converge`]).
    pub converged: Option<ConvergedLimits>,
}

/// The converged critical length and rate of one wind speed.
#[derive(Clone, Debug, PartialEq)]
pub struct ConvergedLimits {
    pub critical_length: ConvergedSearch,
    pub critical_rate: ConvergedSearch,
}

/// A converged search as a [`QsSearch`] at its safe side (the onset the
/// operator acts on), for the answer's per-wind fields; a flutter onset
/// on the base mesh is kept as it is (not converged).
pub fn safe_search(c: &ConvergedSearch) -> QsSearch {
    let (onset, at_onset) = match (&c.outcome, c.flutter) {
        (_, Some(f)) => (f, None),
        (ConvergedOutcome::During(o), None) => {
            (QsOnset::During { at: o.safe_value }, Some(o.at_safe))
        }
        (ConvergedOutcome::Immediate, None) => (
            QsOnset::Immediate {
                max_real_1_s: f64::NAN,
            },
            None,
        ),
        (ConvergedOutcome::Never { up_to }, None) => (QsOnset::Never { up_to: *up_to }, None),
        (ConvergedOutcome::Failed { at }, None) => (
            QsOnset::EquilibriumFailed {
                at: *at,
                failure: crate::numerics::ge::solver::NewtonFailure {
                    time_s: 0.0,
                    iterations: 0,
                    residual_norm: f64::NAN,
                },
            },
            None,
        ),
        (ConvergedOutcome::Cancelled, None) => (QsOnset::Cancelled, None),
    };
    QsSearch {
        onset,
        bracket: None,
        divergence: c.flutter.is_none(),
        qep_solves: 0,
        equilibria: c.equilibria,
        at_onset: at_onset.map(|s: OnsetState| s),
    }
}

/// The envelope with the GE verdicts.
#[derive(Clone, Debug, PartialEq)]
pub struct GeEnvelope {
    pub envelope: Envelope,
    /// Per point (row by row): `max Re λ` (1/s) of the cell's QEP; `None`
    /// when the cell was not solved (slack, not converged) or failed.
    pub max_growth_rate_1_s: Vec<Option<f64>>,
    /// Per wind speed.
    pub wind_limits: Vec<GeWindLimits>,
}

/// One wind row of a GE envelope.
#[derive(Clone, Debug, PartialEq)]
pub struct GeRow {
    pub points: Vec<EnvelopePoint>,
    pub max_growth_rate_1_s: Vec<Option<f64>>,
    pub wind_limits: GeWindLimits,
}

impl GeStabilitySpec {
    /// Refuses a payout rate at or above [`ROTATION_WAVE_FRACTION`] of the
    /// rotation wave speed of the model.
    pub fn validate_rate(
        &self,
        problem: &EnvelopeProblem,
        rate_m_s: f64,
    ) -> Result<(), InvalidInput> {
        let sys = ge_system(problem, self, 0.0)?;
        let cap = ROTATION_WAVE_FRACTION * rotation_wave_speed_m_s(&sys.model);
        if rate_m_s.abs() >= cap {
            return Err(InvalidInput::new(
                "payout_rate_m_s",
                format!(
                    "must be below {cap:.4} m/s with the quasi-static GE stability: {ROTATION_WAVE_FRACTION} of the rotation wave speed √(EI/I_ρ) of the tether (I_ρ = ρA d²/16, solid section); raise the bending stiffness or lower the rate"
                ),
            ));
        }
        Ok(())
    }

    pub fn validate(&self) -> Result<(), InvalidInput> {
        require_positive(
            "stability.bending_stiffness_n_m2",
            self.bending_stiffness_n_m2,
        )?;
        require_positive(
            "stability.critical_rate_length_m",
            self.critical_rate_length_m,
        )?;
        if !(2..=MAX_ELEMENTS).contains(&self.elements) {
            return Err(InvalidInput::new(
                "stability.elements",
                format!(
                    "must be between 2 and {MAX_ELEMENTS}, got {}",
                    self.elements
                ),
            ));
        }
        Ok(())
    }
}

/// The GE system of the envelope at one wind speed: [`ge_tether_system`]
/// of the problem at that wind and the longest grid length (which sets the
/// stiffness of an inextensible tether), solid section.
pub fn ge_system(
    problem: &EnvelopeProblem,
    spec: &GeStabilitySpec,
    wind_speed_m_s: f64,
) -> Result<GeTetherSystem, InvalidInput> {
    let longest = problem
        .tether_lengths_m
        .iter()
        .copied()
        .fold(problem.base.tether_length_m, f64::max);
    let sys = ge_tether_system(
        &problem.point_problem(wind_speed_m_s, longest),
        &GeTetherOptions {
            bending_stiffness_n_m2: spec.bending_stiffness_n_m2,
            aerostat_mass_kg: spec.aerostat_mass_kg,
            elements: spec.elements,
        },
    )?;
    Ok(sys)
}

/// The local QS GE stability of one cell (the single-point answer).
pub fn cell_stability(
    sys: &GeTetherSystem,
    length_m: f64,
    rate_m_s: f64,
    start: Option<&[f64]>,
) -> Result<WindStateStability, GeStateFailure> {
    wind_stability(
        &sys.model,
        Kinematics {
            length_m,
            rate_m_s,
            acceleration_m_s2: 0.0,
        },
        sys.tip_load,
        &sys.air,
        StateMotion::AtRest,
        &QsConfig::default(),
        start,
    )
}

/// The upper end of the rate search at `length_m`: twice the string's
/// critical rate for a tension bound `F + lift + drag + weight + tether drag`
/// (every tension of the blown-down tether is below it).
fn rate_search_max(model: &GeModel, air: &AirLoads, load: TipLoad, length_m: f64) -> f64 {
    let u = air.wind.speed_m_s(length_m).abs();
    let q = 0.5 * air.air_density_kg_m3 * u * u;
    let bound = load.force_n[0]
        + q * (air.aerostat_lift_area_m2.abs() + air.aerostat_drag_area_m2)
        + model.section.mass_per_length_kg_m * model.gravity_m_s2 * length_m
        + q * air.cable_diameter_m * air.cable_normal_drag_coefficient * length_m;
    let rotation =
        (model.section.bending_stiffness_n_m2 / model.section.rotary_inertia_kg_m).sqrt();
    (2.0 * (bound / model.section.mass_per_length_kg_m).sqrt())
        .min(ROTATION_WAVE_FRACTION * rotation)
}

/// The two searches of one wind speed (converged with
/// [`GeStabilitySpec::converge`], else on the `elements` mesh).
pub fn wind_limits(
    problem: &EnvelopeProblem,
    sys: &GeTetherSystem,
    spec: &GeStabilitySpec,
    rate_m_s: f64,
    rate_start: Option<&[f64]>,
    cancel: &dyn Fn() -> bool,
) -> Result<GeWindLimits, InvalidInput> {
    let config = QsSearchConfig::default();
    let lmin = problem
        .tether_lengths_m
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min);
    let lmax = problem.tether_lengths_m.iter().copied().fold(0.0, f64::max);
    let lift_max = lift_limit_length_m(&sys.model, sys.net_buoyancy_n, &sys.air)
        .max(lmax)
        .max(lmin);
    // In wind the GE model has no ground: past the continuum tether's
    // ground contact (the `slack` limit) its states are not the tether's
    // (`qs_wind`), so the length search stops there.
    let length_search_max_m = if sys.air.is_calm() {
        lift_max
    } else {
        airborne_length_m(&sys.model, &sys.air, sys.net_buoyancy_n, (lmin, lift_max))
    };
    let rate_search_max_m_s = rate_search_max(
        &sys.model,
        &sys.air,
        sys.tip_load,
        spec.critical_rate_length_m,
    );
    if let Some(cfg) = &spec.converge {
        // In wind the local GE onset is an imperfect bifurcation, not a
        // limit (`wind_criterion`): the string criterion of the continuum
        // tether in this wind, converged and on the safe side. With
        // `tracked_wind_onset` every level follows the branch reached by
        // paying out (`qs_wind`); its levels are not reliable near the
        // string speed (issue 21, `qs_wind_onset`): three levels, the safe
        // side below each.
        let (cl, cr) = if !sys.air.is_calm() && !cfg.tracked_wind_onset {
            (
                wind_criterion::critical_length(
                    &sys.model,
                    sys.net_buoyancy_n,
                    &sys.air,
                    rate_m_s,
                    (lmin, length_search_max_m),
                )?,
                wind_criterion::critical_rate(
                    &sys.model,
                    sys.net_buoyancy_n,
                    &sys.air,
                    spec.critical_rate_length_m,
                    rate_search_max_m_s,
                )?,
            )
        } else {
            converged_limits(
                sys,
                spec,
                cfg,
                rate_m_s,
                (lmin, length_search_max_m),
                rate_search_max_m_s,
                rate_start,
                cancel,
            )?
        };
        return Ok(GeWindLimits {
            critical_length: safe_search(&cl),
            length_search_max_m,
            critical_rate: safe_search(&cr),
            rate_search_max_m_s,
            converged: Some(ConvergedLimits {
                critical_length: cl,
                critical_rate: cr,
            }),
        });
    }
    let critical_length = critical_length(
        &sys.model,
        sys.net_buoyancy_n,
        &sys.air,
        rate_m_s,
        0.0,
        StateMotion::AtRest,
        &config,
        (lmin, length_search_max_m),
        cancel,
    )?;
    let critical_rate = critical_rate_from(
        &sys.model,
        sys.net_buoyancy_n,
        &sys.air,
        spec.critical_rate_length_m,
        rate_search_max_m_s,
        StateMotion::AtRest,
        &config,
        cancel,
        rate_start,
    )?;
    Ok(GeWindLimits {
        critical_length,
        length_search_max_m,
        critical_rate,
        rate_search_max_m_s,
        converged: None,
    })
}

/// The converged GE searches of one wind (calm air, or in wind with
/// [`ConvergenceConfig::tracked_wind_onset`]).
#[allow(clippy::too_many_arguments)]
fn converged_limits(
    sys: &GeTetherSystem,
    spec: &GeStabilitySpec,
    cfg: &ConvergenceConfig,
    rate_m_s: f64,
    (lmin, length_search_max_m): (f64, f64),
    rate_search_max_m_s: f64,
    rate_start: Option<&[f64]>,
    cancel: &dyn Fn() -> bool,
) -> Result<(ConvergedSearch, ConvergedSearch), InvalidInput> {
    let cfg = &if sys.air.is_calm() {
        *cfg
    } else {
        ConvergenceConfig {
            max_elements: 4 * cfg.base_elements,
            ..*cfg
        }
    };
    let cl = converged_critical_length(
        &sys.model,
        sys.net_buoyancy_n,
        &sys.air,
        rate_m_s,
        cfg,
        (lmin, length_search_max_m),
        cancel,
    )?;
    let cr = converged_critical_rate(
        &sys.model,
        sys.net_buoyancy_n,
        &sys.air,
        spec.critical_rate_length_m,
        rate_search_max_m_s,
        cfg,
        cancel,
        rate_start,
    )?;
    Ok((cl, cr))
}

/// One wind row: the static equilibria, the GE verdicts (continued along
/// the length) and the wind's critical length and rate.
pub fn ge_row(
    problem: &EnvelopeProblem,
    spec: &GeStabilitySpec,
    config: &EquilibriumConfig,
    wind_speed_m_s: f64,
    cancel: &dyn Fn() -> bool,
) -> Result<GeRow, InvalidInput> {
    let rate = problem.limits.payout_rate_m_s.ok_or_else(|| {
        InvalidInput::new(
            "payout_rate_m_s",
            "the quasi-static GE stability needs the payout rate",
        )
    })?;
    let config = EquilibriumConfig {
        keep_shape: false,
        ..*config
    };
    let sys = ge_system(problem, spec, wind_speed_m_s)?;
    let cap = ROTATION_WAVE_FRACTION * rotation_wave_speed_m_s(&sys.model);
    if rate.abs() >= cap {
        spec.validate_rate(problem, rate)?;
    }
    let rho_a = problem.base.cable.mass_per_length_kg_m;
    // Converged: the wind's limits first; they judge the cells by length.
    let converged_limits = match spec.converge {
        Some(_) => Some(wind_limits(problem, &sys, spec, rate, None, cancel)?),
        None => None,
    };
    // (longest safe length, whether no cell QEP is needed below it)
    let by_length: Option<(f64, bool)> = converged_limits.as_ref().map(|w| {
        let c = w.converged.as_ref().map(|c| &c.critical_length);
        let confirmed = c.is_some_and(|c| c.flutter.is_none());
        match (w.critical_length.onset, c.map(|c| &c.outcome)) {
            (QsOnset::During { at }, _) if confirmed => (at, true),
            (_, Some(ConvergedOutcome::During(o))) => (o.safe_value, confirmed),
            (QsOnset::Never { .. }, _) if confirmed => (f64::INFINITY, true),
            (QsOnset::Immediate { .. }, _) if confirmed => (f64::NEG_INFINITY, true),
            _ => (f64::INFINITY, false),
        }
    });
    let mut start: Option<Vec<f64>> = None;
    let mut rate_seed: Option<Vec<f64>> = None;
    let mut points = Vec::with_capacity(problem.tether_lengths_m.len());
    let mut growth = Vec::with_capacity(problem.tether_lengths_m.len());
    for &l in &problem.tether_lengths_m {
        let eq = problem.point_problem(wind_speed_m_s, l).solve(&config)?;
        let margin = Some(eq.min_tension_n - rho_a * rate * rate);
        let (stable, g) = if !eq.converged {
            (None, None)
        } else if eq.slack || eq.min_tension_n <= 0.0 {
            (Some(false), None)
        } else if let Some((safe, _)) = by_length
            && l > safe
        {
            (Some(false), None)
        } else if let Some((_, true)) = by_length {
            (Some(true), None)
        } else {
            match cell_stability(&sys, l, rate, start.as_deref()) {
                Ok(w) => {
                    let s = w.spectrum.is_stable();
                    let m = w.spectrum.max_real;
                    if l <= spec.critical_rate_length_m {
                        rate_seed = Some(w.state.q.clone());
                    }
                    start = Some(w.state.q);
                    (Some(s), Some(m))
                }
                Err(_) => {
                    start = None;
                    (Some(false), None)
                }
            }
        };
        let verdict = judge_with(&eq, &problem.limits, margin, stable);
        points.push(EnvelopePoint {
            wind_speed_m_s,
            tether_length_m: l,
            equilibrium: eq,
            verdict,
        });
        growth.push(g);
    }
    // The rate search starts from the row's tensioned branch: the GE
    // equilibrium of the longest cell at or below its length.
    let wind_limits = match converged_limits {
        Some(w) => w,
        None => wind_limits(problem, &sys, spec, rate, rate_seed.as_deref(), cancel)?,
    };
    Ok(GeRow {
        points,
        max_growth_rate_1_s: growth,
        wind_limits,
    })
}

/// The rows `range` of the wind grid; `progress(done, total)` after each
/// row (total = rows of the range); `None` when `cancelled()` stopped it.
pub fn ge_rows(
    problem: &EnvelopeProblem,
    spec: &GeStabilitySpec,
    config: &EquilibriumConfig,
    range: std::ops::Range<usize>,
    parallelism: Parallelism,
    progress: &(dyn Fn(usize, usize) + Sync),
    cancelled: &(dyn Fn() -> bool + Sync),
) -> Result<Option<Vec<GeRow>>, InvalidInput> {
    problem.validate()?;
    spec.validate()?;
    let winds = problem.wind_speeds_m_s.get(range).unwrap_or(&[]);
    let total = winds.len();
    let done = AtomicUsize::new(0);
    let stop = AtomicBool::new(false);
    let cancel = || stop.load(Ordering::Relaxed) || cancelled();
    let row = |&u: &f64| -> Result<Option<GeRow>, InvalidInput> {
        if cancel() {
            stop.store(true, Ordering::Relaxed);
            return Ok(None);
        }
        let r = ge_row(problem, spec, config, u, &cancel)?;
        progress(done.fetch_add(1, Ordering::Relaxed) + 1, total);
        Ok(Some(r))
    };
    let rows: Vec<Option<GeRow>> = match parallelism {
        Parallelism::Serial => winds.iter().map(row).collect::<Result<_, _>>()?,
        Parallelism::Rayon => winds.par_iter().map(row).collect::<Result<_, _>>()?,
    };
    if stop.load(Ordering::Relaxed) || cancelled() {
        return Ok(None);
    }
    Ok(rows.into_iter().collect())
}

/// The whole envelope with the GE verdicts.
pub fn solve_ge(
    problem: &EnvelopeProblem,
    spec: &GeStabilitySpec,
    config: &EquilibriumConfig,
    parallelism: Parallelism,
    progress: &(dyn Fn(usize, usize) + Sync),
    cancelled: &(dyn Fn() -> bool + Sync),
) -> Result<Option<GeEnvelope>, InvalidInput> {
    let n = problem.wind_speeds_m_s.len();
    let Some(rows) = ge_rows(
        problem,
        spec,
        config,
        0..n,
        parallelism,
        progress,
        cancelled,
    )?
    else {
        return Ok(None);
    };
    Ok(Some(assemble(problem, rows)))
}

/// The envelope from its rows (every wind row, in grid order).
pub fn assemble(problem: &EnvelopeProblem, rows: Vec<GeRow>) -> GeEnvelope {
    let mut growth = Vec::new();
    let mut limits = Vec::new();
    let mut points = Vec::new();
    for r in rows {
        growth.extend(r.max_growth_rate_1_s);
        limits.push(r.wind_limits);
        points.push(r.points);
    }
    GeEnvelope {
        envelope: summarise(
            points,
            &problem.wind_speeds_m_s,
            problem.tether_lengths_m.len(),
        ),
        max_growth_rate_1_s: growth,
        wind_limits: limits,
    }
}
