//! Quasi-static GE critical length, critical payout rate and maximum safe
//! altitude, in calm air or a steady wind (issue 12 item 4), from the
//! local stability of [`super::quasi_static`].
//!
//! **The search.** Along one parameter `p` (the tether length at a fixed
//! payout rate, or the rate at a fixed length) the state is judged by its
//! local QEP: stable iff `max Re λ ≤ tol` (the tolerance of
//! [`crate::numerics::qep::Spectrum::tolerance`]). The onset is found in
//! three stages:
//!
//! 1. **scan** — equilibria at `scan_points` evenly spaced values of `p`,
//!    each Newton started from the previous one, and the number of
//!    negative eigenvalues of `K` at each in calm air (Sylvester inertia
//!    of a band `LDLᵀ`, O(n)), in wind the sign of `det K` (band LU);
//! 2. **divergence root** — where that count first grows, an eigenvalue
//!    of `K` passes through zero, and with it a real eigenvalue of the
//!    QEP; the root is refined to `1e-12` relative by
//!    [`refine_root`](super::qs_root::refine_root)
//!    (Illinois regula falsi on `det K`, safeguarded by the count;
//!    equilibrium + band `LDLᵀ` per step, no eigenvalues), shared with
//!    the converged search of [`super::qs_converged`];
//! 3. **confirmation** — the QEP is solved at `p*(1 ∓ δ)`: stable below,
//!    and above either unstable or with a real eigenvalue above zero
//!    (just past the root it grows more slowly than the roundoff
//!    tolerance), confirms the onset at the root. Otherwise (a flutter
//!    onset, no sign change, or an earlier instability) the QEP verdict
//!    itself is bisected between the last stable and the first unstable
//!    value to relative width `δ`.
//!
//! In calm air at a constant rate the stiffness is symmetric and the
//! symmetric part of the damping is `(L̇/L)` times the cable's mass
//! matrix — positive definite while paying out — so by the
//! Kelvin–Tait–Chetaev theorem the state is stable exactly while `K` is
//! positive definite: the divergence root *is* the onset (as for the
//! string's pencil bisection); the confirmation checks it. A state whose
//! equilibrium cannot be found (the cable's weight exceeds the lift) is
//! counted unstable.
//!
//! The quasi-static critical time of a constant-rate deployment from `L0`
//! is `t* = (L* − L0)/L̇`.

use super::GeModel;
use super::air_load::AirLoads;
use super::element::{TipLoad, node};
use super::quasi_static::{
    QsConfig, divergence_indicator, state_at, wind_equilibrium, wind_matrices,
};

use super::qs_root::{MAX_BISECTIONS, Scan, refine_root, scan_change};
use super::solver::NewtonFailure;
use super::stability::{StateMotion, spectrum_of};
use crate::numerics::params::{InvalidInput, Kinematics, require_finite, require_positive};

/// Largest number of scan points.
pub const MAX_SCAN_POINTS: usize = 10_000;

/// Settings of a quasi-static search.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QsSearchConfig {
    pub state: QsConfig,
    /// Equilibria of the scan (≥ 1).
    pub scan_points: usize,
    /// Relative half-width `δ` of the QEP confirmation and of the QEP bisection.
    pub relative_tolerance: f64,
    /// Solve the QEP (at the lower end and on either side of the root).
    /// Without it the verdict is the inertia of `K` alone: exact by the
    /// Kelvin–Tait–Chetaev theorem in calm air at a constant payout rate
    /// (`K` symmetric, damping positive definite), O(n) per state, so fine
    /// meshes stay cheap. Refused in wind or with an acceleration.
    pub confirm_with_qep: bool,
}

impl Default for QsSearchConfig {
    fn default() -> Self {
        Self {
            state: QsConfig::default(),
            scan_points: 16,
            relative_tolerance: 1e-4,
            confirm_with_qep: true,
        }
    }
}

impl QsSearchConfig {
    pub fn validate(&self) -> Result<(), InvalidInput> {
        if !(1..=MAX_SCAN_POINTS).contains(&self.scan_points) {
            return Err(InvalidInput::new(
                "numerics.scan_points",
                format!(
                    "must be between 1 and {MAX_SCAN_POINTS}, got {}",
                    self.scan_points
                ),
            ));
        }
        if !(1e-12..=0.1).contains(&self.relative_tolerance) {
            return Err(InvalidInput::new(
                "numerics.relative_tolerance_nondim",
                format!(
                    "must be between 1e-12 and 0.1, got {}",
                    self.relative_tolerance
                ),
            ));
        }
        Ok(())
    }
}

/// Where along the parameter the state first loses stability.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum QsOnset {
    /// Unstable at the lower end (`max Re λ` there, 1/s).
    Immediate { max_real_1_s: f64 },
    /// First unstable at `at`.
    During { at: f64 },
    /// Stable up to the upper end `up_to`.
    Never { up_to: f64 },
    /// No equilibrium at the lower end.
    EquilibriumFailed { at: f64, failure: NewtonFailure },
    /// The eigenvalue iteration failed at `at`.
    SpectrumFailed { at: f64 },
    /// Stopped by the caller.
    Cancelled,
}

/// The state at the onset (or at the end of the search).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct OnsetState {
    pub root_axial_force_n: f64,
    pub tip_altitude_m: f64,
    pub tip_downwind_m: f64,
}

/// Result of one search.
#[derive(Clone, Debug, PartialEq)]
pub struct QsSearch {
    pub onset: QsOnset,
    /// The final bracket `(stable, unstable)`, when there is an onset during the range.
    pub bracket: Option<(f64, f64)>,
    /// Whether the onset is the divergence root confirmed by the QEP.
    pub divergence: bool,
    pub qep_solves: usize,
    pub equilibria: usize,
    /// The equilibrium at the onset (`During`) or at the upper end (`Never`).
    pub at_onset: Option<OnsetState>,
}

/// One point's verdict.
enum Verdict {
    Stable,
    Unstable(f64),
    NoEquilibrium(NewtonFailure),
    SpectrumFailed,
}

struct Searcher<'a, K: Fn(f64) -> Kinematics> {
    model: &'a GeModel,
    load: TipLoad,
    air: &'a AirLoads,
    motion: StateMotion,
    config: &'a QsSearchConfig,
    kin: K,
    qep_solves: usize,
    equilibria: usize,
    /// Last equilibrium found.
    last: Option<Vec<f64>>,
    /// Every equilibrium found, by parameter: the next one starts from the
    /// nearest (a start far along the parameter, e.g. the end of the scan
    /// when the QEP bisection goes back to its beginning, can converge in
    /// wind to a spurious buckled equilibrium with almost no tension).
    known: Vec<(f64, Vec<f64>)>,
}

impl<K: Fn(f64) -> Kinematics> Searcher<'_, K> {
    fn equilibrium(&mut self, p: f64) -> Result<Vec<f64>, NewtonFailure> {
        self.equilibria += 1;
        let kin = (self.kin)(p);
        let start = nearest(&self.known, p)
            .map(|k| k.1.as_slice())
            .or(self.last.as_deref());
        let eq = wind_equilibrium(
            self.model,
            kin,
            self.load,
            self.air,
            &self.config.state,
            start,
        )?;
        self.last = Some(eq.q.clone());
        self.known.push((p, eq.q.clone()));
        Ok(eq.q)
    }

    /// The divergence indicator at `p` ([`divergence_indicator`]: the
    /// inertia of `K` in calm air, the parity of `det K` in wind, and
    /// `ln |det|`); `None` without an equilibrium or with a zero pivot.
    fn indicator(&mut self, p: f64) -> Option<(usize, f64)> {
        let q = self.equilibrium(p).ok()?;
        divergence_indicator(self.model, (self.kin)(p), self.load, self.air, &q)
    }

    /// The QEP verdict at `p`. With `divergence`, a real eigenvalue above
    /// zero also counts as unstable (however slowly it grows: just past a
    /// divergence root it is below the roundoff tolerance).
    fn verdict(&mut self, p: f64, divergence: bool) -> (Verdict, Option<OnsetState>) {
        let q = match self.equilibrium(p) {
            Ok(q) => q,
            Err(f) => return (Verdict::NoEquilibrium(f), None),
        };
        let kin = (self.kin)(p);
        let Ok(state) = state_at(self.model, kin, self.load, self.air, self.motion, q) else {
            return (Verdict::SpectrumFailed, None);
        };
        self.qep_solves += 1;
        let at = onset_state(self.model, kin, &state.q);
        match spectrum_of(
            self.model,
            wind_matrices(self.model, kin, self.load, self.air, &state),
        ) {
            Err(_) => (Verdict::SpectrumFailed, Some(at)),
            Ok(s)
                if s.max_real > s.tolerance()
                    || (divergence && s.eigenvalues.iter().any(|e| e.im == 0.0 && e.re > 0.0)) =>
            {
                (Verdict::Unstable(s.max_real), Some(at))
            }
            Ok(_) => (Verdict::Stable, Some(at)),
        }
    }
}

fn interpolate(a: OnsetState, b: OnsetState, f: f64) -> OnsetState {
    OnsetState {
        root_axial_force_n: a.root_axial_force_n
            + f * (b.root_axial_force_n - a.root_axial_force_n),
        tip_altitude_m: a.tip_altitude_m + f * (b.tip_altitude_m - a.tip_altitude_m),
        tip_downwind_m: a.tip_downwind_m + f * (b.tip_downwind_m - a.tip_downwind_m),
    }
}

/// The equilibrium already found nearest to `p` along the parameter (a
/// start far along it can converge in wind to a spurious buckled
/// equilibrium with almost no tension).
pub(super) fn nearest(known: &[(f64, Vec<f64>)], p: f64) -> Option<&(f64, Vec<f64>)> {
    known
        .iter()
        .min_by(|a, b| (a.0 - p).abs().total_cmp(&(b.0 - p).abs()))
}

/// The state of the equilibrium `q` at `kin`: root force, top of the cable.
pub(super) fn onset_state(model: &GeModel, kin: Kinematics, q: &[f64]) -> OnsetState {
    let top = node(q, model.elements);
    OnsetState {
        root_axial_force_n: super::critical::root_axial_force_n(model, kin.length_m, q),
        tip_altitude_m: kin.length_m + top[0],
        tip_downwind_m: top[1],
    }
}

/// The states along the length at a constant rate and acceleration.
pub fn along_length(rate_m_s: f64, acceleration_m_s2: f64) -> impl Fn(f64) -> Kinematics {
    move |length_m| Kinematics {
        length_m,
        rate_m_s,
        acceleration_m_s2,
    }
}

/// The constant-rate states at one length, along the rate.
pub fn along_rate(length_m: f64) -> impl Fn(f64) -> Kinematics {
    move |rate_m_s| Kinematics {
        length_m,
        rate_m_s,
        acceleration_m_s2: 0.0,
    }
}

/// The first loss of stability along `p ∈ [lo, hi]` with the state
/// `kin(p)`; `cancel()` is polled between equilibria.
#[allow(clippy::too_many_arguments)]
pub fn search_onset(
    model: &GeModel,
    net_buoyancy_n: f64,
    air: &AirLoads,
    motion: StateMotion,
    config: &QsSearchConfig,
    range: (f64, f64),
    kin: impl Fn(f64) -> Kinematics,
    cancel: &dyn Fn() -> bool,
) -> Result<QsSearch, InvalidInput> {
    search_onset_from(
        model,
        net_buoyancy_n,
        air,
        motion,
        config,
        range,
        kin,
        cancel,
        None,
    )
}

/// [`search_onset`] with the first equilibrium's Newton started from
/// `start` (an equilibrium near the lower end, e.g. continued along the
/// length: in strong wind on a long tether the start from the straight
/// calm state can land on a compressed branch).
#[allow(clippy::too_many_arguments)]
pub fn search_onset_from(
    model: &GeModel,
    net_buoyancy_n: f64,
    air: &AirLoads,
    motion: StateMotion,
    config: &QsSearchConfig,
    range: (f64, f64),
    kin: impl Fn(f64) -> Kinematics,
    cancel: &dyn Fn() -> bool,
    start: Option<&[f64]>,
) -> Result<QsSearch, InvalidInput> {
    config.validate()?;
    require_positive("net_buoyancy_n", net_buoyancy_n)?;
    if !config.confirm_with_qep && !air.is_calm() {
        return Err(InvalidInput::new(
            "numerics.confirm_with_qep",
            "the inertia of K alone decides stability only in calm air; confirm with the QEP in wind",
        ));
    }
    let (lo, hi) = range;
    require_finite("range.min", lo)?;
    require_finite("range.max", hi)?;
    if hi < lo {
        return Err(InvalidInput::new(
            "range.max",
            format!("must be at least the lower end {lo}, got {hi}"),
        ));
    }
    let mut s = Searcher {
        model,
        load: TipLoad {
            force_n: [net_buoyancy_n, 0.0],
            moment_n_m: 0.0,
        },
        air,
        motion,
        config,
        kin,
        qep_solves: 0,
        equilibria: 0,
        last: start.map(<[f64]>::to_vec),
        known: Vec::new(),
    };
    let mut out = QsSearch {
        onset: QsOnset::Cancelled,
        bracket: None,
        divergence: false,
        qep_solves: 0,
        equilibria: 0,
        at_onset: None,
    };
    let finish = |mut out: QsSearch, s: &Searcher<'_, _>| {
        out.qep_solves = s.qep_solves;
        out.equilibria = s.equilibria;
        out
    };
    if !config.confirm_with_qep {
        return Ok(inertia_only(&mut s, lo, hi, out));
    }
    // the lower end
    let (v0, st0) = s.verdict(lo, false);
    let q_lo = s.last.clone();
    match v0 {
        Verdict::NoEquilibrium(failure) => {
            out.onset = QsOnset::EquilibriumFailed { at: lo, failure };
            return Ok(finish(out, &s));
        }
        Verdict::SpectrumFailed => {
            out.onset = QsOnset::SpectrumFailed { at: lo };
            return Ok(finish(out, &s));
        }
        Verdict::Unstable(m) => {
            out.onset = QsOnset::Immediate { max_real_1_s: m };
            out.at_onset = st0;
            return Ok(finish(out, &s));
        }
        Verdict::Stable => {}
    }
    let mut stable = (lo, st0.unwrap_or_default());
    let delta = config.relative_tolerance;
    // 1. scan the inertia of K
    let i_lo = q_lo
        .as_ref()
        .and_then(|q| divergence_indicator(model, (s.kin)(lo), s.load, air, q));
    let n = config.scan_points;
    let mut det_bracket = None;
    let mut no_eq_at = None;
    if let Some((c_lo, _)) = i_lo {
        let mut last = None;
        match scan_change(
            (lo, hi),
            n,
            |p| match s.equilibrium(p) {
                Err(_) => None,
                Ok(q) => {
                    last = divergence_indicator(model, (s.kin)(p), s.load, air, &q);
                    Some(last.map(|x| x.0) == Some(c_lo))
                }
            },
            cancel,
        ) {
            Scan::Cancelled => return Ok(finish(out, &s)),
            Scan::Unchanged => {}
            Scan::Bracket { a, b, failed: true } => no_eq_at = Some((a, b)),
            Scan::Bracket { a, b, .. } => det_bracket = Some((a, b, last)),
        }
    }
    // 2. the divergence root
    let mut unstable: Option<(f64, Option<OnsetState>)> = None;
    if let Some((a, b, i_b)) = det_bracket {
        s.last = q_lo.clone();
        let i_a = if a == lo { i_lo } else { s.indicator(a) };
        let Some((a, b)) = refine_root((a, b), (i_a, i_b), 1e-12, |p| s.indicator(p), cancel)
        else {
            return Ok(finish(out, &s));
        };
        let root = 0.5 * (a + b);
        // 3. confirm with the QEP on either side
        let (below, above) = (root - delta * root.abs(), root + delta * root.abs());
        let (vb, stb) = if below > lo {
            s.verdict(below, false)
        } else {
            (Verdict::Stable, Some(stable.1))
        };
        let (va, sta) = s.verdict(above.min(hi), true);
        match (&vb, &va) {
            (Verdict::Stable, Verdict::Unstable(_)) => {
                out.onset = QsOnset::During { at: root };
                out.bracket = Some((below.max(lo), above.min(hi)));
                out.divergence = true;
                out.at_onset = match (stb, sta) {
                    (Some(x), Some(y)) => Some(interpolate(x, y, 0.5)),
                    (x, y) => x.or(y),
                };
                return Ok(finish(out, &s));
            }
            _ => {
                if matches!(vb, Verdict::Stable) {
                    stable = (below, stb.unwrap_or_default());
                } else {
                    unstable = Some((below, stb));
                }
                if unstable.is_none() && !matches!(va, Verdict::Stable) {
                    unstable = Some((above.min(hi), sta));
                } else if matches!(va, Verdict::Stable) {
                    stable = (above.min(hi), sta.unwrap_or_default());
                }
            }
        }
    } else if let Some((_, p)) = no_eq_at {
        unstable = Some((p, None));
    }
    // QEP bisection: find an unstable upper end first, scanning up from the stable one
    if unstable.is_none() {
        let start = stable.0;
        for k in 1..=n {
            if cancel() {
                return Ok(finish(out, &s));
            }
            let p = start + (hi - start) * k as f64 / n as f64;
            let (v, st) = s.verdict(p, false);
            match v {
                Verdict::Stable => stable = (p, st.unwrap_or_default()),
                Verdict::SpectrumFailed => {
                    out.onset = QsOnset::SpectrumFailed { at: p };
                    return Ok(finish(out, &s));
                }
                _ => {
                    unstable = Some((p, st));
                    break;
                }
            }
        }
    }
    let Some(mut bad) = unstable else {
        out.onset = QsOnset::Never { up_to: hi };
        out.at_onset = Some(stable.1);
        return Ok(finish(out, &s));
    };
    for _ in 0..MAX_BISECTIONS {
        if bad.0 - stable.0 <= 2.0 * delta * bad.0.abs() {
            break;
        }
        if cancel() {
            return Ok(finish(out, &s));
        }
        let m = 0.5 * (stable.0 + bad.0);
        let (v, st) = s.verdict(m, false);
        match v {
            Verdict::Stable => stable = (m, st.unwrap_or_default()),
            Verdict::SpectrumFailed => {
                out.onset = QsOnset::SpectrumFailed { at: m };
                return Ok(finish(out, &s));
            }
            _ => bad = (m, st),
        }
    }
    out.onset = QsOnset::During {
        at: 0.5 * (stable.0 + bad.0),
    };
    out.bracket = Some((stable.0, bad.0));
    out.at_onset = Some(match bad.1 {
        Some(b) => interpolate(stable.1, b, 0.5),
        None => stable.1,
    });
    Ok(finish(out, &s))
}

/// The search on the inertia of `K` alone (see [`QsSearchConfig::confirm_with_qep`]).
fn inertia_only<K: Fn(f64) -> Kinematics>(
    s: &mut Searcher<'_, K>,
    lo: f64,
    hi: f64,
    mut out: QsSearch,
) -> QsSearch {
    let state = |s: &mut Searcher<'_, K>, p: f64| -> Option<((usize, f64), OnsetState)> {
        let q = s.equilibrium(p).ok()?;
        let kin = (s.kin)(p);
        let c = divergence_indicator(s.model, kin, s.load, s.air, &q)?;
        Some((c, onset_state(s.model, kin, &q)))
    };
    let finish = |mut out: QsSearch, s: &Searcher<'_, K>| {
        out.equilibria = s.equilibria;
        out
    };
    let Some((c0, st0)) = state(s, lo) else {
        out.onset = QsOnset::EquilibriumFailed {
            at: lo,
            failure: NewtonFailure {
                time_s: 0.0,
                iterations: 0,
                residual_norm: f64::NAN,
            },
        };
        return finish(out, s);
    };
    if c0.0 > 0 {
        out.onset = QsOnset::Immediate {
            max_real_1_s: f64::NAN,
        };
        out.at_onset = Some(st0);
        return finish(out, s);
    }
    let n = s.config.scan_points;
    let mut last = None;
    let (a, b) = match scan_change(
        (lo, hi),
        n,
        |p| {
            last = state(s, p);
            Some(last.is_some_and(|x| x.0.0 == 0))
        },
        &|| false,
    ) {
        Scan::Bracket { a, b, .. } => (a, b),
        _ => {
            out.onset = QsOnset::Never { up_to: hi };
            out.at_onset = state(s, hi).map(|x| x.1).or(Some(st0));
            return finish(out, s);
        }
    };
    let i_a = if a == lo {
        Some(c0)
    } else {
        state(s, a).map(|x| x.0)
    };
    let i_b = last.map(|x| x.0);
    let (a, b) = refine_root(
        (a, b),
        (i_a, i_b),
        1e-12,
        |p| state(s, p).map(|x| x.0),
        &|| false,
    )
    .unwrap_or((a, b));
    let sa = state(s, a).map_or(st0, |x| x.1);
    let sb = state(s, b).map(|x| x.1);
    out.onset = QsOnset::During { at: 0.5 * (a + b) };
    out.bracket = Some((a, b));
    out.divergence = true;
    out.at_onset = Some(match sb {
        Some(x) => interpolate(sa, x, 0.5),
        None => sa,
    });
    finish(out, s)
}

/// Quasi-static critical length of a payout at constant rate `rate_m_s`
/// (and acceleration `acceleration_m_s2`) between `min_length_m` and
/// `max_length_m`.
#[allow(clippy::too_many_arguments)]
pub fn critical_length(
    model: &GeModel,
    net_buoyancy_n: f64,
    air: &AirLoads,
    rate_m_s: f64,
    acceleration_m_s2: f64,
    motion: StateMotion,
    config: &QsSearchConfig,
    (min_length_m, max_length_m): (f64, f64),
    cancel: &dyn Fn() -> bool,
) -> Result<QsSearch, InvalidInput> {
    require_positive("min_length_m", min_length_m)?;
    require_finite("rate_m_s", rate_m_s)?;
    require_finite("acceleration_m_s2", acceleration_m_s2)?;
    search_onset(
        model,
        net_buoyancy_n,
        air,
        motion,
        config,
        (min_length_m, max_length_m),
        along_length(rate_m_s, acceleration_m_s2),
        cancel,
    )
}

/// Quasi-static critical payout rate at one length: the smallest constant
/// rate in `[0, max_rate_m_s]` at which the state is unstable (`During`),
/// or `Never` when every rate up to the cap is stable.
#[allow(clippy::too_many_arguments)]
pub fn critical_rate(
    model: &GeModel,
    net_buoyancy_n: f64,
    air: &AirLoads,
    length_m: f64,
    max_rate_m_s: f64,
    motion: StateMotion,
    config: &QsSearchConfig,
    cancel: &dyn Fn() -> bool,
) -> Result<QsSearch, InvalidInput> {
    critical_rate_from(
        model,
        net_buoyancy_n,
        air,
        length_m,
        max_rate_m_s,
        motion,
        config,
        cancel,
        None,
    )
}

/// [`critical_rate`] with the first Newton started from `start` (see
/// [`search_onset_from`]).
#[allow(clippy::too_many_arguments)]
pub fn critical_rate_from(
    model: &GeModel,
    net_buoyancy_n: f64,
    air: &AirLoads,
    length_m: f64,
    max_rate_m_s: f64,
    motion: StateMotion,
    config: &QsSearchConfig,
    cancel: &dyn Fn() -> bool,
    start: Option<&[f64]>,
) -> Result<QsSearch, InvalidInput> {
    require_positive("length_m", length_m)?;
    require_positive("max_rate_m_s", max_rate_m_s)?;
    // At zero rate the calm cable has no damping (purely imaginary
    // spectrum); the search starts at a small fraction of the cap.
    search_onset_from(
        model,
        net_buoyancy_n,
        air,
        motion,
        config,
        (1e-3 * max_rate_m_s, max_rate_m_s),
        along_rate(length_m),
        cancel,
        start,
    )
}

/// The default upper end of a length search: well past the static lift
/// limit `(F + lift)/(ρA g)`, where the tether's weight equals the lift.
pub fn lift_limit_length_m(model: &GeModel, net_buoyancy_n: f64, air: &AirLoads) -> f64 {
    let u = air.wind.speed_m_s(
        net_buoyancy_n / (model.section.mass_per_length_kg_m * model.gravity_m_s2.max(1e-9)),
    );
    let lift = 0.5 * air.air_density_kg_m3 * air.aerostat_lift_area_m2 * u * u;
    (net_buoyancy_n + lift.max(0.0))
        / (model.section.mass_per_length_kg_m * model.gravity_m_s2.max(1e-9))
}
