//! Deployment profiles `L(t)` (SI): the winch schedule that drives the
//! time-varying length. Each profile gives the kinematics at any `t ≥ 0`
//! and the time it stops (reaches its target length), if it does.
//!
//! Lengthening has `L̇ > 0`, shortening (retrieval) `L̇ < 0`. Besides the
//! closed-form constant-rate and constant-acceleration profiles there are
//! two piecewise ones (SPEC §2, thesis ch. 4.4, Figs 4.8–4.9): a
//! trapezoidal rate (ramp up, cruise, ramp down, stopping exactly at the
//! target length) and a table of `(t, L̇)` interpolated linearly. Both are
//! piecewise constant-acceleration schedules ([`RateSchedule`]).

use crate::numerics::params::{InvalidInput, Kinematics, require_finite, require_positive};

/// Largest rate magnitude accepted anywhere (m/s).
pub const MAX_RATE_M_S: f64 = 1e5;
/// Largest number of points of a rate table.
pub const MAX_TABLE_POINTS: usize = 10_000;

/// A deployment (lengthening, `rate > 0`) or retrieval (`rate < 0`) schedule.
#[derive(Clone, Debug, PartialEq)]
pub enum Profile {
    /// `L = L0 + v t`, stopping at `target_length_m` if given.
    ConstantRate {
        initial_length_m: f64,
        rate_m_s: f64,
        target_length_m: Option<f64>,
    },
    /// From rest: `L = L0 + a t²/2`, stopping at `target_length_m` if given.
    ConstantAcceleration {
        initial_length_m: f64,
        acceleration_m_s2: f64,
        target_length_m: Option<f64>,
    },
    /// Rate ramps linearly from 0 to `cruise_rate_m_s` over `ramp_up_s`,
    /// holds, and ramps back to 0 over `ramp_down_s`, arriving at rest
    /// exactly at `target_length_m`. Zero ramp times give a sharp
    /// (instantaneous) start or stop.
    Trapezoidal {
        schedule: RateSchedule,
        cruise_rate_m_s: f64,
        ramp_up_s: f64,
        ramp_down_s: f64,
        target_length_m: f64,
    },
    /// Rate interpolated linearly in a table of `(t, L̇)` (held at the last
    /// value after the table), stopping at `target_length_m` if given.
    PiecewiseLinearRate {
        schedule: RateSchedule,
        target_length_m: Option<f64>,
        /// When it stops (s), found once when it is built (a search
        /// through the table).
        stop_s: Option<f64>,
    },
}

/// A piecewise-linear rate `L̇(t)` through knots `(t_k, L̇_k)`, `t_0 = 0`,
/// with the lengths at the knots precomputed; the rate is held at its last
/// value after the last knot.
#[derive(Clone, Debug, PartialEq)]
pub struct RateSchedule {
    pub initial_length_m: f64,
    times_s: Vec<f64>,
    rates_m_s: Vec<f64>,
    lengths_m: Vec<f64>,
}

impl RateSchedule {
    /// Builds and validates a schedule; `field` names the table in errors.
    pub fn new(
        initial_length_m: f64,
        points: &[(f64, f64)],
        field: &str,
    ) -> Result<Self, InvalidInput> {
        require_positive("initial_length_m", initial_length_m)?;
        if points.is_empty() || points.len() > MAX_TABLE_POINTS {
            return Err(InvalidInput::new(
                field,
                format!(
                    "must have between 1 and {MAX_TABLE_POINTS} points, got {}",
                    points.len()
                ),
            ));
        }
        for (i, &(t, v)) in points.iter().enumerate() {
            require_finite(&format!("{field}[{i}].time_s"), t)?;
            require_finite(&format!("{field}[{i}].rate_m_s"), v)?;
            if v.abs() > MAX_RATE_M_S {
                return Err(InvalidInput::new(
                    format!("{field}[{i}].rate_m_s"),
                    format!("must lie within ±{MAX_RATE_M_S} m/s"),
                ));
            }
            if i == 0 && t != 0.0 {
                return Err(InvalidInput::new(
                    format!("{field}[0].time_s"),
                    format!("the table must start at t = 0, got {t}"),
                ));
            }
            if i > 0 && t <= points[i - 1].0 {
                return Err(InvalidInput::new(
                    format!("{field}[{i}].time_s"),
                    format!(
                        "times must increase strictly, got {t} after {}",
                        points[i - 1].0
                    ),
                ));
            }
        }
        let times_s: Vec<f64> = points.iter().map(|p| p.0).collect();
        let rates_m_s: Vec<f64> = points.iter().map(|p| p.1).collect();
        let mut lengths_m = vec![initial_length_m; points.len()];
        for k in 1..points.len() {
            let dt = times_s[k] - times_s[k - 1];
            lengths_m[k] = lengths_m[k - 1] + 0.5 * (rates_m_s[k] + rates_m_s[k - 1]) * dt;
        }
        Ok(Self {
            initial_length_m,
            times_s,
            rates_m_s,
            lengths_m,
        })
    }

    fn segments(&self) -> usize {
        self.times_s.len()
    }

    /// The knot times `t_k` (s), where the acceleration may jump.
    pub fn knot_times_s(&self) -> &[f64] {
        &self.times_s
    }

    /// Knot index `k` with `t_k ≤ t < t_{k+1}` (the last knot for `t` beyond).
    fn segment(&self, t_s: f64) -> usize {
        self.times_s
            .partition_point(|&tk| tk <= t_s)
            .saturating_sub(1)
    }

    /// Slope of the rate on segment `k` (0 after the last knot).
    fn acceleration(&self, k: usize) -> f64 {
        if k + 1 < self.segments() {
            (self.rates_m_s[k + 1] - self.rates_m_s[k]) / (self.times_s[k + 1] - self.times_s[k])
        } else {
            0.0
        }
    }

    /// Unclamped kinematics of the schedule at `t_s ≥ 0`.
    pub fn kinematics(&self, t_s: f64) -> Kinematics {
        let t_s = t_s.max(0.0);
        let k = self.segment(t_s);
        let a = self.acceleration(k);
        let tau = t_s - self.times_s[k];
        Kinematics {
            length_m: self.lengths_m[k] + self.rates_m_s[k] * tau + 0.5 * a * tau * tau,
            rate_m_s: self.rates_m_s[k] + a * tau,
            acceleration_m_s2: a,
        }
    }

    /// First time `t ≥ 0` at which the length crosses `length_m` moving in
    /// `direction` (`+1` upwards, `−1` downwards), if it ever does.
    pub fn first_crossing(&self, length_m: f64, direction: f64) -> Option<f64> {
        let n = self.segments();
        for k in 0..n {
            let (t0, l0, v0) = (self.times_s[k], self.lengths_m[k], self.rates_m_s[k]);
            let a = self.acceleration(k);
            let t_end = if k + 1 < n {
                self.times_s[k + 1] - t0
            } else {
                f64::INFINITY
            };
            // Solve l0 + v0 τ + a τ²/2 = length in [0, t_end], with the
            // length moving in `direction` there.
            let d = length_m - l0;
            let roots = quadratic_roots(0.5 * a, v0, -d);
            let mut best: Option<f64> = None;
            for tau in roots.into_iter().flatten() {
                if tau >= 0.0 && tau <= t_end {
                    let rate = v0 + a * tau;
                    if rate * direction >= 0.0 && best.is_none_or(|b| tau < b) {
                        best = Some(tau);
                    }
                }
            }
            if let Some(tau) = best {
                return Some(t0 + tau);
            }
        }
        None
    }

    /// Smallest length reached on `[0, until_s]`.
    pub fn min_length_until(&self, until_s: f64) -> f64 {
        let mut min = self.kinematics(until_s).length_m.min(self.initial_length_m);
        for k in 0..self.segments() {
            if self.times_s[k] > until_s {
                break;
            }
            min = min.min(self.lengths_m[k]);
            let a = self.acceleration(k);
            if a != 0.0 {
                let tau = -self.rates_m_s[k] / a; // rate zero: extremum
                let t = self.times_s[k] + tau;
                if tau > 0.0
                    && t <= until_s
                    && (k + 1 == self.segments() || t < self.times_s[k + 1])
                {
                    min = min.min(self.kinematics(t).length_m);
                }
            }
        }
        min
    }

    /// Time after which the length no longer changes (last rate zero).
    fn rest_time_s(&self) -> Option<f64> {
        let last = self.segments() - 1;
        if self.rates_m_s[last] != 0.0 {
            return None;
        }
        // Earliest knot from which the rate stays zero.
        let mut k = last;
        while k > 0 && self.rates_m_s[k - 1] == 0.0 {
            k -= 1;
        }
        Some(self.times_s[k])
    }

    /// Shortest knot interval over which the rate changes (s).
    fn shortest_ramp_s(&self) -> Option<f64> {
        (0..self.segments().saturating_sub(1))
            .filter(|&k| self.rates_m_s[k + 1] != self.rates_m_s[k])
            .map(|k| self.times_s[k + 1] - self.times_s[k])
            .reduce(f64::min)
    }

    /// Rate held after the table.
    fn final_rate(&self) -> f64 {
        self.rates_m_s[self.segments() - 1]
    }
}

/// Real roots of `a x² + b x + c = 0` (a linear equation when `a = 0`).
fn quadratic_roots(a: f64, b: f64, c: f64) -> [Option<f64>; 2] {
    if a == 0.0 {
        return [(b != 0.0).then(|| -c / b), None];
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return [None, None];
    }
    let q = -0.5 * (b + b.signum() * disc.sqrt());
    if q == 0.0 {
        return [Some(0.0), None];
    }
    [Some(q / a), Some(c / q)]
}

impl Profile {
    pub fn constant_rate(
        initial_length_m: f64,
        rate_m_s: f64,
        target_length_m: Option<f64>,
    ) -> Result<Self, InvalidInput> {
        require_finite("profile.rate_m_s", rate_m_s)?;
        if rate_m_s.abs() > MAX_RATE_M_S {
            return Err(InvalidInput::new(
                "profile.rate_m_s",
                "must lie within ±1e5 m/s",
            ));
        }
        check_target(initial_length_m, rate_m_s, target_length_m)?;
        Ok(Self::ConstantRate {
            initial_length_m,
            rate_m_s,
            target_length_m,
        })
    }

    pub fn constant_acceleration(
        initial_length_m: f64,
        acceleration_m_s2: f64,
        target_length_m: Option<f64>,
    ) -> Result<Self, InvalidInput> {
        require_finite("profile.acceleration_m_s2", acceleration_m_s2)?;
        if acceleration_m_s2 == 0.0 || acceleration_m_s2.abs() > 1e4 {
            return Err(InvalidInput::new(
                "profile.acceleration_m_s2",
                "must be nonzero and within ±1e4 m/s²",
            ));
        }
        check_target(initial_length_m, acceleration_m_s2, target_length_m)?;
        Ok(Self::ConstantAcceleration {
            initial_length_m,
            acceleration_m_s2,
            target_length_m,
        })
    }

    /// Trapezoidal rate: ramp up to `cruise_rate_m_s` over `ramp_up_s`,
    /// cruise, ramp down over `ramp_down_s`, at rest at `target_length_m`.
    /// A negative cruise rate shortens (target below the initial length).
    pub fn trapezoidal(
        initial_length_m: f64,
        cruise_rate_m_s: f64,
        ramp_up_s: f64,
        ramp_down_s: f64,
        target_length_m: f64,
    ) -> Result<Self, InvalidInput> {
        require_finite("profile.cruise_rate_m_s", cruise_rate_m_s)?;
        if cruise_rate_m_s == 0.0 || cruise_rate_m_s.abs() > MAX_RATE_M_S {
            return Err(InvalidInput::new(
                "profile.cruise_rate_m_s",
                format!("must be nonzero and within ±{MAX_RATE_M_S} m/s"),
            ));
        }
        // A ramp of zero length would be an acceleration impulse that a
        // time-stepped run cannot see; sharp ramps are short, not absent.
        require_positive("profile.ramp_up_s", ramp_up_s)?;
        require_positive("profile.ramp_down_s", ramp_down_s)?;
        check_target(initial_length_m, cruise_rate_m_s, Some(target_length_m))?;
        let travel = (target_length_m - initial_length_m) / cruise_rate_m_s; // > 0
        let cruise_s = travel - 0.5 * (ramp_up_s + ramp_down_s);
        if cruise_s < 0.0 {
            return Err(InvalidInput::new(
                "profile.target_length_m",
                format!(
                    "{target_length_m} m is too close to {initial_length_m} m for ramps of {ramp_up_s} s and \
                     {ramp_down_s} s at {cruise_rate_m_s} m/s (the ramps alone cover {:.3} m)",
                    0.5 * (ramp_up_s + ramp_down_s) * cruise_rate_m_s.abs()
                ),
            ));
        }
        let v = cruise_rate_m_s;
        let mut points = vec![(0.0, 0.0), (ramp_up_s, v)];
        let t_cruise_end = ramp_up_s + cruise_s;
        if t_cruise_end > ramp_up_s {
            points.push((t_cruise_end, v));
        }
        points.push((t_cruise_end + ramp_down_s, 0.0));
        let schedule = RateSchedule::new(initial_length_m, &points, "profile")?;
        Ok(Self::Trapezoidal {
            schedule,
            cruise_rate_m_s,
            ramp_up_s,
            ramp_down_s,
            target_length_m,
        })
    }

    /// Piecewise-linear rate table `(t_s, rate_m_s)`, first time 0.
    pub fn piecewise_linear_rate(
        initial_length_m: f64,
        points: &[(f64, f64)],
        target_length_m: Option<f64>,
    ) -> Result<Self, InvalidInput> {
        let schedule = RateSchedule::new(initial_length_m, points, "profile.points")?;
        if let Some(target) = target_length_m {
            require_positive("profile.target_length_m", target)?;
            let dir = (target - initial_length_m).signum();
            if dir == 0.0 || schedule.first_crossing(target, dir).is_none() {
                return Err(InvalidInput::new(
                    "profile.target_length_m",
                    format!(
                        "the rate table never brings the length from {initial_length_m} m to {target} m"
                    ),
                ));
            }
        }
        let reach = match target_length_m {
            Some(target) => {
                schedule.first_crossing(target, (target - schedule.initial_length_m).signum())
            }
            None => schedule.first_crossing(0.0, -1.0),
        };
        let stop_s = match (reach, schedule.rest_time_s()) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        };
        let profile = Self::PiecewiseLinearRate {
            schedule,
            target_length_m,
            stop_s,
        };
        let horizon = profile
            .stop_time_s()
            .unwrap_or(*points.last().map(|(t, _)| t).unwrap_or(&0.0));
        if let Self::PiecewiseLinearRate { schedule, .. } = &profile {
            let min = schedule.min_length_until(horizon);
            let stops_at_zero = target_length_m.is_none() && schedule.final_rate() < 0.0;
            if min <= 0.0
                && !(stops_at_zero && schedule.first_crossing(0.0, -1.0) == profile.stop_time_s())
            {
                return Err(InvalidInput::new(
                    "profile.points",
                    format!(
                        "the table shortens the cable to {min:.3} m; the length must stay positive"
                    ),
                ));
            }
        }
        Ok(profile)
    }

    pub fn initial_length_m(&self) -> f64 {
        match self {
            Self::ConstantRate {
                initial_length_m, ..
            }
            | Self::ConstantAcceleration {
                initial_length_m, ..
            } => *initial_length_m,
            Self::Trapezoidal { schedule, .. } | Self::PiecewiseLinearRate { schedule, .. } => {
                schedule.initial_length_m
            }
        }
    }

    /// Length, rate and acceleration at time `t_s`.
    pub fn kinematics(&self, t_s: f64) -> Kinematics {
        let stop = self.stop_time_s();
        let t = t_s.min(stop.unwrap_or(f64::INFINITY));
        let stopped = stop.is_some_and(|stop| t_s >= stop);
        let moving = |k: Kinematics| {
            if stopped {
                Kinematics {
                    rate_m_s: 0.0,
                    acceleration_m_s2: 0.0,
                    ..k
                }
            } else {
                k
            }
        };
        match self {
            &Self::ConstantRate {
                initial_length_m,
                rate_m_s,
                ..
            } => moving(Kinematics {
                length_m: initial_length_m + rate_m_s * t,
                rate_m_s,
                acceleration_m_s2: 0.0,
            }),
            &Self::ConstantAcceleration {
                initial_length_m,
                acceleration_m_s2: a,
                ..
            } => moving(Kinematics {
                length_m: initial_length_m + 0.5 * a * t * t,
                rate_m_s: a * t,
                acceleration_m_s2: a,
            }),
            Self::Trapezoidal {
                schedule,
                target_length_m,
                ..
            } => {
                let k = moving(schedule.kinematics(t));
                // Land exactly on the target despite roundoff in the knots.
                if stopped {
                    Kinematics {
                        length_m: *target_length_m,
                        ..k
                    }
                } else {
                    k
                }
            }
            Self::PiecewiseLinearRate {
                schedule,
                target_length_m,
                ..
            } => {
                let k = moving(schedule.kinematics(t));
                match target_length_m {
                    Some(target) if stopped => Kinematics {
                        length_m: *target,
                        ..k
                    },
                    _ => k,
                }
            }
        }
    }

    /// Time at which the length reaches the target, or reaches zero when
    /// retrieving without a target, or stops changing (a rate table ending
    /// at rest).
    pub fn stop_time_s(&self) -> Option<f64> {
        match *self {
            Self::ConstantRate {
                initial_length_m,
                rate_m_s,
                target_length_m,
            } => {
                let end = target_length_m.or((rate_m_s < 0.0).then_some(0.0))?;
                if rate_m_s == 0.0 {
                    None
                } else {
                    Some((end - initial_length_m) / rate_m_s)
                }
            }
            Self::ConstantAcceleration {
                initial_length_m,
                acceleration_m_s2,
                target_length_m,
            } => {
                let end = target_length_m.or((acceleration_m_s2 < 0.0).then_some(0.0))?;
                Some((2.0 * (end - initial_length_m) / acceleration_m_s2).sqrt())
            }
            Self::Trapezoidal {
                ref schedule,
                cruise_rate_m_s,
                ramp_up_s,
                ramp_down_s,
                target_length_m,
            } => Some(
                (target_length_m - schedule.initial_length_m) / cruise_rate_m_s
                    + 0.5 * (ramp_up_s + ramp_down_s),
            ),
            Self::PiecewiseLinearRate { stop_s, .. } => stop_s,
        }
    }

    /// Shortest phase of changing rate (s), which a time step must resolve:
    /// the ramps of a trapezoid, the sloped intervals of a rate table.
    pub fn shortest_ramp_s(&self) -> Option<f64> {
        match self {
            Self::ConstantRate { .. } | Self::ConstantAcceleration { .. } => None,
            Self::Trapezoidal {
                ramp_up_s,
                ramp_down_s,
                ..
            } => Some(ramp_up_s.min(*ramp_down_s)),
            Self::PiecewiseLinearRate { schedule, .. } => schedule.shortest_ramp_s(),
        }
    }

    /// Time at which the length reaches `length_m` (lengthening profiles),
    /// or `None` if it never does.
    pub fn time_to_length_s(&self, length_m: f64) -> Option<f64> {
        let t = match self {
            &Self::ConstantRate {
                initial_length_m,
                rate_m_s,
                ..
            } => {
                if rate_m_s <= 0.0 {
                    return None;
                }
                (length_m - initial_length_m) / rate_m_s
            }
            &Self::ConstantAcceleration {
                initial_length_m,
                acceleration_m_s2,
                ..
            } => {
                if acceleration_m_s2 <= 0.0 {
                    return None;
                }
                (2.0 * (length_m - initial_length_m) / acceleration_m_s2).sqrt()
            }
            Self::Trapezoidal { schedule, .. } | Self::PiecewiseLinearRate { schedule, .. } => {
                if length_m <= schedule.initial_length_m {
                    0.0
                } else {
                    schedule.first_crossing(length_m, 1.0)?
                }
            }
        };
        match self.stop_time_s() {
            Some(stop) if t > stop => None,
            _ => Some(t.max(0.0)),
        }
    }
}

fn check_target(
    initial_length_m: f64,
    direction: f64,
    target_length_m: Option<f64>,
) -> Result<(), InvalidInput> {
    let Some(target) = target_length_m else {
        return Ok(());
    };
    require_positive("profile.target_length_m", target)?;
    if (target - initial_length_m) * direction <= 0.0 {
        return Err(InvalidInput::new(
            "profile.target_length_m",
            format!(
                "{target} m cannot be reached from {initial_length_m} m in the profile's direction"
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_acceleration_kinematics_and_stop() {
        let p = Profile::constant_acceleration(1.0, 2.0, Some(101.0)).unwrap();
        assert_eq!(p.stop_time_s(), Some(10.0));
        let k = p.kinematics(5.0);
        assert_eq!(
            (k.length_m, k.rate_m_s, k.acceleration_m_s2),
            (26.0, 10.0, 2.0)
        );
        let k = p.kinematics(12.0);
        assert_eq!(
            (k.length_m, k.rate_m_s, k.acceleration_m_s2),
            (101.0, 0.0, 0.0)
        );
        assert_eq!(p.time_to_length_s(51.0), Some((50.0f64).sqrt()));
    }

    #[test]
    fn retrieval_stops_at_zero_length() {
        let p = Profile::constant_rate(100.0, -2.0, None).unwrap();
        assert_eq!(p.stop_time_s(), Some(50.0));
        assert!(Profile::constant_rate(100.0, -2.0, Some(150.0)).is_err());
    }

    #[test]
    fn trapezoid_ramps_cruises_and_stops_at_the_target() {
        // 0 → 10 m/s over 5 s, cruise, 10 → 0 over 5 s, 1 → 2001 m
        let p = Profile::trapezoidal(1.0, 10.0, 5.0, 5.0, 2001.0).unwrap();
        assert_eq!(p.stop_time_s(), Some(205.0));
        let k = p.kinematics(2.0);
        assert!(
            (k.length_m - (1.0 + 0.5 * 2.0 * 4.0)).abs() < 1e-12
                && (k.rate_m_s - 4.0).abs() < 1e-12
        );
        assert_eq!(k.acceleration_m_s2, 2.0);
        let k = p.kinematics(100.0);
        assert!(
            (k.length_m - (1.0 + 25.0 + 950.0)).abs() < 1e-9
                && k.rate_m_s == 10.0
                && k.acceleration_m_s2 == 0.0
        );
        let k = p.kinematics(203.0); // 2 s before the stop
        assert!((k.rate_m_s - 4.0).abs() < 1e-12 && k.acceleration_m_s2 == -2.0);
        assert!((k.length_m - (2001.0 - 0.5 * 2.0 * 4.0)).abs() < 1e-9);
        let k = p.kinematics(300.0);
        assert_eq!(
            (k.length_m, k.rate_m_s, k.acceleration_m_s2),
            (2001.0, 0.0, 0.0)
        );
        assert!((p.time_to_length_s(976.0).unwrap() - 100.0).abs() < 1e-9);
        assert_eq!(p.time_to_length_s(3000.0), None);
        assert_eq!(p.shortest_ramp_s(), Some(5.0));
        // too short for its ramps, zero ramps, shortening
        assert_eq!(
            Profile::trapezoidal(1.0, 10.0, 5.0, 5.0, 20.0)
                .unwrap_err()
                .field,
            "profile.target_length_m"
        );
        assert_eq!(
            Profile::trapezoidal(1.0, 10.0, 0.0, 5.0, 200.0)
                .unwrap_err()
                .field,
            "profile.ramp_up_s"
        );
        let s = Profile::trapezoidal(100.0, -2.0, 1.0, 1.0, 50.0).unwrap();
        assert_eq!(s.stop_time_s(), Some(26.0));
        assert_eq!(s.kinematics(30.0).length_m, 50.0);
        assert!(s.kinematics(10.0).rate_m_s == -2.0);
    }

    #[test]
    fn rate_table_interpolates_and_stops() {
        let pts = [(0.0, 0.0), (10.0, 4.0), (20.0, 4.0), (30.0, -2.0)];
        let p = Profile::piecewise_linear_rate(5.0, &pts, None).unwrap();
        let k = p.kinematics(5.0);
        assert!(
            (k.rate_m_s - 2.0).abs() < 1e-12
                && (k.length_m - 10.0).abs() < 1e-12
                && k.acceleration_m_s2 == 0.4
        );
        // after the table the rate is held: −2 m/s until the length reaches zero
        let l30 = 5.0 + 20.0 + 40.0 + 10.0; // areas: 20, 40, (4 − 2)/2·10 = 10
        assert!((p.kinematics(30.0).length_m - l30).abs() < 1e-9);
        assert!((p.stop_time_s().unwrap() - (30.0 + l30 / 2.0)).abs() < 1e-9);
        // with a target it stops there
        let p = Profile::piecewise_linear_rate(5.0, &pts, Some(50.0)).unwrap();
        let t = p.stop_time_s().unwrap();
        assert!(
            (p.kinematics(t).length_m - 50.0).abs() < 1e-9 && p.kinematics(t + 1.0).rate_m_s == 0.0
        );
        assert_eq!(p.time_to_length_s(10.0), Some(5.0));
        // a table ending at rest stops there
        let p = Profile::piecewise_linear_rate(5.0, &[(0.0, 1.0), (4.0, 0.0)], None).unwrap();
        assert_eq!(p.stop_time_s(), Some(4.0));
        assert!(Profile::piecewise_linear_rate(5.0, &[(1.0, 1.0)], None).is_err());
        assert!(Profile::piecewise_linear_rate(5.0, &[(0.0, 1.0), (0.0, 2.0)], None).is_err());
        assert_eq!(
            Profile::piecewise_linear_rate(5.0, &[(0.0, 1.0)], Some(2.0))
                .unwrap_err()
                .field,
            "profile.target_length_m"
        );
        // a table that would shorten through zero before stopping is rejected
        assert!(
            Profile::piecewise_linear_rate(5.0, &[(0.0, -1.0), (10.0, -1.0), (11.0, 1.0)], None)
                .is_err()
        );
    }
}
