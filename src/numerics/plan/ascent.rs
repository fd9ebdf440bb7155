//! The aerostat's drag from its own ascent while the tether pays out.
//!
//! The static loads of [`super::air`] are those of the steady wind, with the
//! aerostat at rest. Paying out at `L̇ = v > 0`, the aerostat moves at
//! about `v` along its tether's top tangent `t`. The air it meets is
//! `u_r = U − v t` instead of `U`, where `U` is the wind at the aerostat.
//! Its drag `c_D |u_r| u_r` (`c_D = ½ρ C_D A`) and its lift
//! `c_L |u_r| R u_r` (`c_L = ½ρ |C_L| A`, `R` a quarter turn) change by
//! `ΔA`, and the tension below the aerostat drops by at most `ΔA · (−t)`.
//!
//! **Calm air** (`U = 0`): exact. The aerostat rises into still air,
//! its drag `c_D v²` pulls straight down the tether, and `T(x)` falls by
//! `c_D v²` everywhere. The criterion of SPEC §7 becomes
//! `(1 − r)F − (m + ρA L)L̈ − ρA g L − (ρA + c_D) v² ≥ ε(1 − r)F`.
//! The terminal ascent speed `√(F / c_D)` caps the rate: 16.5 m/s for
//! F = 1000 N, C_D 0.3 on 20 m².
//!
//! **Wind**: a bound. With `|u_r| ≤ U + v` and `|u_r| ≥ U − v`, the
//! drag's part is at most `c_D (v² + 2 U v)`: `c_D U v (1 + t_x) − c_D v²`
//! while `u_r · t ≥ 0`, and `c_D (v² + U v (1 − t_x))` after. The map
//! `x ↦ |x| x` changes by at most `2 max(|x|) |Δx|`, so the lift's part is
//! at most `2 c_L (U + v) v`. So the loss is
//!
//! ```text
//! δ(v) ≤ a₂ v² + a₁ v,   a₂ = c_D + 2 c_L,   a₁ = 2 U (c_D + c_L)   (N)
//! ```
//!
//! with `U` the fastest wind below the tether's length (the aerostat
//! flies no higher). With gusts, the faster of the mean and the gust.
//! The bound is exact in calm air and 0 at rest. It neglects the turn of
//! the tether's shape that the changed top force causes (second order in
//! `ΔA / T`).
//!
//! **In the pass** ([`super::schedule`]), a constraint must be linear in
//! `u = v²`. The term `a₁ v ≤ a₁ (u / v₀ + v₀) / 2` (AM–GM) is tangent at
//! `v₀`, where `v₀` is the rate ceiling at rest. The linear constraint is
//! therefore conservative at every rate and exact on the ceiling at zero
//! acceleration. Hauling in, the aerostat descends and its drag adds
//! tension, which only steadies the tether, so nothing is taken off.

/// The loss of tension bound `a₂ v² + a₁ v` while paying out (`v > 0`).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct AscentDrag {
    /// `a₂` (N s²/m²): `½ρ (C_D + 2|C_L|) A`.
    pub quadratic_n_s2_m2: f64,
    /// `a₁` (N s/m): `ρ U (C_D + |C_L|) A`.
    pub linear_n_s_m: f64,
}

impl AscentDrag {
    /// No aerodynamic data: nothing is taken off.
    pub const NONE: Self = Self {
        quadratic_n_s2_m2: 0.0,
        linear_n_s_m: 0.0,
    };

    /// The bound for an aerostat of drag and lift coefficients on
    /// `area_m2` in air of `density`, with `wind_m_s` the fastest wind it
    /// can meet.
    pub fn new(
        density_kg_m3: f64,
        drag_coefficient: f64,
        lift_coefficient: f64,
        area_m2: f64,
        wind_m_s: f64,
    ) -> Self {
        let c_d = 0.5 * density_kg_m3 * drag_coefficient.max(0.0) * area_m2;
        let c_l = 0.5 * density_kg_m3 * lift_coefficient.abs() * area_m2;
        Self {
            quadratic_n_s2_m2: c_d + 2.0 * c_l,
            linear_n_s_m: 2.0 * wind_m_s.abs() * (c_d + c_l),
        }
    }

    pub fn is_none(&self) -> bool {
        self.quadratic_n_s2_m2 == 0.0 && self.linear_n_s_m == 0.0
    }

    /// The bound on the tension lost at winch rate `rate_m_s` (N); 0
    /// hauling in or at rest.
    pub fn loss_n(&self, rate_m_s: f64) -> f64 {
        if rate_m_s > 0.0 {
            (self.quadratic_n_s2_m2 * rate_m_s + self.linear_n_s_m) * rate_m_s
        } else {
            0.0
        }
    }

    /// The largest `v ≥ 0` with `(ρA + a₂) v² + a₁ v ≤ budget_n` (m/s); 0
    /// when the budget is not positive.
    pub fn ceiling_m_s(&self, rho_a: f64, budget_n: f64) -> f64 {
        if !(budget_n > 0.0) {
            return 0.0;
        }
        let q = rho_a + self.quadratic_n_s2_m2;
        let b = self.linear_n_s_m;
        if b == 0.0 {
            return (budget_n / q).sqrt();
        }
        // the root without cancellation: 2c / (b + √(b² + 4qc))
        2.0 * budget_n / (b + (b * b + 4.0 * q * budget_n).sqrt())
    }

    /// The pass's linear form of `ρA u + δ(√u) ≤ budget_n`, tangent at the
    /// ceiling: `k ρA u ≤ budget_n − a₁ v₀ / 2`. Returns `(k, reduced
    /// budget (N))`; `k = 1` and the budget unchanged without a linear term
    /// or budget.
    pub fn linearised(&self, rho_a: f64, budget_n: f64) -> (f64, f64) {
        let v0 = self.ceiling_m_s(rho_a, budget_n);
        let q = rho_a + self.quadratic_n_s2_m2;
        if self.linear_n_s_m == 0.0 || v0 <= 0.0 {
            return (q / rho_a, budget_n);
        }
        let k = (q + 0.5 * self.linear_n_s_m / v0) / rho_a;
        (k, budget_n - 0.5 * self.linear_n_s_m * v0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn calm_air_is_the_terminal_speed() {
        // F = 1000 N, C_D 0.3 on 20 m², ρ 1.225: c_D = 3.675 N s²/m².
        let a = AscentDrag::new(1.225, 0.3, 0.0, 20.0, 0.0);
        assert_eq!(a.quadratic_n_s2_m2, 0.5 * 1.225 * 0.3 * 20.0);
        assert_eq!(a.linear_n_s_m, 0.0);
        let v = a.ceiling_m_s(0.0, 1000.0);
        assert!((v - (1000.0f64 / 3.675).sqrt()).abs() < 1e-12, "{v}");
        assert!((v - 16.496).abs() < 1e-3);
        // with the cable's ρA: (ρA + c_D) v² = budget
        let v = a.ceiling_m_s(0.078, 500.0);
        assert!((v - (500.0f64 / (0.078 + 3.675)).sqrt()).abs() < 1e-12);
        assert_eq!(a.loss_n(-3.0), 0.0);
        assert_eq!(a.loss_n(2.0), 4.0 * 3.675);
    }

    #[test]
    fn the_linear_form_is_tangent_at_the_ceiling_and_above_elsewhere() {
        let a = AscentDrag::new(1.225, 0.3, 0.1, 20.0, 6.0);
        let (rho_a, budget) = (0.078, 700.0);
        let v0 = a.ceiling_m_s(rho_a, budget);
        // on the ceiling: exactly the budget
        let exact = |v: f64| rho_a * v * v + a.loss_n(v);
        assert!((exact(v0) - budget).abs() < 1e-9 * budget);
        let (k, reduced) = a.linearised(rho_a, budget);
        let linear = |v: f64| k * rho_a * v * v + (budget - reduced);
        assert!((linear(v0) - budget).abs() < 1e-9 * budget);
        // the linear form never allows more than the exact one
        for i in 0..=200 {
            let v = 3.0 * v0 * i as f64 / 200.0;
            assert!(linear(v) >= exact(v) - 1e-9 * budget, "v {v}");
        }
    }

    #[test]
    fn the_wind_bound_holds_for_the_exact_relative_velocity() {
        // The loss of tension along the top tangent t for the exact
        // u_r = U e_x − v t, drag and lift (normal to u_r, upward side),
        // against a₂ v² + a₁ v, over blow-down angles and rates.
        let (rho, cd, cl, area) = (1.225, 0.3, 0.4, 20.0);
        let (c_d, c_l) = (0.5 * rho * cd * area, 0.5 * rho * cl * area);
        let force = |u: [f64; 2]| {
            let m = u[0].hypot(u[1]);
            // drag along u, lift a quarter turn from u (upward for u = e_x)
            [
                c_d * m * u[0] - c_l * m * u[1],
                c_d * m * u[1] + c_l * m * u[0],
            ]
        };
        for wind in [0.0, 3.0, 6.0, 15.0] {
            let a = AscentDrag::new(rho, cd, cl, area, wind);
            for deg in [0.0, 10.0, 30.0, 60.0, 85.0] {
                let th = f64::to_radians(deg);
                let t = [th.sin(), th.cos()];
                let rest = force([wind, 0.0]);
                for i in 0..=60 {
                    let v = 0.5 * i as f64;
                    let moving = force([wind - v * t[0], -v * t[1]]);
                    let loss = (rest[0] - moving[0]) * t[0] + (rest[1] - moving[1]) * t[1];
                    assert!(
                        loss <= a.loss_n(v) + 1e-9 * (1.0 + loss.abs()),
                        "U {wind}, {deg}°, v {v}: loss {loss} > bound {}",
                        a.loss_n(v)
                    );
                }
            }
        }
    }
}
