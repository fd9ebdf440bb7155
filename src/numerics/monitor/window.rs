//! Rolling windows over a time-ordered stream, O(1) amortised per sample:
//! the mean of the samples in the last `span` seconds ([`RollingMean`]) and
//! the largest value of a derived series in the last `span` seconds
//! ([`RollingMax`], a monotonic deque). Together they give the wind
//! check's 10-minute mean and its gust, the largest 3 s mean of the last
//! 10 minutes (SPEC §10, §13; WMO's 3 s gust).
//!
//! A window holds the samples with `time > t − span` at the latest time
//! `t` (half-open: a sample exactly `span` old has left). Times must not
//! decrease (the monitor evaluates in time order); a sample at an equal
//! time is a new sample of the window.

use std::collections::VecDeque;

/// Mean of the samples of the last `span_s` seconds.
///
/// The running sum is kept with Neumaier's compensation so that hours of
/// additions and removals do not drift (a test compares it with a direct
/// sum after 100 000 samples).
#[derive(Clone, Debug)]
pub struct RollingMean {
    span_s: f64,
    samples: VecDeque<(f64, f64)>,
    sum: f64,
    compensation: f64,
}

impl RollingMean {
    pub fn new(span_s: f64) -> Self {
        Self {
            span_s,
            samples: VecDeque::new(),
            sum: 0.0,
            compensation: 0.0,
        }
    }

    fn add(&mut self, x: f64) {
        let t = self.sum + x;
        if self.sum.abs() >= x.abs() {
            self.compensation += (self.sum - t) + x;
        } else {
            self.compensation += (x - t) + self.sum;
        }
        self.sum = t;
    }

    /// Adds the sample `value` at `time_s`, drops those that left the
    /// window, and returns the mean of what is in it.
    pub fn push(&mut self, time_s: f64, value: f64) -> f64 {
        self.samples.push_back((time_s, value));
        self.add(value);
        while let Some(&(t0, v0)) = self.samples.front() {
            if t0 > time_s - self.span_s {
                break;
            }
            self.samples.pop_front();
            self.add(-v0);
        }
        self.mean().unwrap_or(value)
    }

    /// The mean of the window; `None` when empty.
    pub fn mean(&self) -> Option<f64> {
        let n = self.samples.len();
        (n > 0).then(|| (self.sum + self.compensation) / n as f64)
    }

    /// Time spanned by the samples in the window (s).
    pub fn covered_s(&self) -> f64 {
        match (self.samples.front(), self.samples.back()) {
            (Some(a), Some(b)) => b.0 - a.0,
            _ => 0.0,
        }
    }

    pub fn len(&self) -> usize {
        self.samples.len()
    }

    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }
}

/// Largest value pushed in the last `span_s` seconds: a deque of values
/// that decrease from front to back (each value enters and leaves once).
#[derive(Clone, Debug)]
pub struct RollingMax {
    span_s: f64,
    candidates: VecDeque<(f64, f64)>,
}

impl RollingMax {
    pub fn new(span_s: f64) -> Self {
        Self {
            span_s,
            candidates: VecDeque::new(),
        }
    }

    /// Adds `value` at `time_s` and returns the largest value of the window.
    pub fn push(&mut self, time_s: f64, value: f64) -> f64 {
        while let Some(&(_, v)) = self.candidates.back() {
            if v > value {
                break;
            }
            self.candidates.pop_back();
        }
        self.candidates.push_back((time_s, value));
        while let Some(&(t0, _)) = self.candidates.front() {
            if t0 > time_s - self.span_s {
                break;
            }
            self.candidates.pop_front();
        }
        self.max().unwrap_or(value)
    }

    pub fn max(&self) -> Option<f64> {
        self.candidates.front().map(|&(_, v)| v)
    }
}

/// The wind's two figures: the mean of the last `mean_span_s` (600 s) and
/// the gust, the largest `gust_span_s` (3 s) mean of the last
/// `mean_span_s`.
#[derive(Clone, Debug)]
pub struct WindWindow {
    mean: RollingMean,
    short: RollingMean,
    gust: RollingMax,
}

impl WindWindow {
    pub fn new(mean_span_s: f64, gust_span_s: f64) -> Self {
        Self {
            mean: RollingMean::new(mean_span_s),
            short: RollingMean::new(gust_span_s),
            gust: RollingMax::new(mean_span_s),
        }
    }

    /// Adds a wind speed; returns `(mean, gust)` (m/s).
    pub fn push(&mut self, time_s: f64, speed_m_s: f64) -> (f64, f64) {
        let mean = self.mean.push(time_s, speed_m_s);
        let short = self.short.push(time_s, speed_m_s);
        let gust = self.gust.push(time_s, short);
        (mean, gust)
    }

    /// `(mean, gust)` of the samples so far; `None` before the first.
    pub fn current(&self) -> Option<(f64, f64)> {
        Some((self.mean.mean()?, self.gust.max()?))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Direct O(n) means over the same half-open windows.
    fn direct_mean(s: &[(f64, f64)], t: f64, span: f64) -> f64 {
        let w: Vec<f64> = s
            .iter()
            .filter(|(ti, _)| *ti > t - span && *ti <= t)
            .map(|p| p.1)
            .collect();
        w.iter().sum::<f64>() / w.len() as f64
    }

    fn series(n: usize) -> Vec<(f64, f64)> {
        // irregular times, a deterministic wiggly value
        let mut t = 0.0;
        (0..n)
            .map(|i| {
                t += 0.05 + 0.1 * ((i * 7919 % 13) as f64 / 13.0);
                (t, 8.0 + 3.0 * (0.37 * i as f64).sin() + ((i * 104729 % 17) as f64) / 17.0)
            })
            .collect()
    }

    #[test]
    fn rolling_mean_matches_the_direct_mean_to_1e_12() {
        let s = series(20_000);
        let mut w = RollingMean::new(600.0);
        for (i, &(t, v)) in s.iter().enumerate() {
            let m = w.push(t, v);
            if i % 997 == 0 || i + 1 == s.len() {
                let d = direct_mean(&s[..=i], t, 600.0);
                assert!((m - d).abs() <= 1e-12 * d, "i {i}: {m} vs {d}");
            }
        }
    }

    #[test]
    fn gust_is_the_largest_3_s_mean_of_the_last_10_minutes() {
        let s = series(12_000);
        let mut w = WindWindow::new(600.0, 3.0);
        for (i, &(t, v)) in s.iter().enumerate() {
            let (_, gust) = w.push(t, v);
            if i % 1499 == 0 || i + 1 == s.len() {
                // the 3 s mean at every sample time of the last 600 s
                let direct = s[..=i]
                    .iter()
                    .filter(|(tj, _)| *tj > t - 600.0)
                    .map(|&(tj, _)| direct_mean(&s[..=i], tj, 3.0))
                    .fold(f64::NEG_INFINITY, f64::max);
                assert!((gust - direct).abs() <= 1e-12 * direct, "i {i}: {gust} vs {direct}");
            }
        }
    }

    #[test]
    fn a_step_in_the_wind_reaches_the_mean_linearly_and_the_gust_after_3_s() {
        // 1 Hz samples: 5 m/s for 600 s then 10 m/s
        let mut w = WindWindow::new(600.0, 3.0);
        for k in 1..=600 {
            w.push(k as f64, 5.0);
        }
        let (m, g) = w.push(601.0, 10.0);
        // the window (1, 601] holds 599 fives and one ten
        assert!((m - (599.0 * 5.0 + 10.0) / 600.0).abs() < 1e-12);
        assert!((g - (5.0 + 5.0 + 10.0) / 3.0).abs() < 1e-12);
        w.push(602.0, 10.0);
        let (_, g) = w.push(603.0, 10.0);
        assert_eq!(g, 10.0);
        // after 10 minutes of ten, the fives are gone from both
        let mut last = (0.0, 0.0);
        for k in 604..=1203 {
            last = w.push(k as f64, 10.0);
        }
        assert_eq!(last, (10.0, 10.0));
    }

    #[test]
    fn rolling_max_forgets_after_the_span() {
        let mut m = RollingMax::new(10.0);
        assert_eq!(m.push(0.0, 5.0), 5.0);
        assert_eq!(m.push(1.0, 3.0), 5.0);
        assert_eq!(m.push(9.5, 1.0), 5.0);
        assert_eq!(m.push(10.0, 2.0), 3.0); // the 5 at t = 0 is exactly 10 s old
        assert_eq!(m.push(11.0, 0.0), 2.0);
    }
}
