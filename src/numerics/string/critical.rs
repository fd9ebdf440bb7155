//! Critical time `t*` (first unstable instant of a deployment profile),
//! maximum safe elevation `h* = L(t*)`, and the safe rate for a target
//! elevation (SPEC §1, thesis ch. 4.2).
//!
//! The criterion is the quasi-static QEP: a state is stable iff every
//! `Re λ ≤ tol` of `λ²M + λC + K`. Two faster routes are used where they are
//! provably equivalent, and are checked against the QEP:
//!
//! * **Constant-rate lengthening** (`l̈ = 0`, `l̇ > 0`): `K` is symmetric and
//!   the symmetric part of `C` is `(l̇/l)·M_cable`, positive definite. By the
//!   Kelvin–Tait–Chetaev theorems (complete dissipation), the state is stable
//!   iff `K` is positive definite. `l·K = S₀ − ṽ² S₂ − (l/F̃) S₁` with constant
//!   symmetric tridiagonal `S_k = ∫(1−ζ)^k N'N'ᵀ`, and `S₁` is positive
//!   definite, so `K` loses definiteness exactly once, at
//!   `l* = F̃ · μ*`, `μ*` the smallest eigenvalue of the pencil
//!   `(S₀ − ṽ²S₂, S₁)`. `μ*` is found by bisection on the negative-pivot
//!   count (Sylvester inertia) in `O(n)` per step.
//! * **Shortening** (`l̇ < 0`): the symmetric part of `C` is negative definite;
//!   reversing time shows some `Re λ > 0` at every instant.
//!
//! Other profiles (accelerating: `K` is not symmetric) use the QEP as the
//! criterion. Their search first brackets the divergence point (a real
//! eigenvalue through zero, where `det K` changes sign, detected by the
//! pivot count) and then confirms with the QEP before, at and after it;
//! if the QEP disagrees anywhere it falls back to a QEP scan and bisection.

use crate::numerics::params::{InvalidInput, Kinematics};
use crate::numerics::profile::Profile;
use crate::numerics::qep::QepError;
use crate::numerics::string::StringModel;
use crate::numerics::string::operators::StringOperators;
use crate::numerics::tridiag::count_negative_pivots;

/// Relative offset in time of the QEP probes placed either side of `t*`.
pub const PROBE_OFFSET: f64 = 1e-3;
/// Relative precision of the pencil bisection (length, rate²).
const PENCIL_RTOL: f64 = 1e-12;
/// Iteration cap of every bisection here (2⁻²⁰⁰ is far below any tolerance).
const MAX_BISECTIONS: usize = 200;

/// Why a deployment is unstable from its first instant.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImmediateCause {
    /// The rate reaches the (discrete) wave speed at the initial length.
    RateAboveWaveSpeed,
    /// Shortening: negative damping, `Re λ > 0` at every instant.
    Shortening,
    /// The initial state is already beyond the stability limit.
    UnstableInitialState,
}

/// When the deployment first becomes unstable.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Onset {
    Immediate(ImmediateCause),
    /// First unstable at `time_s`, length `length_m`.
    During {
        time_s: f64,
        length_m: f64,
    },
    /// Stable over the whole profile (it stops, or never changes length,
    /// below the critical length); `until_s` is where the search ended.
    Never {
        until_s: f64,
    },
}

/// How the onset was located.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SearchMethod {
    /// Inertia of the symmetric `K` (constant-rate lengthening; exact by
    /// Kelvin–Tait–Chetaev).
    StiffnessInertia,
    /// Shortening: unstable by the sign of the damping.
    NegativeDamping,
    /// Divergence point from `det K`, confirmed by QEP probes.
    DivergenceConfirmedByQep,
    /// QEP scan and bisection (the probes disagreed with the divergence point).
    QepScan,
}

/// One QEP evaluation made to confirm an answer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QepProbe {
    pub time_s: f64,
    pub length_m: f64,
    /// Largest real part of the QEP eigenvalues (1/s).
    pub max_real_1_s: f64,
    pub stable: bool,
    pub expected_stable: bool,
}

/// Result of a critical-time search.
#[derive(Clone, Debug, PartialEq)]
pub struct CriticalTime {
    pub onset: Onset,
    pub method: SearchMethod,
    /// QEP probes: empty unless confirmation was asked for (or the method needs it).
    pub probes: Vec<QepProbe>,
}

impl CriticalTime {
    /// `t*` (s): `Some(0)` when unstable at once, `None` when never.
    pub fn time_s(&self) -> Option<f64> {
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
}

/// Options of the search.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SearchConfig {
    /// Confirm the fast answers with QEP probes either side of `t*`.
    pub confirm_with_qep: bool,
}

impl Default for SearchConfig {
    fn default() -> Self {
        Self {
            confirm_with_qep: true,
        }
    }
}

/// Critical time of any profile.
pub fn critical_time(
    model: &StringModel,
    profile: &Profile,
    config: SearchConfig,
) -> Result<CriticalTime, QepError> {
    critical_time_cancellable(model, profile, config, &|| false)
}

/// [`critical_time`], polling `cancel()` between the QEP solves of the
/// general search; `Err(QepError::Cancelled)` once it returns `true`.
pub fn critical_time_cancellable(
    model: &StringModel,
    profile: &Profile,
    config: SearchConfig,
    cancel: &dyn Fn() -> bool,
) -> Result<CriticalTime, QepError> {
    match *profile {
        Profile::ConstantRate {
            rate_m_s,
            target_length_m,
            ..
        } if rate_m_s > 0.0 => {
            let mut result = constant_rate_lengthening(model, rate_m_s, target_length_m);
            if config.confirm_with_qep {
                result.probes = probes_around(model, profile, &result.onset)?;
            }
            Ok(result)
        }
        Profile::ConstantRate { rate_m_s, .. } if rate_m_s < 0.0 => {
            let mut result = CriticalTime {
                onset: Onset::Immediate(ImmediateCause::Shortening),
                method: SearchMethod::NegativeDamping,
                probes: vec![],
            };
            if config.confirm_with_qep {
                result.probes = vec![probe(model, profile, 0.0, false)?];
            }
            Ok(result)
        }
        _ => general_profile(model, profile, cancel),
    }
}

/// `μ*`: the supremum of `μ ≥ 0` with `base_diag/base_off − μ·(step)`
/// positive definite, by bisection on the pivot count; `None` if not
/// positive definite at `μ = 0`.
pub(crate) fn pencil_limit(
    n: usize,
    base: impl Fn(usize) -> f64 + Copy,
    base_off: impl Fn(usize) -> f64 + Copy,
    step: impl Fn(usize) -> f64 + Copy,
    step_off: impl Fn(usize) -> f64 + Copy,
) -> Option<f64> {
    let definite = |mu: f64| {
        count_negative_pivots(
            n,
            |i| base(i) - mu * step(i),
            |i| {
                let o = base_off(i) - mu * step_off(i);
                o * o
            },
        ) == 0
    };
    if !definite(0.0) {
        return None;
    }
    let (mut lo, mut hi) = (0.0, 1.0);
    while definite(hi) {
        lo = hi;
        hi *= 2.0;
        if hi > 1e300 {
            return Some(f64::INFINITY);
        }
    }
    for _ in 0..MAX_BISECTIONS {
        if hi - lo <= PENCIL_RTOL * hi {
            break;
        }
        let mid = 0.5 * (lo + hi);
        if definite(mid) { lo = mid } else { hi = mid }
    }
    Some(0.5 * (lo + hi))
}

/// Non-dimensional critical length `l*` for constant-rate lengthening at
/// `ṽ`: `F̃ μ*` of the pencil `(S₀ − ṽ²S₂, S₁)`; `None` when `S₀ − ṽ²S₂`
/// is already indefinite (rate at or above the discrete wave speed).
pub fn critical_length_constant_rate(
    ops: &StringOperators,
    buoyancy_ratio: f64,
    rate_nondim: f64,
) -> Option<f64> {
    let v2 = rate_nondim * rate_nondim;
    let (s0, s1, s2) = (&ops.stiff_0, &ops.stiff_1, &ops.stiff_2);
    pencil_limit(
        ops.dim(),
        |i| s0.diag[i] - v2 * s2.diag[i],
        |i| s0.lower[i] - v2 * s2.lower[i],
        |i| s1.diag[i],
        |i| s1.lower[i],
    )
    .map(|mu| buoyancy_ratio * mu)
}

/// The fast, exact search for constant-rate lengthening (no QEP).
pub fn constant_rate_lengthening(
    model: &StringModel,
    rate_m_s: f64,
    target_length_m: Option<f64>,
) -> CriticalTime {
    let sys = &model.system;
    let vt = rate_m_s / sys.wave_speed_m_s();
    let onset = match critical_length_constant_rate(&model.operators, sys.buoyancy_ratio(), vt) {
        None => Onset::Immediate(ImmediateCause::RateAboveWaveSpeed),
        Some(l) if l <= 1.0 => Onset::Immediate(ImmediateCause::UnstableInitialState),
        Some(l) => {
            let length_m = l * sys.initial_length_m;
            match target_length_m {
                Some(target) if target <= length_m => Onset::Never {
                    until_s: (target - sys.initial_length_m) / rate_m_s,
                },
                _ => Onset::During {
                    time_s: (length_m - sys.initial_length_m) / rate_m_s,
                    length_m,
                },
            }
        }
    };
    CriticalTime {
        onset,
        method: SearchMethod::StiffnessInertia,
        probes: vec![],
    }
}

pub(crate) fn probe(
    model: &StringModel,
    profile: &Profile,
    time_s: f64,
    expected_stable: bool,
) -> Result<QepProbe, QepError> {
    let k = profile.kinematics(time_s);
    let spectrum = model.spectrum(model.system.to_nondim(k))?;
    Ok(QepProbe {
        time_s,
        length_m: k.length_m,
        max_real_1_s: model.system.eigenvalue_to_si(spectrum.max_real),
        stable: spectrum.is_stable(),
        expected_stable,
    })
}

/// QEP probes confirming an onset: stable at the start and just before
/// `t*`, unstable just after; stable at the start and end for `Never`.
fn probes_around(
    model: &StringModel,
    profile: &Profile,
    onset: &Onset,
) -> Result<Vec<QepProbe>, QepError> {
    match *onset {
        Onset::Immediate(_) => Ok(vec![probe(model, profile, 0.0, false)?]),
        Onset::During { time_s, .. } => Ok(vec![
            probe(model, profile, 0.0, true)?,
            probe(model, profile, 0.5 * time_s, true)?,
            probe(model, profile, time_s * (1.0 - PROBE_OFFSET), true)?,
            probe(model, profile, time_s * (1.0 + PROBE_OFFSET), false)?,
        ]),
        Onset::Never { until_s } => Ok(vec![
            probe(model, profile, 0.0, true)?,
            probe(model, profile, 0.5 * until_s, true)?,
            probe(model, profile, until_s, true)?,
        ]),
    }
}

/// Where a general search may stop: the profile's end, or once the cable
/// is far beyond the static lift limit (surely unstable by then).
pub(crate) fn search_horizon_s(model: &StringModel, profile: &Profile) -> f64 {
    let sys = &model.system;
    let far = sys.initial_length_m + 4.0 * sys.static_lift_limit_m();
    let reach = profile.time_to_length_s(far);
    match (profile.stop_time_s(), reach) {
        (Some(stop), Some(r)) => stop.min(r),
        (Some(stop), None) => stop,
        (None, Some(r)) => r,
        (None, None) => 0.0,
    }
}

/// Cheap divergence indicator: shortening, or `K` has a negative pivot.
pub(crate) fn looks_unstable(model: &StringModel, k: Kinematics) -> bool {
    if k.rate_m_s < 0.0 {
        return true;
    }
    if k.length_m <= 0.0 {
        return true;
    }
    let s = model.system.to_nondim(k);
    model.matrices(s).stiffness.negative_pivots() > 0
}

/// Shortening profiles that stop near zero length would make `l → 0`;
/// keep the search away from it.
pub(crate) fn clamp_to_positive_length(
    model: &StringModel,
    profile: &Profile,
    horizon_s: f64,
) -> f64 {
    let min_length = 1e-3 * model.system.initial_length_m;
    if profile.kinematics(horizon_s).length_m >= min_length {
        return horizon_s;
    }
    let (mut lo, mut hi) = (0.0, horizon_s);
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if profile.kinematics(mid).length_m >= min_length {
            lo = mid
        } else {
            hi = mid
        }
    }
    lo
}

/// First time the indicator turns unstable within `[0, horizon]`; `None`
/// also when `cancel()` stops the scan (the caller checks it).
pub(crate) fn first_crossing(
    horizon_s: f64,
    samples: usize,
    unstable: impl Fn(f64) -> bool,
    cancel: &dyn Fn() -> bool,
) -> Option<f64> {
    if unstable(0.0) {
        return Some(0.0);
    }
    let mut prev = 0.0;
    for j in 1..=samples {
        if cancel() {
            return None;
        }
        let t = horizon_s * j as f64 / samples as f64;
        if unstable(t) {
            let (mut lo, mut hi) = (prev, t);
            for _ in 0..MAX_BISECTIONS {
                if hi - lo <= 1e-12 * hi.max(1e-300) || cancel() {
                    break;
                }
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break;
                }
                if unstable(mid) { hi = mid } else { lo = mid }
            }
            return Some(hi);
        }
        prev = t;
    }
    None
}

fn general_profile(
    model: &StringModel,
    profile: &Profile,
    cancel: &dyn Fn() -> bool,
) -> Result<CriticalTime, QepError> {
    let check = || {
        if cancel() {
            Err(QepError::Cancelled)
        } else {
            Ok(())
        }
    };
    let horizon = clamp_to_positive_length(model, profile, search_horizon_s(model, profile));
    // A profile that starts retrieving (e.g. decelerating from rest) is
    // shortening from its first instant: unstable at once.
    if profile.kinematics(1e-9 * horizon).rate_m_s < 0.0 {
        // (probe where the rate has grown enough for Re λ to clear the tolerance)
        let probes = vec![probe(model, profile, 1e-2 * horizon, false)?];
        let onset = Onset::Immediate(ImmediateCause::Shortening);
        return Ok(CriticalTime {
            onset,
            method: SearchMethod::NegativeDamping,
            probes,
        });
    }
    let candidate = first_crossing(
        horizon,
        256,
        |t| looks_unstable(model, profile.kinematics(t)),
        cancel,
    );
    check()?;
    let onset = onset_at(model, profile, candidate, horizon);
    let probes = probes_around(model, profile, &onset)?;
    let result = CriticalTime {
        onset,
        method: SearchMethod::DivergenceConfirmedByQep,
        probes,
    };
    if result.confirmed() {
        return Ok(result);
    }
    // The QEP disagrees with the divergence point (flutter or worse):
    // search on the QEP verdict itself.
    let qep_unstable = |t: f64| -> bool {
        let k = profile.kinematics(t);
        model
            .spectrum(model.system.to_nondim(k))
            .map(|s| !s.is_stable())
            .unwrap_or(true)
    };
    check()?;
    let candidate = first_crossing(horizon, 64, qep_unstable, cancel);
    check()?;
    let onset = onset_at(model, profile, candidate, horizon);
    let probes = probes_around(model, profile, &onset)?;
    Ok(CriticalTime {
        onset,
        method: SearchMethod::QepScan,
        probes,
    })
}

pub(crate) fn onset_at(
    model: &StringModel,
    profile: &Profile,
    candidate: Option<f64>,
    horizon_s: f64,
) -> Onset {
    match candidate {
        Some(0.0) => {
            let k = profile.kinematics(0.0);
            Onset::Immediate(if k.rate_m_s < 0.0 {
                ImmediateCause::Shortening
            } else {
                ImmediateCause::UnstableInitialState
            })
        }
        Some(t) => Onset::During {
            time_s: t,
            length_m: profile.kinematics(t).length_m,
        },
        None => {
            let _ = model;
            Onset::Never { until_s: horizon_s }
        }
    }
}

/// Largest constant rate that keeps a deployment stable up to a target.
#[derive(Clone, Debug, PartialEq)]
pub enum SafeRate {
    /// Any rate up to `rate_m_s` reaches the target while stable.
    Rate {
        rate_m_s: f64,
        /// `ṽ = v / c`.
        rate_nondim: f64,
    },
    /// No lengthening rate is safe; `reason` says why.
    NoSafeRate { reason: String },
}

/// Safe rate for `target_length_m`: `K` must stay positive definite up to
/// the target, and `l K` decreases with `l` (Loewner order), so it is
/// enough at the target: `ṽ*² = ν*` of the pencil `(S₀ − (l_H/F̃) S₁, S₂)`.
pub fn safe_rate(model: &StringModel, target_length_m: f64) -> Result<SafeRate, InvalidInput> {
    let sys = &model.system;
    if !target_length_m.is_finite() || target_length_m <= sys.initial_length_m {
        return Err(InvalidInput::new(
            "target_elevation_m",
            format!(
                "must be a finite length above initial_length_m = {} m, got {target_length_m}",
                sys.initial_length_m
            ),
        ));
    }
    let limit = sys.static_lift_limit_m();
    if target_length_m >= limit {
        return Ok(SafeRate::NoSafeRate {
            reason: format!(
                "target {target_length_m} m is at or above the static lift limit F/(ρA g) = {limit:.1} m: \
                 the net buoyancy cannot hold that much cable even at rest"
            ),
        });
    }
    let ops = &model.operators;
    let load = target_length_m / sys.initial_length_m / sys.buoyancy_ratio();
    let (s0, s1, s2) = (&ops.stiff_0, &ops.stiff_1, &ops.stiff_2);
    let nu = pencil_limit(
        ops.dim(),
        |i| s0.diag[i] - load * s1.diag[i],
        |i| s0.lower[i] - load * s1.lower[i],
        |i| s2.diag[i],
        |i| s2.lower[i],
    );
    Ok(match nu {
        None => SafeRate::NoSafeRate {
            reason: format!(
                "target {target_length_m} m is beyond the discrete model's static stability limit"
            ),
        },
        Some(nu) => {
            let vt = nu.sqrt();
            SafeRate::Rate {
                rate_m_s: vt * sys.wave_speed_m_s(),
                rate_nondim: vt,
            }
        }
    })
}
