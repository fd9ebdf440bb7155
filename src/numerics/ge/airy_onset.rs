//! Closed-form quasi-static GE onset in calm air (issue 21): the string's
//! critical length lifted by the bending layer at the guide, from the
//! first zero of Airy's function.
//!
//! **Derivation.** Paying out at a constant rate `v` in calm air, the
//! quasi-static state is straight and its axial force is the weight below
//! the top, `T(x) = F − ρA g (L − x)` (`x` the unstretched distance from
//! the guide, `F` the net buoyancy). Linearised about it, the mapped-frame
//! linear stiffness of the module docs of [`super`],
//! `−(L̇²/L) ∫ (1−ζ)² W_ζ·I·U_ζ`, is a compressive transport force
//! `ρA v² (1 − x/L)²` on the lateral displacement and a loss of bending
//! stiffness `I_ρ v² (1 − x/L)²` on the rotation, so that (shear-rigid,
//! `θ = w'`) the lateral equilibrium is
//!
//! ```text
//! (EI_eff φ')' = T_eff(x) φ,   φ = w',   φ(0) = 0 (clamped at the guide),
//! T_eff(x)  = F − ρA g (L − x) − ρA v² (1 − x/L)²,
//! EI_eff(x) = EI − I_ρ v² (1 − x/L)²,
//! ```
//!
//! once integrated from the top, where no lateral force acts (the net
//! buoyancy keeps its direction), so that the shear constant is zero. At
//! the onset `T_eff(0)` is slightly negative and the mode lives in a layer
//! of thickness `ℓ = (EI/b)^(1/3)` at the guide. Over it `T_eff` is
//! linear, `T_eff(0) + b x` with `b = ρA g + 2 ρA v²/L`, and `EI_eff` is
//! its guide value `EI − I_ρ v²`; with `s = (b/EI_eff)^(1/3) x +
//! T_eff(0)/(EI_eff b²)^(1/3)` the equation is Airy's, `φ_ss = s φ`, whose
//! solution bounded towards the top (exponentially far away: `L/ℓ ≥ 100`
//! for the thesis tether) is `Ai(s)`. The clamp `φ(0) = 0` puts the guide
//! at a zero of `Ai`; the first one, `a₁ = −2.338 107 410 46`, is the
//! onset (a longer cable puts the guide at a more negative `s`, past `a₁`):
//!
//! ```text
//! F − ρA g L − ρA v² = a₁ (EI_eff b²)^(1/3),   b = ρA g + 2 ρA v²/L.
//! ```
//!
//! With `EI → 0` it is the string's `L* = (F/ρA − v²)/g`; the bending
//! lifts it by `|a₁| (EI b²)^(1/3)/(ρA g)` (25.8 m at `EI = 1000 N m²` for
//! the thesis tether, 0.26 m at 10⁻³ N m²). Since `b` depends on `L` the
//! length is a fixed point, reached in a few steps (the map contracts by
//! `~ ℓ/L`); the critical rate at a given length is the root in `v` (the
//! margin falls monotonically with `v` while `ℓ ≪ L`), by bisection.
//!
//! **Neglected** (each relative to the guide tension `|a₁|(EI b²)^(1/3)`
//! that sets the lift, and all below 10⁻³ of the lift for the thesis
//! tether):
//!
//! * shear flexibility: a Timoshenko beam-column under an axial force `T`
//!   has its bending stiffness scaled by about `1 + T/GA`; `T ≈ T_eff(0)`
//!   in the layer, so `~ |T_eff(0)|/GA` (2·10⁻⁵ at `GA = 10⁶ N`);
//! * the curvature of `T_eff` and the slope of `EI_eff` over the layer:
//!   `T_eff'' ℓ²/(b ℓ) = 2 ρA v² ℓ/(b L²)`, `~ 10⁻⁴` for the thesis tether;
//! * extensibility: the axial strain at the guide is `T(0)/EA`, `~ 10⁻⁵`,
//!   and `T(x)` and `L` are per unstretched length (exact in statics);
//! * the tip: `Ai` decays as `exp(−⅔ (L/ℓ)^(3/2))` towards it;
//! * the aerostat's mass does not enter (no acceleration: `L̈ = 0`).
//!
//! The FE criterion of [`super::qs_converged`] should meet it within its
//! own error estimate (tested in `tests/verification_ge_converged.rs`);
//! the converged search also uses it as its first guess in calm air.

use super::GeModel;

/// First zero of Airy's `Ai` (DLMF 9.9.1, Table 9.9.1).
pub const AIRY_AI_FIRST_ZERO: f64 = -2.338_107_410_459_767;

/// The calm-air quasi-static problem of the closed form (SI).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AiryOnset {
    /// Net buoyancy `F` at the top (N).
    pub net_buoyancy_n: f64,
    /// Mass per unstretched length `ρA` (kg/m).
    pub mass_per_length_kg_m: f64,
    /// Gravity `g` (m/s²).
    pub gravity_m_s2: f64,
    /// Bending stiffness `EI` (N m²).
    pub bending_stiffness_n_m2: f64,
    /// Rotary inertia per unit length `I_ρ` (kg m).
    pub rotary_inertia_kg_m: f64,
}

impl AiryOnset {
    /// The closed form of a GE model's section and gravity under `F`.
    pub fn of_model(model: &GeModel, net_buoyancy_n: f64) -> Self {
        let s = &model.section;
        Self {
            net_buoyancy_n,
            mass_per_length_kg_m: s.mass_per_length_kg_m,
            gravity_m_s2: model.gravity_m_s2,
            bending_stiffness_n_m2: s.bending_stiffness_n_m2,
            rotary_inertia_kg_m: s.rotary_inertia_kg_m,
        }
    }

    /// `EI_eff` at the guide, `EI − I_ρ v²` (N m²).
    pub fn effective_bending_stiffness_n_m2(&self, rate_m_s: f64) -> f64 {
        self.bending_stiffness_n_m2 - self.rotary_inertia_kg_m * rate_m_s * rate_m_s
    }

    /// Slope `b = ρA g + 2 ρA v²/L` of the effective tension at the guide (N/m).
    pub fn tension_slope_n_m(&self, length_m: f64, rate_m_s: f64) -> f64 {
        let ra = self.mass_per_length_kg_m;
        ra * self.gravity_m_s2 + 2.0 * ra * rate_m_s * rate_m_s / length_m
    }

    /// The compression the bending layer carries at the onset,
    /// `|a₁| (EI_eff b²)^(1/3)` (N); `None` when `EI_eff ≤ 0` (the
    /// rotation's transport outruns the bending stiffness: no layer).
    pub fn layer_compression_n(&self, length_m: f64, rate_m_s: f64) -> Option<f64> {
        let ei = self.effective_bending_stiffness_n_m2(rate_m_s);
        if !(ei > 0.0) {
            return None;
        }
        let b = self.tension_slope_n_m(length_m, rate_m_s);
        Some(-AIRY_AI_FIRST_ZERO * (ei * b * b).cbrt())
    }

    /// Stability margin at `(L, v)` (N): `T_eff(0) + |a₁| (EI_eff b²)^(1/3)`,
    /// positive while stable, zero at the onset.
    pub fn margin_n(&self, length_m: f64, rate_m_s: f64) -> Option<f64> {
        let ra = self.mass_per_length_kg_m;
        let t0 = self.net_buoyancy_n - ra * self.gravity_m_s2 * length_m - ra * rate_m_s * rate_m_s;
        self.layer_compression_n(length_m, rate_m_s).map(|c| t0 + c)
    }

    /// The string's critical length `(F/ρA − v²)/g` (m).
    pub fn string_length_m(&self, rate_m_s: f64) -> f64 {
        (self.net_buoyancy_n / self.mass_per_length_kg_m - rate_m_s * rate_m_s) / self.gravity_m_s2
    }

    /// The critical length at a payout rate `v` (m): the fixed point of
    /// `L = (F − ρA v² + |a₁| (EI_eff b(L)²)^(1/3))/(ρA g)` from the
    /// string's length; `None` when there is no positive one (unstable
    /// from the start) or `EI_eff ≤ 0`.
    pub fn critical_length_m(&self, rate_m_s: f64) -> Option<f64> {
        let ra_g = self.mass_per_length_kg_m * self.gravity_m_s2;
        let string = self.string_length_m(rate_m_s);
        let mut l = string.max(1e-9 * self.net_buoyancy_n / ra_g);
        for _ in 0..100 {
            let next = string + self.layer_compression_n(l, rate_m_s)? / ra_g;
            if !(next > 0.0) {
                return None;
            }
            let done = (next - l).abs() <= 1e-14 * next;
            l = next;
            if done {
                break;
            }
        }
        Some(l)
    }

    /// The critical payout rate at a length (m/s): the root of
    /// [`Self::margin_n`] in `v` on `(0, v_max]`, `v_max` where the margin
    /// or `EI_eff` runs out (bisection to roundoff). `None` when the
    /// cable is unstable at rest at this length.
    pub fn critical_rate_m_s(&self, length_m: f64) -> Option<f64> {
        if !(self.margin_n(length_m, 0.0)? > 0.0) {
            return None;
        }
        let stable = |v: f64| self.margin_n(length_m, v).is_some_and(|m| m > 0.0);
        let (mut a, mut b) = (
            0.0,
            (self.net_buoyancy_n / self.mass_per_length_kg_m).sqrt(),
        );
        while stable(b) {
            a = b;
            b *= 2.0;
            if !b.is_finite() {
                return None;
            }
        }
        for _ in 0..200 {
            let m = 0.5 * (a + b);
            if !(m > a && m < b) {
                break;
            }
            if stable(m) {
                a = m;
            } else {
                b = m;
            }
        }
        Some(0.5 * (a + b))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Thesis tether (Table 7.1): ρA = 0.078 kg/m, F = 1000 N, the 5 mm
    /// solid section's I_ρ = ρA d²/16.
    fn thesis(ei: f64) -> AiryOnset {
        AiryOnset {
            net_buoyancy_n: 1000.0,
            mass_per_length_kg_m: 0.078,
            gravity_m_s2: 9.81,
            bending_stiffness_n_m2: ei,
            rotary_inertia_kg_m: 0.078 * 0.005 * 0.005 / 16.0,
        }
    }

    /// Hand check at EI = 1000 N m², 10 m/s: b = 0.765 18 + 2·7.8/1322.5
    /// = 0.776 98 N/m, (EI b²)^(1/3) = 8.450 N, lift 2.3381·8.450/0.765 18
    /// = 25.82 m above the string's 1296.69 m: 1322.5 m (the previous
    /// session's 1280-element reference: 1322.48 m).
    #[test]
    fn thesis_tether_by_hand() {
        let a = thesis(1000.0);
        let string = a.string_length_m(10.0);
        assert!((string - 1296.688).abs() < 1e-3, "{string}");
        let l = a.critical_length_m(10.0).unwrap();
        let b = 0.078 * 9.81 + 2.0 * 0.078 * 100.0 / l;
        let ei = 1000.0 - a.rotary_inertia_kg_m * 100.0;
        let by_hand = string + 2.338_107_410_46 * (ei * b * b).cbrt() / (0.078 * 9.81);
        assert!((l - by_hand).abs() < 1e-9, "{l} vs {by_hand}");
        assert!((l - 1322.5).abs() < 0.05, "{l}");
        assert!(a.margin_n(l, 10.0).unwrap().abs() < 1e-9);
    }

    /// The lift scales as EI^(1/3) and vanishes with EI: the string.
    #[test]
    fn flexible_limit_is_the_string() {
        let lift = |ei: f64, v: f64| {
            let a = thesis(ei);
            a.critical_length_m(v).unwrap() - a.string_length_m(v)
        };
        // b = ρA g + 2ρA v²/L changes by 1.6e-4 between them (L by 14 m):
        // the ratio is 10^(1/3) to (2/3)·1.6e-4·2.15 = 2.3e-4
        let r = lift(1e3, 10.0) / lift(1e2, 10.0);
        assert!((r - 10f64.cbrt()).abs() < 4e-4, "{r}");
        // at rest (EI_eff = EI): |a₁| (10⁻¹² · 0.765²)^(1/3)/0.765 = 2.6e-4 m
        let tiny = lift(1e-12, 0.0);
        assert!(tiny > 2.5e-4 && tiny < 2.7e-4, "{tiny}");
    }

    /// Length and rate are inverse: L*(v*(L)) = L.
    #[test]
    fn critical_rate_inverts_the_critical_length() {
        for ei in [1e-3, 1.0, 1e3] {
            let a = thesis(ei);
            for v in [1.0, 10.0, 30.0] {
                let l = a.critical_length_m(v).unwrap();
                let back = a.critical_rate_m_s(l).unwrap();
                assert!((back - v).abs() < 1e-9 * v, "EI {ei}, v {v}: {back}");
            }
        }
        // unstable at rest past the static bound: no rate
        let a = thesis(1.0);
        assert_eq!(
            a.critical_rate_m_s(1.1 * a.critical_length_m(0.0).unwrap()),
            None
        );
    }

    /// EI_eff ≤ 0 (rotation transport faster than √(EI/I_ρ)): no closed form.
    #[test]
    fn no_layer_without_effective_bending_stiffness() {
        let a = thesis(1e-9);
        let v = (1e-9 / a.rotary_inertia_kg_m).sqrt() * 1.01;
        assert_eq!(a.critical_length_m(v), None);
    }
}
