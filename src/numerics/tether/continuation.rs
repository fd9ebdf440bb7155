//! Continued shootings: the starts of the static-equilibrium shootings
//! ([`super::equilibrium`]) along a sequence of lengths, each from the
//! answers of its neighbours. Along the plan's grid (4000 segments) a
//! cold solve takes about five RK4 passes (a coarse shooting, then the
//! fine one); a continued one about one, to the same tolerance.

use super::equilibrium::{Equilibrium, ShootingStart};

/// The starts of the shootings along a sequence of lengths
/// ([`ShootingStart`]): the aerostat's altitude extrapolated (cubic, by
/// Lagrange) from the last four converged answers, and the last secant
/// slope. (The altitude `z_top − z(winch)` is a better guess of the root
/// than the last `z_top` itself: the slope of `z(winch)` is near 1.)
/// Forgets its history at an answer that did not converge.
#[derive(Clone, Debug, Default)]
pub struct ShootingContinuation {
    /// `(L, altitude)` of the last converged answers, oldest first.
    points: Vec<(f64, f64)>,
    slope: Option<f64>,
}

/// Points of the extrapolation (cubic).
const POINTS: usize = 4;

impl ShootingContinuation {
    /// The start at length `l` (None before any answer).
    pub fn start_at(&self, l: f64) -> Option<ShootingStart> {
        if self.points.is_empty() {
            return None;
        }
        // Lagrange extrapolation through the last (up to four) points.
        let pts = &self.points;
        let z = if pts.len() == 1 {
            pts[0].1 * l / pts[0].0
        } else {
            pts.iter()
                .enumerate()
                .map(|(i, &(li, zi))| {
                    pts.iter()
                        .enumerate()
                        .filter(|&(j, _)| j != i)
                        .fold(zi, |acc, (_, &(lj, _))| acc * (l - lj) / (li - lj))
                })
                .sum()
        };
        Some(ShootingStart {
            z_top_m: z,
            slope: self.slope,
        })
    }

    /// Records the answer at length `l`; an answer that did not converge
    /// (or the equilibrium not found) clears the history.
    pub fn record(&mut self, l: f64, eq: Option<&Equilibrium>) {
        match eq {
            Some(e) if e.converged => {
                self.record_altitude(l, e.altitude_m);
                if e.shooting_slope.is_some() {
                    self.slope = e.shooting_slope;
                }
            }
            _ => *self = Self::default(),
        }
    }

    /// Records a length whose answer came from elsewhere (its altitude).
    pub fn record_altitude(&mut self, l: f64, altitude_m: f64) {
        if !altitude_m.is_finite() {
            *self = Self::default();
            return;
        }
        // a length (nearly) repeated replaces its point: nodes closer than
        // this would make the extrapolation amplify the answers' roundoff
        if let Some(last) = self.points.last_mut()
            && (last.0 - l).abs() <= 1e-6 * l.abs().max(1.0)
        {
            *last = (l, altitude_m);
            return;
        }
        if self
            .points
            .iter()
            .any(|&(lp, _)| (lp - l).abs() <= 1e-6 * l.abs().max(1.0))
        {
            self.points.clear();
        }
        if self.points.len() == POINTS {
            self.points.remove(0);
        }
        self.points.push((l, altitude_m));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::tether::equilibrium::{EquilibriumConfig, EquilibriumProblem};
    use crate::numerics::tether::wind::WindProfile;

    /// A log-law wind over the tether with drag: `z(winch)` depends on
    /// `z_top`, so the shooting iterates.
    fn sheared(length_m: f64) -> EquilibriumProblem {
        let mut p = crate::numerics::tether::equilibrium::tests::problem(0.0);
        p.cable.normal_drag_coefficient = 1.2;
        p.wind = WindProfile::LogLaw {
            reference_speed_m_s: 6.0,
            reference_height_m: 10.0,
            roughness_length_m: 0.03,
        };
        p.tether_length_m = length_m;
        p
    }

    #[test]
    fn continued_shootings_meet_the_cold_answers_in_fewer_passes() {
        let config = EquilibriumConfig {
            keep_shape: false,
            ..EquilibriumConfig::default()
        };
        let mut c = ShootingContinuation::default();
        let (mut cold_passes, mut warm_passes) = (0, 0);
        // the plan's grid: 4000 segments over 1000 m
        for k in 0..=200 {
            let l = 500.0 + 0.25 * k as f64;
            let p = sheared(l);
            let cold = p.solve(&config).unwrap();
            let warm = p.solve_from(&config, c.start_at(l)).unwrap();
            c.record(l, Some(&warm));
            assert!(cold.converged && warm.converged);
            // both meet the shooting tolerance 1e-11 L on z(winch): the
            // altitudes agree to a few times it, the tensions to roundoff
            assert!(warm.residual_m <= 1e-11 * l, "{l}: {}", warm.residual_m);
            assert!(
                (warm.altitude_m - cold.altitude_m).abs() <= 4e-11 * l,
                "{l}"
            );
            let dt = (warm.winch_tension_n - cold.winch_tension_n).abs();
            assert!(dt <= 1e-9 * cold.winch_tension_n, "{l}: {dt}");
            cold_passes += cold.iterations;
            warm_passes += warm.iterations;
        }
        // cold: a coarse and a fine shooting (about 5 passes); continued:
        // about one pass once four answers are known
        assert!(cold_passes >= 4 * 201, "{cold_passes}");
        assert!(
            warm_passes <= 201 + 40,
            "{warm_passes} against {cold_passes}"
        );
    }

    #[test]
    fn continued_shootings_follow_the_tether_onto_the_ground() {
        // F/(ρA g) = 4077 m in calm air; blown down, the tether reaches the
        // ground sooner: the lengths pass from airborne to grounded
        let config = EquilibriumConfig::default();
        let mut c = ShootingContinuation::default();
        let mut grounded = 0;
        for k in 0..=150 {
            let l = 2000.0 + 15.0 * k as f64;
            let p = sheared(l);
            let cold = p.solve(&config).unwrap();
            let warm = p.solve_from(&config, c.start_at(l)).unwrap();
            c.record(l, Some(&warm));
            assert_eq!(warm.slack, cold.slack, "{l}");
            assert_eq!(warm.converged, cold.converged, "{l}");
            assert!((warm.altitude_m - cold.altitude_m).abs() <= 1e-9 * l, "{l}");
            assert!(
                (warm.grounded_length_m - cold.grounded_length_m).abs() <= 1e-6,
                "{l}"
            );
            let dt = (warm.min_tension_n - cold.min_tension_n).abs();
            assert!(dt <= 1e-6 * cold.top_tension_n, "{l}: {dt}");
            grounded += usize::from(cold.slack);
        }
        assert!(grounded > 20 && grounded < 140, "{grounded}");
    }

    #[test]
    fn a_start_far_off_falls_back_to_the_cold_solve() {
        let config = EquilibriumConfig::default();
        let p = sheared(800.0);
        let cold = p.solve(&config).unwrap();
        for z in [1e-3, 0.5, 2000.0, 1e6] {
            let s = Some(ShootingStart {
                z_top_m: z,
                slope: Some(1.0),
            });
            let e = p.solve_from(&config, s).unwrap();
            assert!(e.converged, "{z}");
            assert!(
                (e.altitude_m - cold.altitude_m).abs() <= 4e-11 * 800.0,
                "{z}"
            );
        }
        // no start: the cold solve itself, bit for bit
        assert_eq!(p.solve_from(&config, None).unwrap(), cold);
    }
}
