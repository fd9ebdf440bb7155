//! Local stability (thesis ch. 7.2): about a converged state, the
//! linearised equations `M ΔÜ + C ΔU̇ + K ΔU = 0` (7.2) give the QEP
//! `λ² M + λ C + K = 0` (7.3), with `K` the tangent stiffness (material,
//! geometric, sliding and aerostat parts). Solved through the companion
//! matrix `[[0, I], [−M⁻¹K, −M⁻¹C]]` (band LU of `M`, then faer's dense
//! eigenvalues in sequential mode). Eigenvalues are in 1/s.

use faer::Mat;

use super::GeModel;
use super::element::TipLoad;
use super::equations::{self, Drive, State, SystemMatrices};
use crate::numerics::params::Kinematics;
use crate::numerics::qep::{self, Eigenvalue, QepError, Spectrum};

/// The QEP spectrum of the linearisation about `state`.
pub fn local_spectrum(
    model: &GeModel,
    kin: Kinematics,
    load: TipLoad,
    mu: f64,
    state: &State,
) -> Result<Spectrum, QepError> {
    let sys = equations::system_matrices(model, kin, load, mu, &state.q, &state.v, &state.a);
    spectrum_of(model, sys)
}

/// The QEP spectrum about a state of a run under `drive` (its loads at the
/// state's time, air load included).
pub fn drive_spectrum(model: &GeModel, drive: &Drive, state: &State) -> Result<Spectrum, QepError> {
    spectrum_of(model, equations::drive_matrices(model, drive, state))
}

/// The QEP spectrum of the linearised system `sys` (companion form,
/// scaled); for a model with [`GeModel::slow_spectrum`] its slow modes
/// ([`slow_spectrum_of`]).
pub fn spectrum_of(model: &GeModel, sys: SystemMatrices) -> Result<Spectrum, QepError> {
    if model.slow_spectrum {
        if let Some(s) = slow_spectrum_of(model, &sys)? {
            return Ok(s);
        }
    }
    full_spectrum_of(model, sys)
}

/// Of the inverted problem, eigenvalues `μ = 1/λ` below this fraction of
/// the largest `|μ|` are dropped (see [`slow_spectrum_of`]).
pub const SLOW_SPECTRUM_CUT: f64 = 1e-6;

/// The slow modes of `λ² M + λ C + K = 0` by the inverted problem
/// `μ² K + μ C + M = 0`, `μ = 1/λ` (a shift-invert about `λ = 0`, on the
/// imaginary axis): companion `[[0, I], [−K⁻¹M, −K⁻¹C]]` with band LU of
/// `K`. The slowest modes, which decide stability, have the largest `|μ|`
/// and are resolved to roundoff of the *slowest* scale, not of the
/// stiffest: the rotation–shear modes of a thin solid section
/// (`√(GA/I_ρ) ≈ 10⁷ 1/s`) no longer swamp them, so no stand-in radius of
/// gyration is needed. Eigenvalues with `|μ| < `[`SLOW_SPECTRUM_CUT`]` ·
/// max |μ|` (modes more than 10⁶ times faster than the slowest, where
/// the roundoff of `Re λ = Re μ/|μ|²` would pass the stability tolerance)
/// are dropped: those modes are treated as quasi-static, the static
/// condensation of the rotation's inertia in the limit. The roundoff of
/// the kept ones is at most 10⁻⁷ of the spectrum's tolerance
/// ([`Spectrum::tolerance`], 10⁻⁹ of the kept radius) times the ratio of
/// radii, ≤ 0.1 of it. `None` when `K` is singular (then the caller
/// solves the full problem).
pub fn slow_spectrum_of(
    model: &GeModel,
    sys: &SystemMatrices,
) -> Result<Option<Spectrum>, QepError> {
    let n = model.dofs();
    let m = sys.mass.to_dense();
    let c = sys.damping.to_dense();
    if (0..n).any(|i| (0..n).any(|j| !m[(i, j)].is_finite() || !c[(i, j)].is_finite())) {
        return Err(QepError::NonFinite);
    }
    let Some(lu) = sys.stiffness.clone().factor() else {
        return Ok(None);
    };
    let mut inv = Mat::<f64>::zeros(n, 2 * n);
    let mut col = vec![0.0; n];
    for j in 0..2 * n {
        for i in 0..n {
            col[i] = if j < n { m[(i, j)] } else { c[(i, j - n)] };
        }
        lu.solve_in_place(&mut col);
        if col.iter().any(|x| !x.is_finite()) {
            return Ok(None);
        }
        for i in 0..n {
            inv[(i, j)] = col[i];
        }
    }
    let row_norm = |off: usize| {
        (0..n)
            .map(|i| (0..n).map(|j| inv[(i, j + off)].abs()).sum::<f64>())
            .fold(0.0, f64::max)
    };
    let sigma = row_norm(0).sqrt().max(row_norm(n)).max(1e-300);
    let companion = Mat::<f64>::from_fn(2 * n, 2 * n, |i, j| {
        if i < n {
            if j == i + n { 1.0 } else { 0.0 }
        } else if j < n {
            -inv[(i - n, j)] / (sigma * sigma)
        } else {
            -inv[(i - n, j)] / sigma
        }
    });
    let (re, im) = qep::eigenvalues_real(&companion)?;
    let mu: Vec<(f64, f64)> = re
        .into_iter()
        .zip(im)
        .map(|(r, i)| (sigma * r, sigma * i))
        .collect();
    let top = mu.iter().map(|&(r, i)| r.hypot(i)).fold(0.0, f64::max);
    if !(top > 0.0 && top.is_finite()) {
        return Ok(None);
    }
    let eigenvalues = mu
        .into_iter()
        .filter(|&(r, i)| r.hypot(i) >= SLOW_SPECTRUM_CUT * top)
        .map(|(r, i)| {
            let d = r * r + i * i;
            Eigenvalue {
                re: r / d,
                im: -i / d,
            }
        })
        .collect();
    Ok(Some(Spectrum::from_eigenvalues(eigenvalues)))
}

/// The full QEP spectrum of `sys` (companion form with `M⁻¹`, scaled).
pub fn full_spectrum_of(model: &GeModel, sys: SystemMatrices) -> Result<Spectrum, QepError> {
    let n = model.dofs();
    let k = sys.stiffness.to_dense();
    let c = sys.damping.to_dense();
    if (0..n).any(|i| (0..n).any(|j| !k[(i, j)].is_finite() || !c[(i, j)].is_finite())) {
        return Err(QepError::NonFinite);
    }
    let lu = sys.mass.factor().ok_or(QepError::NonFinite)?;
    // columns of M⁻¹[K | C]
    let mut inv = Mat::<f64>::zeros(n, 2 * n);
    let mut col = vec![0.0; n];
    for j in 0..2 * n {
        for i in 0..n {
            col[i] = if j < n { k[(i, j)] } else { c[(i, j - n)] };
        }
        lu.solve_in_place(&mut col);
        for i in 0..n {
            inv[(i, j)] = col[i];
        }
    }
    // Scale λ = σ μ with σ² = ‖M⁻¹K‖∞ so the companion has norm ~ 1 (the
    // stiff axial/shear modes otherwise make it ~ρ² and swamp the
    // eigenvalues with roundoff).
    let row_norm = |off: usize| {
        (0..n)
            .map(|i| (0..n).map(|j| inv[(i, j + off)].abs()).sum::<f64>())
            .fold(0.0, f64::max)
    };
    let sigma = row_norm(0).sqrt().max(row_norm(n)).max(1e-300);
    let companion = Mat::<f64>::from_fn(2 * n, 2 * n, |i, j| {
        if i < n {
            if j == i + n { 1.0 } else { 0.0 }
        } else if j < n {
            -inv[(i - n, j)] / (sigma * sigma)
        } else {
            -inv[(i - n, j)] / sigma
        }
    });
    let (re, im) = qep::eigenvalues_real(&companion)?;
    Ok(Spectrum::from_eigenvalues(
        re.into_iter()
            .zip(im)
            .map(|(re, im)| Eigenvalue {
                re: sigma * re,
                im: sigma * im,
            })
            .collect(),
    ))
}

/// How the cable moves at a queried state (see [`super::start::StartState`]).
pub use super::start::StartState as StateMotion;

/// Local stability of the GE cable at one deployment state `(L, L̇, L̈)`.
#[derive(Clone, Debug)]
pub struct GeStateStability {
    /// The straight equilibrium (quasi-static at the state's rate and
    /// acceleration) about which the QEP was solved.
    pub state: State,
    pub spectrum: Spectrum,
    /// Axial force in the element at the guide (N).
    pub root_axial_force_n: f64,
    /// Load increments of the equilibrium solve.
    pub load_steps: usize,
}

/// Why a state's stability could not be computed.
#[derive(Debug)]
pub enum GeStateFailure {
    /// The quasi-static equilibrium did not converge.
    Equilibrium(equations::NewtonFailure),
    /// The mass matrix was singular or the eigenvalue iteration failed.
    Spectrum(QepError),
}

/// The local QEP (7.3) at a deployment state: the straight equilibrium of
/// the cable at length `kin.length_m` under the tip load, gravity and the
/// sliding terms of the rate and acceleration in `kin` (static solve in
/// the mapped frame, in `load_steps` increments), with the velocity of
/// `motion` (`AtRest`: every point moves at `L̇` along the guide;
/// `SteadyPayout`: the quasi-static payout of a stretched cable) and the
/// consistent acceleration `M q̈ = −R(q, q̇, 0)`; then the spectrum about
/// that state. This is the state the critical-time search starts from
/// ([`super::critical::initial_state`]) placed at any length.
pub fn state_stability(
    model: &GeModel,
    kin: Kinematics,
    load: TipLoad,
    motion: StateMotion,
    load_steps: usize,
    newton: equations::NewtonConfig,
) -> Result<GeStateStability, GeStateFailure> {
    let q = equations::static_solve(model, kin, load, load_steps, newton)
        .map_err(GeStateFailure::Equilibrium)?;
    let v = match motion {
        StateMotion::AtRest => vec![0.0; q.len()],
        StateMotion::SteadyPayout => super::start::steady_payout_velocity(model, kin, &q),
    };
    let zero = vec![0.0; q.len()];
    let r = equations::residual(model, kin, load, 0.0, &q, &v, &zero);
    let m = equations::system_matrices(model, kin, load, 0.0, &q, &v, &zero).mass;
    let lu = m
        .factor()
        .ok_or(GeStateFailure::Spectrum(QepError::NonFinite))?;
    let mut a: Vec<f64> = r.total.iter().map(|x| -x).collect();
    lu.solve_in_place(&mut a);
    let state = State {
        time_s: 0.0,
        q,
        v,
        a,
    };
    let spectrum =
        local_spectrum(model, kin, load, 0.0, &state).map_err(GeStateFailure::Spectrum)?;
    Ok(GeStateStability {
        root_axial_force_n: super::start::root_axial_force_n(model, kin.length_m, &state.q),
        spectrum,
        state,
        load_steps,
    })
}
