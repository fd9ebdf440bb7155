//! Closed-form critical length of an extensible cable paid out at a
//! constant rate, in the string limit (`EI → 0`) and quasi-statically —
//! the analytic reference for the stiffness-ratio (`E*`) series of the GE
//! charts.
//!
//! With reel-out rate `v` (unstretched length per second), net buoyancy
//! `F` at the top, aerostat mass `m`, mass per unstretched length `μ` and
//! axial stiffness `EA`:
//!
//! * each material point keeps its tension (the tension depends only on
//!   the unstretched distance below the top), so the cable moves as a
//!   rigid body at the speed the guide feeds it out, `V = v (1 + N₀/EA)`,
//!   `N₀` the tension at the guide;
//! * `N₀` falls at `μ (g + A) v` as weight is added, so the cable
//!   decelerates: `A = dV/dt = −β (g + A)` with `β = μ v²/EA`, i.e.
//!   `g + A = g/(1 + β)`;
//! * the tension at the guide is `N₀ = F − m A − μ (g + A) L`;
//! * transverse waves travel through the material at `√(N/(μ(1 + ε)))`
//!   unstretched length per second, so the guide end loses stability when
//!   `N₀ = μ v² (1 + N₀/EA)`, i.e. `N₀ = μ v²/(1 − β)`.
//!
//! Hence
//!
//! ```text
//! L* = [ (1 + β) (F − μ v²/(1 − β)) + m g β ] / (μ g)
//! ```
//!
//! which is `(F − μ v²)/(μ g)` for an inextensible cable (`β = 0`). To
//! first order in `β`, `dL*/dβ = (F + m g − 2 μ v²)/(μ g)`: below the rate
//! `√((F + m g)/(2 μ))` (84 m/s for Table 7.1 data) a more extensible
//! cable pays out a *longer* length before it goes unstable — the
//! decelerating cable weighs less on the guide — and above it a shorter
//! one, reaching `L* ≤ 0` (unstable at once) well before the wave speed.

/// Inputs of [`critical_length_m`] (SI).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExtensibleString {
    /// Net buoyancy `F` at the top (N).
    pub net_buoyancy_n: f64,
    /// Aerostat mass `m` (kg).
    pub aerostat_mass_kg: f64,
    /// Mass per unstretched length `μ` (kg/m).
    pub mass_per_length_kg_m: f64,
    /// Axial stiffness `EA` (N); `f64::INFINITY` for an inextensible cable.
    pub axial_stiffness_n: f64,
    /// Gravity `g` (m/s²).
    pub gravity_m_s2: f64,
}

impl ExtensibleString {
    /// `β = μ v²/EA`: the reel-out rate against the axial wave speed, squared.
    pub fn beta(&self, rate_m_s: f64) -> f64 {
        self.mass_per_length_kg_m * rate_m_s * rate_m_s / self.axial_stiffness_n
    }

    /// Unstretched length paid out when the guide end loses stability
    /// (m); `None` when it is unstable from the start (`β ≥ 1` or
    /// `L* ≤ 0`).
    pub fn critical_length_m(&self, rate_m_s: f64) -> Option<f64> {
        let beta = self.beta(rate_m_s);
        if beta >= 1.0 {
            return None;
        }
        let mu_v2 = self.mass_per_length_kg_m * rate_m_s * rate_m_s;
        let g = self.gravity_m_s2;
        let numerator = (1.0 + beta) * (self.net_buoyancy_n - mu_v2 / (1.0 - beta))
            + self.aerostat_mass_kg * g * beta;
        let length = numerator / (self.mass_per_length_kg_m * g);
        (length > 0.0).then_some(length)
    }

    /// Quasi-static axial force (N) at unstretched distance `x_m` from the
    /// guide once `length_m` has been paid out at `rate_m_s`:
    /// `N(x) = F − m A − μ (g + A) (L − x)`, `A = −β g/(1 + β)`.
    pub fn tension_n(&self, rate_m_s: f64, length_m: f64, x_m: f64) -> f64 {
        let beta = self.beta(rate_m_s);
        let g = self.gravity_m_s2;
        let accel = -beta * g / (1.0 + beta);
        self.net_buoyancy_n
            - self.aerostat_mass_kg * accel
            - self.mass_per_length_kg_m * (g + accel) * (length_m - x_m)
    }

    /// How far the critical length moves per newton of extra tension at
    /// the guide (m/N): `1/|dN₀/dL| = (1 + β)/(μ g)`.
    pub fn length_per_tension_m_n(&self, rate_m_s: f64) -> f64 {
        (1.0 + self.beta(rate_m_s)) / (self.mass_per_length_kg_m * self.gravity_m_s2)
    }

    /// Rate at which extensibility stops lengthening `L*` and starts
    /// shortening it, to first order in `β` (m/s).
    pub fn crossover_rate_m_s(&self) -> f64 {
        ((self.net_buoyancy_n + self.aerostat_mass_kg * self.gravity_m_s2)
            / (2.0 * self.mass_per_length_kg_m))
            .sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table_7_1(axial_stiffness_n: f64) -> ExtensibleString {
        ExtensibleString {
            net_buoyancy_n: 1000.0,
            aerostat_mass_kg: 10.0,
            mass_per_length_kg_m: 0.078,
            axial_stiffness_n,
            gravity_m_s2: 9.81,
        }
    }

    #[test]
    fn inextensible_limit_is_the_string_closed_form() {
        let s = table_7_1(f64::INFINITY);
        for v in [5.0, 40.0, 100.0] {
            let closed = (1000.0 - 0.078 * v * v) / (0.078 * 9.81);
            assert!((s.critical_length_m(v).unwrap() / closed - 1.0).abs() < 1e-14);
        }
    }

    /// The sign of the extensibility effect flips at the crossover rate:
    /// the finite difference in `1/EA` has the sign of `F + m g − 2 μ v²`.
    #[test]
    fn extensibility_lengthens_below_and_shortens_above_the_crossover() {
        let stiff = table_7_1(1e12);
        let soft = table_7_1(1e7);
        let vx = stiff.crossover_rate_m_s();
        assert!((vx - 83.90).abs() < 0.01, "{vx}");
        for (v, longer) in [(20.0, true), (80.0, true), (88.0, false), (110.0, false)] {
            let d = soft.critical_length_m(v).unwrap() - stiff.critical_length_m(v).unwrap();
            assert_eq!(d > 0.0, longer, "v = {v}: ΔL* = {d}");
        }
        // at the axial wave speed the cable is unstable from the start
        let rubber = table_7_1(1000.0);
        assert_eq!(rubber.critical_length_m(f64::sqrt(1000.0 / 0.078)), None);
        assert_eq!(
            rubber.critical_length_m(80.0).map(|l| l.round()),
            Some(70.0)
        );
    }
}
