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
