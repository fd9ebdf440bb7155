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
