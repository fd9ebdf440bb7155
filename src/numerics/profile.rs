//! Deployment profiles `L(t)` (SI): the winch schedule that drives the
//! time-varying length. Each profile gives the kinematics at any `t ≥ 0`
//! and the time it stops (reaches its target length), if it does.

use crate::numerics::params::{InvalidInput, Kinematics, require_finite, require_positive};

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
}

impl Profile {
    pub fn constant_rate(
        initial_length_m: f64,
        rate_m_s: f64,
        target_length_m: Option<f64>,
    ) -> Result<Self, InvalidInput> {
        require_finite("profile.rate_m_s", rate_m_s)?;
        if rate_m_s == 0.0 || rate_m_s.abs() > 1e5 {
            return Err(InvalidInput::new(
                "profile.rate_m_s",
                "must be nonzero and within ±1e5 m/s (for a fixed length, ask for the stability of that state)",
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

    pub fn initial_length_m(&self) -> f64 {
        match *self {
            Self::ConstantRate {
                initial_length_m, ..
            }
            | Self::ConstantAcceleration {
                initial_length_m, ..
            } => initial_length_m,
        }
    }

    /// Length, rate and acceleration at time `t_s`.
    pub fn kinematics(&self, t_s: f64) -> Kinematics {
        let t = t_s.min(self.stop_time_s().unwrap_or(f64::INFINITY));
        let stopped = self.stop_time_s().is_some_and(|stop| t_s >= stop);
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
        match *self {
            Self::ConstantRate {
                initial_length_m,
                rate_m_s,
                ..
            } => moving(Kinematics {
                length_m: initial_length_m + rate_m_s * t,
                rate_m_s,
                acceleration_m_s2: 0.0,
            }),
            Self::ConstantAcceleration {
                initial_length_m,
                acceleration_m_s2: a,
                ..
            } => moving(Kinematics {
                length_m: initial_length_m + 0.5 * a * t * t,
                rate_m_s: a * t,
                acceleration_m_s2: a,
            }),
        }
    }

    /// Time at which the length reaches the target, or reaches zero when
    /// retrieving without a target.
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
        }
    }

    /// Time at which the length reaches `length_m` (lengthening profiles),
    /// or `None` if it never does.
    pub fn time_to_length_s(&self, length_m: f64) -> Option<f64> {
        let t = match *self {
            Self::ConstantRate {
                initial_length_m,
                rate_m_s,
                ..
            } => {
                if rate_m_s <= 0.0 {
                    return None;
                }
                (length_m - initial_length_m) / rate_m_s
            }
            Self::ConstantAcceleration {
                initial_length_m,
                acceleration_m_s2,
                ..
            } => {
                if acceleration_m_s2 <= 0.0 {
                    return None;
                }
                (2.0 * (length_m - initial_length_m) / acceleration_m_s2).sqrt()
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
}
