//! Local stability (thesis ch. 7.2): about a converged state, the
//! linearised equations `M ΔÜ + C ΔU̇ + K ΔU = 0` (7.2) give the QEP
//! `λ² M + λ C + K = 0` (7.3), with `K` the tangent stiffness (material,
//! geometric, sliding and aerostat parts). Solved through the companion
//! matrix `[[0, I], [−M⁻¹K, −M⁻¹C]]` (band LU of `M`, then faer's dense
//! eigenvalues in sequential mode). Eigenvalues are in 1/s.

use faer::Mat;

use super::GeModel;
use super::element::TipLoad;
use super::solver::{self, Drive, State, SystemMatrices};
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
    let sys = solver::system_matrices(model, kin, load, mu, &state.q, &state.v, &state.a);
    spectrum_of(model, sys)
}

/// The QEP spectrum about a state of a run under `drive` (its loads at the
/// state's time, air load included).
pub fn drive_spectrum(model: &GeModel, drive: &Drive, state: &State) -> Result<Spectrum, QepError> {
    spectrum_of(model, solver::drive_matrices(model, drive, state))
}

fn spectrum_of(model: &GeModel, sys: SystemMatrices) -> Result<Spectrum, QepError> {
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
