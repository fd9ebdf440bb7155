//! Converged answers of the linear string: `t*`, `h*` and the safe rate in
//! the continuum limit, each with an estimate of its discretisation error,
//! and the safe side of that error for an operator to act on (issue 10).
//!
//! **Why grade toward the roller.** The critical mode of a lengthening
//! string is a boundary layer at the roller (`ζ = 0`), where the effective
//! tension vanishes at onset. For constant rate the stiffness pencil is
//! *diagonal in the element slopes* (`qᵀ S_k q = Σ_e s_e (q_e − q_{e−1})²`),
//! so a mesh is stable iff every element is, the first element is always
//! the critical one, and the FE critical length depends on the size `h₁` of
//! the first element only: `μ(h₁) = (1 − ṽ² + ṽ²h₁ − ṽ²h₁²/3)/(1 − h₁/2)`,
//! first order in `h₁`, above the continuum `1 − ṽ²` (the FE space is a
//! subspace, so it always errs on the unsafe side). A uniform mesh pays for
//! `h₁` with `1/h₁` elements; a mesh graded geometrically toward the roller
//! pays `log₂(1/h₁)`.
//!
//! **Method** (the ladder: [`super::convergence`]). A nested sequence of
//! graded meshes ([`crate::numerics::mesh::Mesh::graded`],
//! [`BULK_ELEMENTS`] in the bulk, first element `h₁ = 2^{-k}/BULK_ELEMENTS` at
//! level `k`; each level adds one element). On the values `q_k` the known
//! first order is removed by Richardson extrapolation,
//! `R_k = 2 q_k − q_{k−1}`, and the error of `R_k` is estimated by
//! `|R_k − R_{k−1}|` (three times the true error when the remainder is
//! second order). Levels are added until that estimate is below the
//! tolerance (relative, default 1e-4) and the observed order
//! `log₂((q_{k−2} − q_{k−1})/(q_{k−1} − q_k))` is near 1. Measured (thesis
//! data, tests/verification_converged.rs): observed order 1.00 for constant
//! rate and constant acceleration; the extrapolated `h*` lands on the closed
//! form to better than 1e-6 relative.
//!
//! **Conservative.** Every `t*`, `h*` and safe rate handed out as the onset
//! ([`ConvergedCritical::onset`], [`ConvergedSafeRate::Rate::rate_m_s`]) is
//! the safe side of the error bound: best estimate minus its error.
//!
//! Accelerating and other profiles locate the divergence point (`det K`
//! through zero, pivot count) on each level, and confirm it with the QEP on
//! the coarsest level that resolves it to `PROBE_OFFSET/4`; if the QEP
//! disagrees they fall back to the QEP scan on that mesh.

use crate::numerics::params::{AerostatSystem, InvalidInput};
use crate::numerics::profile::Profile;
use crate::numerics::qep::QepError;
use crate::numerics::string::StringModel;
pub use crate::numerics::string::convergence::{
    BULK_ELEMENTS, Converged, DEFAULT_RELATIVE_TOLERANCE, Ladder, MAX_LEVELS,
    MAX_RELATIVE_TOLERANCE, MIN_RELATIVE_TOLERANCE, graded_operators, mesh_error_estimate,
    roller_operators, validate_tolerance,
};
use crate::numerics::string::convergence::{Family, climb};
use crate::numerics::string::critical::{
    self, CriticalTime, ImmediateCause, Onset, PROBE_OFFSET, QepProbe, SafeRate, SearchConfig,
    SearchMethod,
};
use crate::numerics::string::operators::StringOperators;

/// A converged critical-time answer.
#[derive(Clone, Debug, PartialEq)]
pub struct ConvergedCritical {
    /// The onset on the safe side: `t*` and `h*` lowered by their error.
    pub onset: Onset,
    /// Best estimate of `t*` (s) with its error; `None` unless `During`.
    pub time_s: Option<Converged>,
    /// Best estimate of `h*` (m) with its error; `None` unless `During`.
    pub length_m: Option<Converged>,
    pub method: SearchMethod,
    /// QEP probes (on the graded mesh that resolves the onset), if made.
    pub probes: Vec<QepProbe>,
    /// Elements of the finest mesh used.
    pub elements: usize,
}

impl ConvergedCritical {
    /// Conservative `t*` (s): `Some(0)` when unstable at once, `None` when never.
    pub fn conservative_time_s(&self) -> Option<f64> {
        match self.onset {
            Onset::Immediate(_) => Some(0.0),
            Onset::During { time_s, .. } => Some(time_s),
            Onset::Never { .. } => None,
        }
    }

    /// Do all QEP probes agree with the answer?
    pub fn confirmed(&self) -> bool {
        self.probes.iter().all(|p| p.stable == p.expected_stable)
    }

    /// Error estimate of `t*` (s), 0 when immediate or never.
    pub fn time_error_s(&self) -> f64 {
        self.time_s.map_or(0.0, |c| c.error_estimate)
    }

    /// Error estimate of `h*` (m), 0 when immediate or never.
    pub fn length_error_m(&self) -> f64 {
        self.length_m.map_or(0.0, |c| c.error_estimate)
    }

    fn immediate(cause: ImmediateCause, method: SearchMethod, elements: usize) -> Self {
        Self {
            onset: Onset::Immediate(cause),
            time_s: None,
            length_m: None,
            method,
            probes: vec![],
            elements,
        }
    }
}

/// Converged non-dimensional critical length `l*` of constant-rate
/// lengthening at `ṽ`; `None` at or above the wave speed.
pub fn critical_length_constant_rate(
    buoyancy_ratio: f64,
    rate_nondim: f64,
    tolerance: f64,
) -> Option<Converged> {
    let climbed = climb::<()>(tolerance, roller_operators, |_, ops, _| {
        Ok(critical::critical_length_constant_rate(
            ops,
            buoyancy_ratio,
            rate_nondim,
        ))
    })
    .ok()?;
    climbed.ok().map(|(c, _)| c)
}

/// Converged critical time of constant-rate lengthening (or shortening)
/// from `L0` at `rate_m_s`, stopping at `target_length_m` if given.
pub fn constant_rate(
    system: &AerostatSystem,
    rate_m_s: f64,
    target_length_m: Option<f64>,
    tolerance: f64,
) -> ConvergedCritical {
    let finest = graded_operators(0).dim();
    if rate_m_s < 0.0 {
        return ConvergedCritical::immediate(
            ImmediateCause::Shortening,
            SearchMethod::NegativeDamping,
            finest,
        );
    }
    let l0 = system.initial_length_m;
    let vt = rate_m_s / system.wave_speed_m_s();
    let Some(l) = critical_length_constant_rate(system.buoyancy_ratio(), vt, tolerance) else {
        return ConvergedCritical::immediate(
            ImmediateCause::RateAboveWaveSpeed,
            SearchMethod::StiffnessInertia,
            finest,
        );
    };
    let length = l.affine(0.0, l0);
    let mut answer = ConvergedCritical::immediate(
        ImmediateCause::UnstableInitialState,
        SearchMethod::StiffnessInertia,
        l.elements,
    );
    if length.lower() <= l0 {
        return answer;
    }
    let time = length.affine(-l0 / rate_m_s, 1.0 / rate_m_s);
    answer.onset = match target_length_m {
        Some(target) if target <= length.lower() => Onset::Never {
            until_s: (target - l0) / rate_m_s,
        },
        _ => Onset::During {
            time_s: time.lower(),
            length_m: length.lower(),
        },
    };
    if matches!(answer.onset, Onset::During { .. }) {
        answer.time_s = Some(time);
        answer.length_m = Some(length);
    }
    answer
}

/// Options of a converged search.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConvergedConfig {
    /// Relative tolerance of `t*` and `h*`.
    pub relative_tolerance: f64,
    /// Confirm constant-rate answers with QEP probes too (the other profiles
    /// always are).
    pub confirm_with_qep: bool,
}

impl Default for ConvergedConfig {
    fn default() -> Self {
        Self {
            relative_tolerance: DEFAULT_RELATIVE_TOLERANCE,
            confirm_with_qep: true,
        }
    }
}

/// Converged critical time of any profile.
pub fn critical_time(
    system: &AerostatSystem,
    profile: &Profile,
    config: ConvergedConfig,
) -> Result<ConvergedCritical, QepError> {
    let mut answer = match *profile {
        Profile::ConstantRate {
            rate_m_s,
            target_length_m,
            ..
        } if rate_m_s != 0.0 => {
            constant_rate(system, rate_m_s, target_length_m, config.relative_tolerance)
        }
        _ => return general_profile(system, profile, config.relative_tolerance),
    };
    if config.confirm_with_qep {
        let level = match answer.length_m {
            Some(l) => {
                let vt = profile.kinematics(0.0).rate_m_s / system.wave_speed_m_s();
                probe_level(l.value / system.initial_length_m, |ops| {
                    critical::critical_length_constant_rate(ops, system.buoyancy_ratio(), vt)
                })
            }
            None => 0,
        };
        let model = StringModel::with_operators(*system, graded_operators(level));
        answer.probes = probes_around(&model, profile, &answer.onset)?;
    }
    Ok(answer)
}

/// Converged critical time of constant acceleration from rest at `L0`.
pub fn constant_acceleration(
    system: &AerostatSystem,
    acceleration_m_s2: f64,
    target_length_m: Option<f64>,
    tolerance: f64,
) -> Result<ConvergedCritical, ConvergedError> {
    let profile = Profile::constant_acceleration(
        system.initial_length_m,
        acceleration_m_s2,
        target_length_m,
    )?;
    Ok(critical_time(
        system,
        &profile,
        ConvergedConfig {
            relative_tolerance: tolerance,
            confirm_with_qep: true,
        },
    )?)
}

/// Why a converged answer could not be given.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ConvergedError {
    #[error(transparent)]
    Invalid(#[from] InvalidInput),
    #[error(transparent)]
    Numerical(#[from] QepError),
}

/// The coarsest level whose value of `value_at` is within `PROBE_OFFSET/4`
/// of `converged_value` (levels are cached, so this is cheap).
fn probe_level(converged_value: f64, value_at: impl Fn(&StringOperators) -> Option<f64>) -> usize {
    for level in 0..MAX_LEVELS {
        if let Some(q) = value_at(&graded_operators(level))
            && (q - converged_value).abs() <= 0.25 * PROBE_OFFSET * converged_value.abs()
        {
            return level;
        }
    }
    MAX_LEVELS - 1
}

/// QEP probes either side of a (conservative) onset: stable at the start,
/// half-way and `PROBE_OFFSET` before, unstable `PROBE_OFFSET` after.
fn probes_around(
    model: &StringModel,
    profile: &Profile,
    onset: &Onset,
) -> Result<Vec<QepProbe>, QepError> {
    match *onset {
        Onset::Immediate(_) => Ok(vec![critical::probe(model, profile, 0.0, false)?]),
        Onset::During { time_s, .. } => Ok(vec![
            critical::probe(model, profile, 0.0, true)?,
            critical::probe(model, profile, 0.5 * time_s, true)?,
            critical::probe(model, profile, time_s * (1.0 - PROBE_OFFSET), true)?,
            critical::probe(model, profile, time_s * (1.0 + PROBE_OFFSET), false)?,
        ]),
        Onset::Never { until_s } => Ok(vec![
            critical::probe(model, profile, 0.0, true)?,
            critical::probe(model, profile, until_s, true)?,
        ]),
    }
}

/// `K` has a negative pivot at this state, or it shortens: the cheap
/// divergence indicator of [`critical`], without assembling `M` and `C`.
fn diverges(model: &StringModel, k: crate::numerics::params::Kinematics) -> bool {
    if k.rate_m_s < 0.0 || k.length_m <= 0.0 {
        return true;
    }
    let c = model.coefficients(model.system.to_nondim(k));
    let ops = &model.operators;
    let (cv, s0, s1, s2) = (&ops.conv, &ops.stiff_0, &ops.stiff_1, &ops.stiff_2);
    let (a, q, t0, t1) = (
        c.conv_stiffness,
        -c.quad_stiffness,
        c.tension_top,
        c.tension_slope,
    );
    crate::numerics::tridiag::count_negative_pivots(
        ops.dim(),
        |i| a * cv.diag[i] + q * s2.diag[i] + t0 * s0.diag[i] + t1 * s1.diag[i],
        |i| {
            let lower = a * cv.lower[i] + q * s2.lower[i] + t0 * s0.lower[i] + t1 * s1.lower[i];
            let upper = a * cv.upper[i] + q * s2.upper[i] + t0 * s0.upper[i] + t1 * s1.upper[i];
            lower * upper
        },
    ) > 0
}

/// First divergence time on one mesh: a full scan on the first level,
/// then a bracket around the previous level's answer.
fn divergence_time(
    model: &StringModel,
    profile: &Profile,
    horizon_s: f64,
    previous_s: Option<f64>,
) -> Option<f64> {
    first_unstable(
        |t| diverges(model, profile.kinematics(t)),
        horizon_s,
        previous_s,
    )
}

/// First `x ∈ [0, horizon]` where `unstable(x)`: a scan of 256 samples and
/// bisection, or, given the previous level's answer, a bracket around it
/// (widened until it holds a crossing, else the full scan).
fn first_unstable(
    unstable: impl Fn(f64) -> bool,
    horizon: f64,
    previous: Option<f64>,
) -> Option<f64> {
    let Some(prev) = previous.filter(|&t| t > 0.0) else {
        return critical::first_crossing(horizon, 256, unstable, &|| false);
    };
    let mut width = 1e-3 * prev;
    let mut lo;
    let mut hi;
    // lower end: stable
    let mut tries = 0;
    loop {
        lo = (prev - width).max(0.0);
        if !unstable(lo) {
            break;
        }
        tries += 1;
        if lo == 0.0 || tries > 20 {
            return critical::first_crossing(horizon, 256, unstable, &|| false);
        }
        width *= 4.0;
    }
    // upper end: unstable
    width = 1e-3 * prev;
    tries = 0;
    loop {
        hi = (prev + width).min(horizon);
        if unstable(hi) {
            break;
        }
        tries += 1;
        if hi >= horizon || tries > 20 {
            return critical::first_crossing(horizon, 256, unstable, &|| false);
        }
        lo = hi;
        width *= 4.0;
    }
    for _ in 0..200 {
        if hi - lo <= 1e-13 * hi {
            break;
        }
        let mid = 0.5 * (lo + hi);
        if unstable(mid) { hi = mid } else { lo = mid }
    }
    Some(hi)
}

/// Critical length (m) at a fixed rate and acceleration: the shortest
/// length at which the state diverges (`K` loses definiteness; for zero
/// acceleration and `rate ≥ 0` the exact pencil of [`critical`]), on one
/// mesh. `None` when shortening, unstable at any length, or stable up to
/// four times the static lift limit.
pub fn critical_length_at_state_on(
    model: &StringModel,
    rate_m_s: f64,
    acceleration_m_s2: f64,
    previous_m: Option<f64>,
) -> Option<f64> {
    let sys = &model.system;
    if rate_m_s < 0.0 || !rate_m_s.is_finite() || !acceleration_m_s2.is_finite() {
        return None;
    }
    if acceleration_m_s2 == 0.0 {
        let vt = rate_m_s / sys.wave_speed_m_s();
        return critical::critical_length_constant_rate(&model.operators, sys.buoyancy_ratio(), vt)
            .map(|l| l * sys.initial_length_m);
    }
    // the search runs over x = L − L_min, L_min = 1e-6 L0 (K is singular at L = 0)
    let shortest = 1e-6 * sys.initial_length_m;
    let far = sys.initial_length_m + 4.0 * sys.static_lift_limit_m();
    let unstable = |x: f64| {
        diverges(
            model,
            crate::numerics::params::Kinematics {
                length_m: shortest + x,
                rate_m_s,
                acceleration_m_s2,
            },
        )
    };
    first_unstable(unstable, far, previous_m.map(|l| l - shortest))
        .filter(|&x| x > 0.0)
        .map(|x| x + shortest)
}

/// Converged critical length (m) at a fixed rate and acceleration (see
/// [`critical_length_at_state_on`]): a state is stable only below it.
pub fn critical_length_at_state(
    system: &AerostatSystem,
    rate_m_s: f64,
    acceleration_m_s2: f64,
    tolerance: f64,
) -> Option<Converged> {
    let family: Family = if acceleration_m_s2 == 0.0 {
        roller_operators
    } else {
        graded_operators
    };
    let climbed = climb::<()>(tolerance, family, |_, ops, prev| {
        let model = StringModel::with_operators(*system, ops.clone());
        Ok(critical_length_at_state_on(
            &model,
            rate_m_s,
            acceleration_m_s2,
            prev,
        ))
    })
    .ok()?;
    climbed.ok().map(|(c, _)| c)
}

/// Converged critical time of a profile other than constant rate.
fn general_profile(
    system: &AerostatSystem,
    profile: &Profile,
    tolerance: f64,
) -> Result<ConvergedCritical, QepError> {
    let coarse = StringModel::with_operators(*system, graded_operators(0));
    let horizon = critical::clamp_to_positive_length(
        &coarse,
        profile,
        critical::search_horizon_s(&coarse, profile),
    );
    if profile.kinematics(1e-9 * horizon).rate_m_s < 0.0 {
        let mut answer = ConvergedCritical::immediate(
            ImmediateCause::Shortening,
            SearchMethod::NegativeDamping,
            coarse.elements(),
        );
        answer.probes = vec![critical::probe(&coarse, profile, 1e-2 * horizon, false)?];
        return Ok(answer);
    }
    let mut first_none: Option<f64> = None;
    let climbed = climb::<()>(tolerance, graded_operators, |_, ops, prev| {
        let model = StringModel::with_operators(*system, ops.clone());
        let t = divergence_time(&model, profile, horizon, prev);
        match t {
            Some(t) if t > 0.0 => Ok(Some(t)),
            other => {
                first_none = Some(other.unwrap_or(f64::INFINITY));
                Ok(None)
            }
        }
    })
    .unwrap_or(Err(0));
    let (time, ladder) = match climbed {
        Ok(found) => found,
        Err(level) => {
            // no crossing (never) or unstable at once on some level
            let elements = graded_operators(level).dim();
            let model = StringModel::with_operators(*system, graded_operators(level));
            let onset = critical::onset_at(
                &model,
                profile,
                first_none.filter(|t| t.is_finite()),
                horizon,
            );
            let mut answer = ConvergedCritical {
                onset,
                time_s: None,
                length_m: None,
                method: SearchMethod::DivergenceConfirmedByQep,
                probes: vec![],
                elements,
            };
            answer.probes = probes_around(&model, profile, &answer.onset)?;
            return Ok(answer);
        }
    };
    // the QEP probes either side of t* go on the first level that resolves
    // t* to PROBE_OFFSET/3
    let within = PROBE_OFFSET / 3.0;
    let mut level = ladder.first_level_within(time.value, within);
    let mut last = ladder.values.last().copied();
    while level + 1 < MAX_LEVELS
        && level + 1 >= ladder.values.len()
        && last.is_some_and(|q| (q - time.value).abs() > within * time.value.abs())
    {
        level += 1;
        let model = StringModel::with_operators(*system, graded_operators(level));
        last = divergence_time(&model, profile, horizon, last);
    }
    let probe_model = StringModel::with_operators(*system, graded_operators(level));
    let mut answer = finish_during(profile, time, SearchMethod::DivergenceConfirmedByQep);
    answer.probes = match answer.onset {
        // stable at the start and half-way: the coarsest mesh sees that;
        // either side of t*: the mesh that resolves t*
        Onset::During { time_s, .. } => vec![
            critical::probe(&coarse, profile, 0.0, true)?,
            critical::probe(&coarse, profile, 0.5 * time_s, true)?,
            critical::probe(&probe_model, profile, time_s * (1.0 - PROBE_OFFSET), true)?,
            critical::probe(&probe_model, profile, time_s * (1.0 + PROBE_OFFSET), false)?,
        ],
        onset => probes_around(&probe_model, profile, &onset)?,
    };
    if answer.confirmed() {
        return Ok(answer);
    }
    // The QEP disagrees with the divergence point (flutter or worse): the
    // QEP scan on the mesh that resolves the divergence point.
    let scan: CriticalTime = critical::critical_time(
        &probe_model,
        profile,
        SearchConfig {
            confirm_with_qep: true,
        },
    )?;
    let mut answer = match scan.onset {
        Onset::During { time_s, .. } => {
            let spread = Converged {
                value: time_s,
                error_estimate: (time_s - time.value).abs() + time.error_estimate,
                elements: probe_model.elements(),
                order: f64::NAN,
                levels: 1,
                converged: false,
            };
            finish_during(profile, spread, scan.method)
        }
        onset => ConvergedCritical {
            onset,
            time_s: None,
            length_m: None,
            method: scan.method,
            probes: vec![],
            elements: probe_model.elements(),
        },
    };
    answer.probes = scan.probes;
    Ok(answer)
}

/// The conservative `During` onset (or `Immediate` when the safe side of
/// the bound reaches `t = 0`) from a converged `t*`.
fn finish_during(profile: &Profile, time: Converged, method: SearchMethod) -> ConvergedCritical {
    let t_safe = time.lower().max(0.0);
    let at = |t: f64| profile.kinematics(t).length_m;
    let length = Converged {
        value: at(time.value),
        error_estimate: (at(time.value) - at(t_safe)).abs(),
        ..time
    };
    let onset = if t_safe <= 0.0 {
        Onset::Immediate(ImmediateCause::UnstableInitialState)
    } else {
        Onset::During {
            time_s: t_safe,
            length_m: at(t_safe),
        }
    };
    ConvergedCritical {
        onset,
        time_s: Some(time),
        length_m: Some(length),
        method,
        probes: vec![],
        elements: time.elements,
    }
}

/// A converged safe rate.
#[derive(Clone, Debug, PartialEq)]
pub enum ConvergedSafeRate {
    Rate {
        /// The safe side of the bound (m/s): never above the continuum limit.
        rate_m_s: f64,
        /// `rate_m_s / c`.
        rate_nondim: f64,
        /// Best estimate of the continuum safe rate (m/s) with its error.
        estimate: Converged,
    },
    /// No lengthening rate is safe; `reason` says why.
    NoSafeRate { reason: String },
}

/// Converged largest constant rate that keeps the cable stable up to
/// `target_length_m`, on the safe side of its error bound.
pub fn safe_rate(
    system: &AerostatSystem,
    target_length_m: f64,
    tolerance: f64,
) -> Result<ConvergedSafeRate, InvalidInput> {
    // validation and the static limit, on the coarsest level
    let coarse = StringModel::with_operators(*system, graded_operators(0));
    if let SafeRate::NoSafeRate { reason } = critical::safe_rate(&coarse, target_length_m)? {
        return Ok(ConvergedSafeRate::NoSafeRate { reason });
    }
    // converge ν = ṽ*² (first order in h₁, like l*); the rate is √ν
    let mut reason = None;
    let climbed = climb::<InvalidInput>(tolerance, roller_operators, |_, ops, _| {
        let model = StringModel::with_operators(*system, ops.clone());
        Ok(match critical::safe_rate(&model, target_length_m)? {
            SafeRate::Rate { rate_nondim, .. } => Some(rate_nondim * rate_nondim),
            SafeRate::NoSafeRate { reason: r } => {
                reason = Some(r);
                None
            }
        })
    })?;
    let Ok((nu, _)) = climbed else {
        return Ok(ConvergedSafeRate::NoSafeRate {
            reason: reason.unwrap_or_else(|| "no safe rate".into()),
        });
    };
    let c = system.wave_speed_m_s();
    let safe_nu = nu.lower();
    if safe_nu <= 0.0 {
        return Ok(ConvergedSafeRate::NoSafeRate {
            reason: format!(
                "target {target_length_m} m is within the discretisation error of the static lift limit F/(ρA g) = {:.1} m",
                system.static_lift_limit_m()
            ),
        });
    }
    let best = nu.value.max(0.0).sqrt();
    let rate_nondim = safe_nu.sqrt();
    let estimate = Converged {
        value: best * c,
        error_estimate: (best - rate_nondim) * c,
        ..nu
    };
    Ok(ConvergedSafeRate::Rate {
        rate_m_s: rate_nondim * c,
        rate_nondim,
        estimate,
    })
}
