//! Raising and clearing one alarm level of one check with dwell times and
//! hysteresis (SPEC §13; Makani's ground monitor, crane wind alarms).
//!
//! A level is **raised** at the first sample at which its threshold has
//! been passed at every sample for at least `raise_after_s` of sample time
//! (the run starts at the first sample past it, so one sample alone never
//! raises anything unless `raise_after_s = 0`). It is **cleared** at the
//! first sample at which the value has been back on the safe side of
//! `clear_fraction × threshold` at every sample for at least
//! `clear_after_s`; values between the two neither raise nor clear, and
//! reset both runs. "Passed" and "back" are measured in the check's
//! sense: a check that alarms above its threshold is back below
//! `0.9 × threshold`; one that alarms below it (slack) is back above
//! `threshold / 0.9`.

/// Sample times closer than this count as equal in a dwell (s): times
/// such as `0.1 k` are not exact in binary.
pub const TIME_TOLERANCE_S: f64 = 1e-6;

/// Which side of the threshold alarms.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sense {
    /// Alarm when the value exceeds the threshold.
    Above,
    /// Alarm when the value falls below the threshold.
    Below,
}

impl Sense {
    /// Whether `value` has passed `threshold`.
    pub fn passed(self, value: f64, threshold: f64) -> bool {
        match self {
            Self::Above => value > threshold,
            Self::Below => value < threshold,
        }
    }

    /// Whether `value` is back on the safe side of the threshold by the
    /// hysteresis `fraction` (< 1).
    pub fn back(self, value: f64, threshold: f64, fraction: f64) -> bool {
        match self {
            Self::Above => value < fraction * threshold,
            Self::Below => value * fraction > threshold,
        }
    }
}

/// The dwell times and the hysteresis of every level.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dwell {
    /// Sample time a threshold must stay passed before the level is raised (s).
    pub raise_after_s: f64,
    /// Sample time the value must stay back before the level clears (s).
    pub clear_after_s: f64,
    /// The fraction of the threshold the value must be back below (0.9).
    pub clear_fraction: f64,
}

impl Default for Dwell {
    fn default() -> Self {
        Self {
            raise_after_s: 1.0,
            clear_after_s: 5.0,
            clear_fraction: 0.9,
        }
    }
}

/// What one sample did to a level.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Transition {
    None,
    Raised,
    Cleared,
}

/// One level of one check.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LevelTracker {
    /// Whether the level is raised.
    pub active: bool,
    /// Start of the current run past the threshold (while not raised).
    passed_since_s: Option<f64>,
    /// Start of the current run back on the safe side (while raised).
    back_since_s: Option<f64>,
}

impl LevelTracker {
    /// Updates the level with the value of a sample at `time_s` (times in
    /// order) against `threshold`.
    pub fn update(
        &mut self,
        dwell: &Dwell,
        sense: Sense,
        time_s: f64,
        value: f64,
        threshold: f64,
    ) -> Transition {
        if !self.active {
            if sense.passed(value, threshold) {
                let since = *self.passed_since_s.get_or_insert(time_s);
                if time_s - since >= dwell.raise_after_s - TIME_TOLERANCE_S {
                    self.active = true;
                    self.passed_since_s = None;
                    self.back_since_s = None;
                    return Transition::Raised;
                }
            } else {
                self.passed_since_s = None;
            }
        } else if sense.back(value, threshold, dwell.clear_fraction) {
            let since = *self.back_since_s.get_or_insert(time_s);
            if time_s - since >= dwell.clear_after_s - TIME_TOLERANCE_S {
                self.active = false;
                self.back_since_s = None;
                self.passed_since_s = None;
                return Transition::Cleared;
            }
        } else {
            self.back_since_s = None;
        }
        Transition::None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Feeds `(time, value)` and returns the transitions with their times.
    fn run(sense: Sense, thr: f64, s: &[(f64, f64)]) -> Vec<(f64, Transition)> {
        let d = Dwell::default();
        let mut l = LevelTracker::default();
        s.iter()
            .map(|&(t, v)| (t, l.update(&d, sense, t, v, thr)))
            .filter(|(_, tr)| *tr != Transition::None)
            .collect()
    }

    #[test]
    fn a_single_sample_spike_raises_nothing() {
        let mut s: Vec<(f64, f64)> = (0..100).map(|k| (0.1 * k as f64, 1.0)).collect();
        s[50].1 = 100.0;
        assert!(run(Sense::Above, 2.0, &s).is_empty());
    }

    #[test]
    fn raised_after_the_dwell_and_cleared_after_the_longer_one_below_0_9() {
        // 10 Hz: above from t = 1.0 to 3.0, then at 0.95 × threshold (no
        // clearing), then 0.85 × threshold from t = 5.0
        let s: Vec<(f64, f64)> = (0..200)
            .map(|k| {
                let t = 0.1 * k as f64;
                let v = if k < 10 {
                    1.0
                } else if k <= 30 {
                    2.5
                } else if k < 50 {
                    1.9
                } else {
                    1.7
                };
                (t, v)
            })
            .collect();
        let tr = run(Sense::Above, 2.0, &s);
        assert_eq!(tr.len(), 2, "{tr:?}");
        assert_eq!(tr[0].1, Transition::Raised);
        // the run starts at k = 10 (t = 1.0); raised at the first t ≥ 2.0
        assert!((tr[0].0 - 2.0).abs() < 1e-9, "{tr:?}");
        assert_eq!(tr[1].1, Transition::Cleared);
        // back below 1.8 from k = 50 (t = 5.0): cleared at t = 10.0
        assert!((tr[1].0 - 10.0).abs() < 1e-9, "{tr:?}");
    }

    #[test]
    fn a_dip_interrupts_the_raise_and_a_bump_the_clear() {
        let mut s: Vec<(f64, f64)> = (0..30).map(|k| (0.1 * k as f64, 3.0)).collect();
        s[8].1 = 1.0; // the run restarts at k = 9
        let tr = run(Sense::Above, 2.0, &s);
        assert!((tr[0].0 - 1.9).abs() < 1e-9, "{tr:?}");
    }

    #[test]
    fn below_sense_clears_above_threshold_over_0_9() {
        // slack: threshold 50 N; value 10 N for 2 s, then 54 N (not back:
        // 54 × 0.9 = 48.6 < 50), then 60 N (back) for 5 s
        let mut s = Vec::new();
        for k in 0..=20 {
            s.push((0.1 * k as f64, 10.0));
        }
        for k in 21..=40 {
            s.push((0.1 * k as f64, 54.0));
        }
        for k in 41..=100 {
            s.push((0.1 * k as f64, 60.0));
        }
        let tr = run(Sense::Below, 50.0, &s);
        assert_eq!(tr[0], (1.0, Transition::Raised));
        assert_eq!(tr[1].1, Transition::Cleared);
        assert!((tr[1].0 - 9.1).abs() < 1e-9, "{tr:?}");
    }
}
