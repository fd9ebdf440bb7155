//! Haul-down deadline: given a wind forecast `(t, U)` (wind at the
//! aerostat, linear between points, held before the first and after the
//! last) and an operating wind limit, the latest time a retrieval must
//! start so that the aerostat is down before the wind first exceeds the
//! limit: `t_start = t_exceed − D`, `D` the duration of the fastest safe
//! retrieval ([`super::schedule::fastest`]).
//!
//! With gusts (issue 21, SPEC §10) the limit is passed at the first
//! forecast time at which the mean passes `max_operating_wind_m_s` **or**
//! the gust passes `max_gust_m_s` ([`first_limit_exceedance`],
//! [`haul_down_with_gusts`]): whichever comes first sets the deadline.

use crate::numerics::params::{InvalidInput, require_finite, require_non_negative};

/// Most points of a forecast.
pub const MAX_FORECAST_POINTS: usize = 10_000;

/// A validated wind forecast.
#[derive(Clone, Debug, PartialEq)]
pub struct Forecast {
    points: Vec<(f64, f64)>,
}

impl Forecast {
    /// Times strictly increasing and `≥ 0`, speeds `≥ 0`; `field` names the
    /// list in errors.
    pub fn new(points: &[(f64, f64)], field: &str) -> Result<Self, InvalidInput> {
        if points.is_empty() || points.len() > MAX_FORECAST_POINTS {
            return Err(InvalidInput::new(
                field,
                format!(
                    "must have between 1 and {MAX_FORECAST_POINTS} points, got {}",
                    points.len()
                ),
            ));
        }
        for (i, &(t, u)) in points.iter().enumerate() {
            require_non_negative(&format!("{field}[{i}].time_s"), t)?;
            require_non_negative(&format!("{field}[{i}].wind_speed_m_s"), u)?;
            require_finite(&format!("{field}[{i}].time_s"), t)?;
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
        Ok(Self {
            points: points.to_vec(),
        })
    }

    /// Wind speed at `t_s` (m/s).
    pub fn at(&self, t_s: f64) -> f64 {
        let p = &self.points;
        let k = p.partition_point(|q| q.0 <= t_s);
        if k == 0 {
            return p[0].1;
        }
        if k == p.len() {
            return p[k - 1].1;
        }
        let (t0, u0) = p[k - 1];
        let (t1, u1) = p[k];
        u0 + (u1 - u0) * (t_s - t0) / (t1 - t0)
    }

    /// First time at which the wind exceeds `limit` (s), `Some(0)` if it
    /// already does at `t = 0`, `None` if it never does in the forecast.
    pub fn first_exceedance_s(&self, limit: f64) -> Option<f64> {
        if self.at(0.0) > limit {
            return Some(0.0);
        }
        let p = &self.points;
        for w in p.windows(2) {
            let ((t0, u0), (t1, u1)) = (w[0], w[1]);
            if t1 <= 0.0 {
                continue;
            }
            if u1 > limit {
                let t = if u0 >= u1 {
                    t0
                } else {
                    t0 + (limit - u0).max(0.0) / (u1 - u0) * (t1 - t0)
                };
                return Some(t.max(0.0));
            }
        }
        None
    }

    /// Last time of the forecast (s).
    pub fn horizon_s(&self) -> f64 {
        self.points.last().map_or(0.0, |p| p.0)
    }
}

/// The answer.
#[derive(Clone, Debug, PartialEq)]
pub struct HaulDown {
    /// When the wind first exceeds the limit (s); `None`: not in the forecast.
    pub exceeds_at_s: Option<f64>,
    /// Duration of the haul-down (s).
    pub retrieval_duration_s: f64,
    /// Latest start of the haul-down (s); `None` without an exceedance.
    pub latest_start_s: Option<f64>,
    pub go: bool,
    pub reason: String,
}

/// The deadline. `aloft_from_s` is when the aerostat is at its operating
/// altitude (the end of a deployment; 0 for a retrieval from where it is).
pub fn haul_down(
    forecast: &Forecast,
    limit_m_s: f64,
    retrieval_duration_s: f64,
    aloft_from_s: f64,
) -> HaulDown {
    let exceeds = forecast.first_exceedance_s(limit_m_s);
    let Some(t_x) = exceeds else {
        return HaulDown {
            exceeds_at_s: None,
            retrieval_duration_s,
            latest_start_s: None,
            go: true,
            reason: format!(
                "go: the forecast wind stays within {limit_m_s:.1} m/s up to its end at {:.0} s; \
                 the haul-down takes {retrieval_duration_s:.1} s",
                forecast.horizon_s()
            ),
        };
    };
    let latest = t_x - retrieval_duration_s;
    let go = latest >= aloft_from_s;
    let reason = if go {
        format!(
            "go: the wind exceeds {limit_m_s:.1} m/s at {t_x:.1} s; start the haul-down \
             ({retrieval_duration_s:.1} s) by {latest:.1} s"
        )
    } else if aloft_from_s > 0.0 {
        format!(
            "no-go: the wind exceeds {limit_m_s:.1} m/s at {t_x:.1} s; the haul-down takes \
             {retrieval_duration_s:.1} s, so it must start by {latest:.1} s, before the deployment \
             reaches its altitude at {aloft_from_s:.1} s"
        )
    } else {
        format!(
            "no-go: the wind exceeds {limit_m_s:.1} m/s at {t_x:.1} s, but the haul-down takes \
             {retrieval_duration_s:.1} s: it should have started at {latest:.1} s"
        )
    };
    HaulDown {
        exceeds_at_s: Some(t_x),
        retrieval_duration_s,
        latest_start_s: Some(latest),
        go,
        reason,
    }
}

/// Which forecast series passed its limit first.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExceededBy {
    Mean,
    Gust,
}

/// The first time (s) at which the mean passes `mean_limit_m_s` or the
/// gust series passes its limit, and which one (the mean on a tie).
pub fn first_limit_exceedance(
    mean: &Forecast,
    mean_limit_m_s: f64,
    gust: Option<(&Forecast, f64)>,
) -> Option<(f64, ExceededBy)> {
    let m = mean.first_exceedance_s(mean_limit_m_s);
    let g = gust.and_then(|(f, limit)| f.first_exceedance_s(limit));
    match (m, g) {
        (Some(a), Some(b)) if b < a => Some((b, ExceededBy::Gust)),
        (Some(a), _) => Some((a, ExceededBy::Mean)),
        (None, Some(b)) => Some((b, ExceededBy::Gust)),
        (None, None) => None,
    }
}

/// The deadline with gusts: [`haul_down`] at the earlier of the mean's and
/// the gust's first exceedance; the reason names the one that binds.
/// Without a gust series it is [`haul_down`] exactly.
pub fn haul_down_with_gusts(
    mean: &Forecast,
    mean_limit_m_s: f64,
    gust: Option<(&Forecast, f64)>,
    retrieval_duration_s: f64,
    aloft_from_s: f64,
) -> (HaulDown, Option<ExceededBy>) {
    let first = first_limit_exceedance(mean, mean_limit_m_s, gust);
    match (first, gust) {
        (Some((_, ExceededBy::Gust)), Some((g, limit))) => {
            let mut h = haul_down(g, limit, retrieval_duration_s, aloft_from_s);
            h.reason = h.reason.replacen("the wind exceeds", "the gust exceeds", 1);
            (h, Some(ExceededBy::Gust))
        }
        _ => {
            let mut h = haul_down(mean, mean_limit_m_s, retrieval_duration_s, aloft_from_s);
            if let Some((g, limit)) = gust
                && h.exceeds_at_s.is_none()
            {
                h.reason = format!(
                    "{}; the gust stays within {limit:.1} m/s up to {:.0} s",
                    h.reason,
                    g.horizon_s()
                );
            }
            (h, first.map(|f| f.1))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Gusts that pass their limit before the mean passes its own give the
    /// earlier deadline; gusts within their limit leave the mean's.
    #[test]
    fn gusts_passing_first_give_the_earlier_deadline() {
        let mean = Forecast::new(&[(0.0, 6.0), (3600.0, 14.0)], "f").unwrap();
        // mean passes 12 at 2700 s; gust (×1.45) passes 15 at t where 1.45·U = 15
        let gust_pts: Vec<(f64, f64)> = [(0.0, 6.0), (3600.0, 14.0)]
            .iter()
            .map(|&(t, u)| (t, 1.45 * u))
            .collect();
        let gust = Forecast::new(&gust_pts, "g").unwrap();
        let t_mean = 2700.0;
        let t_gust = (15.0 / 1.45 - 6.0) / 8.0 * 3600.0;
        let (h, by) = haul_down_with_gusts(&mean, 12.0, Some((&gust, 15.0)), 300.0, 0.0);
        assert_eq!(by, Some(ExceededBy::Gust));
        assert!((h.exceeds_at_s.unwrap() - t_gust).abs() < 1e-9 && t_gust < t_mean);
        assert!((h.latest_start_s.unwrap() - (t_gust - 300.0)).abs() < 1e-9);
        assert!(h.reason.contains("gust exceeds"), "{}", h.reason);
        // a gust limit the gusts never reach: the mean's deadline, as without gusts
        let (h2, by2) = haul_down_with_gusts(&mean, 12.0, Some((&gust, 30.0)), 300.0, 0.0);
        assert_eq!(by2, Some(ExceededBy::Mean));
        assert_eq!(
            h2.exceeds_at_s,
            haul_down(&mean, 12.0, 300.0, 0.0).exceeds_at_s
        );
        assert!((h2.exceeds_at_s.unwrap() - t_mean).abs() < 1e-9);
        assert_eq!(
            haul_down_with_gusts(&mean, 12.0, None, 300.0, 0.0).0,
            haul_down(&mean, 12.0, 300.0, 0.0)
        );
    }

    #[test]
    fn exceedance_interpolates() {
        let f = Forecast::new(&[(0.0, 5.0), (100.0, 15.0)], "f").unwrap();
        assert!((f.first_exceedance_s(10.0).unwrap() - 50.0).abs() < 1e-12);
        assert_eq!(f.first_exceedance_s(20.0), None);
        assert_eq!(f.first_exceedance_s(4.0), Some(0.0));
    }

    #[test]
    fn rejects_unordered_times() {
        let e = Forecast::new(&[(0.0, 5.0), (0.0, 6.0)], "haul_down.forecast").unwrap_err();
        assert_eq!(e.field, "haul_down.forecast[1].time_s");
    }
}
