//! The monitor's vocabulary: a telemetry sample, the checks, their levels
//! and the limits a flight is judged by (SPEC §13), with the defaults of
//! issue 33.

use super::level::Dwell;

/// One telemetry sample, `time_s` from the flight's start (the committed
/// plan's `t = 0`). Every measurement is optional: an anemometer line
/// carries the wind only, a winch log no wind.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sample {
    pub time_s: f64,
    /// Unstretched tether length paid out (m).
    pub tether_length_m: Option<f64>,
    /// Winch rate, positive paying out (m/s).
    pub winch_rate_m_s: Option<f64>,
    /// Tension at the winch (N).
    pub winch_tension_n: Option<f64>,
    /// Wind speed at the anemometer (m/s).
    pub wind_speed_m_s: Option<f64>,
    /// The anemometer's height (m).
    pub wind_height_m: Option<f64>,
    /// The aerostat's altitude above the winch (m).
    pub aerostat_altitude_m: Option<f64>,
}

impl Sample {
    pub fn at(time_s: f64) -> Self {
        Self {
            time_s,
            ..Self::default()
        }
    }
}

/// A check's or the flight's state, in increasing severity: no data is
/// worse than a caution (nothing is known), a stop worse than everything.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Level {
    Normal,
    Caution,
    Unavailable,
    Stop,
}

impl Level {
    pub fn name(self) -> &'static str {
        match self {
            Self::Normal => "normal",
            Self::Caution => "caution",
            Self::Unavailable => "unavailable",
            Self::Stop => "stop",
        }
    }
}

/// The checks. `Wind` is the 10-minute mean against the operating limit,
/// `Gust` the largest 3 s mean of the last 10 minutes against the gust
/// limit (two values, two thresholds: two checks).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum CheckName {
    Tension,
    Slack,
    Wind,
    Gust,
    PayoutRate,
    Plan,
    Data,
}

impl CheckName {
    pub const ALL: [Self; 7] = [
        Self::Tension,
        Self::Slack,
        Self::Wind,
        Self::Gust,
        Self::PayoutRate,
        Self::Plan,
        Self::Data,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Self::Tension => "tension",
            Self::Slack => "slack",
            Self::Wind => "wind",
            Self::Gust => "gust",
            Self::PayoutRate => "payout_rate",
            Self::Plan => "plan",
            Self::Data => "data",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.name() == name)
    }

    /// Index in [`Self::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }
}

/// What a flight is judged by. A check without its reference (no tether
/// rating, no wind limit, no plan, no ceiling) is not made.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits {
    /// Breaking strength ÷ required safety factor (N).
    pub allowable_tension_n: Option<f64>,
    /// `tension` caution at this fraction of the allowed tension (0.8).
    pub tension_caution_fraction: f64,
    /// Net buoyancy (N): `slack` is judged against a fraction of it.
    pub net_buoyancy_n: f64,
    /// `slack` stop below this fraction of the net buoyancy (0.05).
    pub slack_fraction: f64,
    /// `wind`: the 10-minute mean's limit (m/s).
    pub max_operating_wind_m_s: Option<f64>,
    /// `gust`: the gust's limit (m/s).
    pub max_gust_m_s: Option<f64>,
    /// `wind` and `gust` caution at this fraction of their limits (0.8).
    pub wind_caution_fraction: f64,
    /// `payout_rate` caution at this fraction of the ceiling (0.9).
    pub payout_caution_fraction: f64,
    /// `plan` caution when the length is ahead of the schedule by more
    /// than this fraction of the planned length (0.05).
    pub plan_ahead_fraction: f64,
    /// No sample for this long (server clock) makes the flight
    /// unavailable; no value of a check for this long of sample time makes
    /// the check unavailable (s, 5).
    pub stale_after_s: f64,
    pub dwell: Dwell,
    /// The wind mean's window (600 s).
    pub wind_mean_window_s: f64,
    /// The gust's averaging time (3 s).
    pub gust_average_s: f64,
}

impl Limits {
    /// The defaults of SPEC §13 / issue 33 for a system of net buoyancy
    /// `net_buoyancy_n`.
    pub fn new(net_buoyancy_n: f64) -> Self {
        Self {
            allowable_tension_n: None,
            tension_caution_fraction: 0.8,
            net_buoyancy_n,
            slack_fraction: 0.05,
            max_operating_wind_m_s: None,
            max_gust_m_s: None,
            wind_caution_fraction: 0.8,
            payout_caution_fraction: 0.9,
            plan_ahead_fraction: 0.05,
            stale_after_s: 5.0,
            dwell: Dwell::default(),
            wind_mean_window_s: 600.0,
            gust_average_s: 3.0,
        }
    }
}

/// The committed schedule `L(t)` as samples, linear between them and held
/// at the ends.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanTrace {
    times_s: Vec<f64>,
    lengths_m: Vec<f64>,
    /// `+1` deploying, `−1` retrieving.
    direction: f64,
    /// The smallest planned length a fraction is taken of (m): 1 % of the
    /// plan's travel, so that `L_plan = 0` at the start divides nothing.
    floor_m: f64,
}

impl PlanTrace {
    /// From strictly increasing times and their lengths; `None` when they
    /// are not.
    pub fn new(times_s: Vec<f64>, lengths_m: Vec<f64>) -> Option<Self> {
        let ok = times_s.len() >= 2
            && times_s.len() == lengths_m.len()
            && times_s.windows(2).all(|w| w[0] < w[1])
            && times_s.iter().chain(&lengths_m).all(|v| v.is_finite());
        if !ok {
            return None;
        }
        let travel = lengths_m[lengths_m.len() - 1] - lengths_m[0];
        Some(Self {
            direction: if travel < 0.0 { -1.0 } else { 1.0 },
            floor_m: (0.01 * travel.abs()).max(1e-3),
            times_s,
            lengths_m,
        })
    }

    /// The schedule's last time (s).
    pub fn end_time_s(&self) -> f64 {
        self.times_s[self.times_s.len() - 1]
    }

    /// Planned length at `t` (m).
    pub fn length_at_m(&self, t: f64) -> f64 {
        let n = self.times_s.len();
        if !(t > self.times_s[0]) {
            return self.lengths_m[0];
        }
        if t >= self.times_s[n - 1] {
            return self.lengths_m[n - 1];
        }
        let i = self.times_s.partition_point(|&ti| ti <= t) - 1;
        let a = (t - self.times_s[i]) / (self.times_s[i + 1] - self.times_s[i]);
        self.lengths_m[i] + a * (self.lengths_m[i + 1] - self.lengths_m[i])
    }

    /// How far `length_m` is ahead of the plan at `t`, as a fraction of
    /// the planned length (positive ahead: longer deploying, shorter
    /// retrieving).
    pub fn ahead_fraction(&self, t: f64, length_m: f64) -> f64 {
        let plan = self.length_at_m(t);
        self.direction * (length_m - plan) / plan.abs().max(self.floor_m)
    }
}
