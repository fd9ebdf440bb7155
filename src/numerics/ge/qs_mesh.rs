//! The meshes of the converged calm-air search ([`super::qs_converged`]):
//! the closed form's guess of the onset and of the bending layer
//! ([`super::airy_onset`]), meshes graded toward the guide from it, and
//! their nested bisection.

use super::GeModel;
use super::airy_onset::AiryOnset;

/// The calm-air closed form's answer for a converged search
/// ([`super::airy_onset`]): where the root is expected, and the first
/// element of the graded base mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CalmGuess {
    /// The closed form's onset (m, or m/s along the rate).
    pub root: f64,
    /// The base mesh's first element on `ζ`: a quarter of the bending
    /// layer `(EI_eff/b)^(1/3)` at the closed-form onset, over `L`.
    pub first_element: f64,
}

/// First element of the graded base mesh, in layers `(EI_eff/b)^(1/3)`:
/// measured (thesis tether, 20 to 320 elements) the roots converge at
/// second order from the base mesh on for 0.25 to 1; a quarter gives the
/// smallest errors (0.57 m at 20 elements, EI = 1000 N m²).
pub const FIRST_ELEMENT_IN_LAYERS: f64 = 0.25;

/// The closed form's guess for a calm-air search at `(length, rate)` once
/// one of them is the closed form's onset; `None` without a bending layer.
fn calm_guess(airy: &AiryOnset, length_m: f64, rate_m_s: f64, root: f64) -> Option<CalmGuess> {
    let ei = airy.effective_bending_stiffness_n_m2(rate_m_s);
    let b = airy.tension_slope_n_m(length_m, rate_m_s);
    let first = FIRST_ELEMENT_IN_LAYERS * (ei / b).cbrt() / length_m;
    (first.is_finite() && first > 0.0 && root.is_finite()).then_some(CalmGuess {
        root,
        first_element: first,
    })
}

/// The closed form's guess for the critical length at `rate_m_s` (used
/// in calm air; the graded base mesh is
/// `graded_nodes(base_elements, first_element)`).
pub fn calm_length_guess(model: &GeModel, net_buoyancy_n: f64, rate_m_s: f64) -> Option<CalmGuess> {
    let airy = AiryOnset::of_model(model, net_buoyancy_n);
    let l = airy.critical_length_m(rate_m_s)?;
    calm_guess(&airy, l, rate_m_s, l)
}

/// The closed form's guess for the critical rate at `length_m`.
pub fn calm_rate_guess(model: &GeModel, net_buoyancy_n: f64, length_m: f64) -> Option<CalmGuess> {
    let airy = AiryOnset::of_model(model, net_buoyancy_n);
    let v = airy.critical_rate_m_s(length_m)?;
    calm_guess(&airy, length_m, v, v)
}

/// Nodes of `elements` elements on `ζ ∈ [0, 1]` growing geometrically
/// from `first` at the guide (uniform when `first ≥ 1/elements`).
pub fn graded_nodes(elements: usize, first: f64) -> Vec<f64> {
    let n = elements.max(1);
    if !(first > 0.0) || first * n as f64 >= 1.0 {
        return (0..=n).map(|k| k as f64 / n as f64).collect();
    }
    // first (ρⁿ − 1)/(ρ − 1) = 1: bisection on ρ ∈ (1, 1/first]
    let sum = |rho: f64| first * (rho.powi(n as i32) - 1.0) / (rho - 1.0);
    let (mut a, mut b) = (1.0 + 1e-12, 1.0 / first);
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if !(m > a && m < b) {
            break;
        }
        if sum(m) < 1.0 { a = m } else { b = m }
    }
    let rho = 0.5 * (a + b);
    let mut nodes = Vec::with_capacity(n + 1);
    let (mut z, mut h) = (0.0, first);
    nodes.push(0.0);
    for _ in 1..n {
        z += h;
        h *= rho;
        nodes.push(z);
    }
    nodes.push(1.0);
    nodes
}

/// Every element of a mesh bisected (nested: the coarse nodes kept).
pub fn bisect_nodes(nodes: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(2 * nodes.len() - 1);
    for w in nodes.windows(2) {
        out.push(w[0]);
        out.push(0.5 * (w[0] + w[1]));
    }
    out.extend(nodes.last());
    out
}
