//! The flight monitor (SPEC §13): every sample, in time order, updates the
//! rolling wind windows and each check's value, thresholds and two levels
//! (caution, stop: [`super::level`]); raised levels become alarms; a stop
//! stays latched until acknowledged; the flight's state is its worst
//! check, with `unavailable` when no sample arrived for `stale_after_s` by
//! the caller's clock.
//!
//! **Order.** The monitor is a function of the samples sorted by
//! `time_s` and of the acknowledgements placed at the sample time they
//! were made at. [`Monitor::push`] takes a sample later than every one
//! before in O(1) amortised; a sample at an equal time is a duplicate and
//! changes nothing (the first one stays); an earlier one is refused
//! ([`Pushed::OutOfOrder`]) and the caller rebuilds the monitor with
//! [`Monitor::replay`] over the merged, sorted history, so a late sample
//! is judged exactly where it belongs (a test shuffles a flight's batches
//! and gets the same state and alarms).
//!
//! **Checks** (value, caution, stop; sense):
//! - `tension`: winch tension, `0.8 A`, `A` (`A` = breaking strength ÷
//!   required safety factor); above.
//! - `slack`: winch tension, —, `0.05 F`; below.
//! - `wind`: 10-minute mean, `0.8 U_max`, `U_max`; above.
//! - `gust`: largest 3 s mean of the last 10 minutes, `0.8 U_gust`,
//!   `U_gust`; above.
//! - `payout_rate`: winch rate, `0.9 c`, `c`; above, with `c` the smaller
//!   of the ceilings at the current length in the mean and in the gust
//!   (the plan takes the smaller `S` of the two).
//! - `plan`: `(L − L_plan(t)) / L_plan(t)`, `0.05`, —; above.
//! - `data`: seconds since the last sample by the caller's clock;
//!   `unavailable` past `stale_after_s`.
//!
//! A sample without a check's measurement leaves that check as it was; a
//! check whose last value is older than `stale_after_s` of sample time is
//! `unavailable` (unless a stop is latched).

use std::sync::Arc;

use super::ceiling::RateCeiling;
use super::level::{LevelTracker, Sense, Transition};
use super::sample::{CheckName, Level, Limits, PlanTrace, Sample};
use super::window::WindWindow;

/// The references a flight's checks need beside its limits.
#[derive(Clone)]
pub struct FlightModel {
    pub limits: Limits,
    /// The committed schedule (`plan` check).
    pub plan: Option<PlanTrace>,
    /// The stability ceiling (`payout_rate` check).
    pub ceiling: Option<Arc<dyn RateCeiling + Send + Sync>>,
}

impl FlightModel {
    /// The checks this flight makes, in [`CheckName::ALL`] order.
    pub fn checks(&self) -> Vec<CheckName> {
        let l = &self.limits;
        CheckName::ALL
            .into_iter()
            .filter(|c| match c {
                CheckName::Tension => l.allowable_tension_n.is_some(),
                CheckName::Wind => l.max_operating_wind_m_s.is_some(),
                CheckName::Gust => l.max_gust_m_s.is_some(),
                CheckName::PayoutRate => self.ceiling.is_some(),
                CheckName::Plan => self.plan.is_some(),
                CheckName::Slack | CheckName::Data => true,
            })
            .collect()
    }
}

/// A raised level.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Alarm {
    pub check: CheckName,
    /// `Caution` or `Stop`.
    pub level: Level,
    pub raised_at_s: f64,
    pub cleared_at_s: Option<f64>,
    pub acknowledged_at_s: Option<f64>,
}

/// One check's current figures and levels.
#[derive(Clone, Copy, Debug, Default)]
struct CheckState {
    value: Option<f64>,
    value_time_s: f64,
    caution_at: Option<f64>,
    stop_at: Option<f64>,
    caution: LevelTracker,
    stop: LevelTracker,
    /// Index in the alarm list of the open caution and stop alarms.
    caution_alarm: Option<usize>,
    stop_alarm: Option<usize>,
    /// Stop alarms not yet acknowledged (latched).
    unacknowledged_stops: u32,
}

/// A check as reported.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CheckStatus {
    pub name: CheckName,
    pub state: Level,
    pub value: Option<f64>,
    pub caution_at: Option<f64>,
    pub stop_at: Option<f64>,
}

/// The flight as reported at one instant of the caller's clock.
#[derive(Clone, Debug, PartialEq)]
pub struct Status {
    pub state: Level,
    pub checks: Vec<CheckStatus>,
}

/// What [`Monitor::push`] did with a sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pushed {
    /// Evaluated; the number of levels raised or cleared by it.
    Evaluated { transitions: u32 },
    /// Same `time_s` as the last evaluated sample: ignored.
    Duplicate,
    /// Earlier than the last evaluated sample: not evaluated; replay.
    OutOfOrder,
    /// `time_s` not finite: ignored.
    Invalid,
}

/// An entry of a flight's history, for [`Monitor::replay`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Event {
    Sample(Sample),
    /// Acknowledged when the last sample was at `time_s`.
    Acknowledge {
        time_s: f64,
    },
}

impl Event {
    pub fn time_s(&self) -> f64 {
        match self {
            Self::Sample(s) => s.time_s,
            Self::Acknowledge { time_s } => *time_s,
        }
    }
}

/// The monitor of one flight.
#[derive(Clone)]
pub struct Monitor {
    model: FlightModel,
    wind: WindWindow,
    checks: [CheckState; 7],
    /// Last known length and wind figures (the payout check needs them
    /// from earlier samples when a sample lacks them).
    length_m: Option<f64>,
    wind_now: Option<(f64, f64)>,
    alarms: Vec<Alarm>,
    last_sample_time_s: Option<f64>,
    samples: u64,
}

impl Monitor {
    pub fn new(model: FlightModel) -> Self {
        let l = &model.limits;
        Self {
            wind: WindWindow::new(l.wind_mean_window_s, l.gust_average_s),
            model,
            checks: [CheckState::default(); 7],
            length_m: None,
            wind_now: None,
            alarms: Vec::new(),
            last_sample_time_s: None,
            samples: 0,
        }
    }

    /// A monitor fed `events` (sorted by time, acknowledgements after the
    /// samples of their time; out-of-order entries are sorted first).
    pub fn replay(model: FlightModel, events: &[Event]) -> Self {
        let mut sorted: Vec<Event> = events.to_vec();
        let rank = |e: &Event| matches!(e, Event::Acknowledge { .. }) as u8;
        sorted.sort_by(|a, b| {
            a.time_s()
                .total_cmp(&b.time_s())
                .then(rank(a).cmp(&rank(b)))
        });
        let mut m = Self::new(model);
        for e in &sorted {
            match e {
                Event::Sample(s) => {
                    m.push(s);
                }
                Event::Acknowledge { time_s } => {
                    m.acknowledge_at(*time_s);
                }
            }
        }
        m
    }

    pub fn model(&self) -> &FlightModel {
        &self.model
    }

    pub fn alarms(&self) -> &[Alarm] {
        &self.alarms
    }

    pub fn last_sample_time_s(&self) -> Option<f64> {
        self.last_sample_time_s
    }

    /// The wind's `(10-minute mean, gust)` now (m/s); `None` before any.
    pub fn wind_m_s(&self) -> Option<(f64, f64)> {
        self.wind_now
    }

    /// The latest measured tether length (m).
    pub fn length_m(&self) -> Option<f64> {
        self.length_m
    }

    /// Samples evaluated.
    pub fn samples(&self) -> u64 {
        self.samples
    }

    /// Evaluates one sample (see the module's note on order).
    pub fn push(&mut self, s: &Sample) -> Pushed {
        if !s.time_s.is_finite() {
            return Pushed::Invalid;
        }
        if let Some(last) = self.last_sample_time_s {
            if s.time_s == last {
                return Pushed::Duplicate;
            }
            if s.time_s < last {
                return Pushed::OutOfOrder;
            }
        }
        self.last_sample_time_s = Some(s.time_s);
        self.samples += 1;
        let t = s.time_s;
        let l = self.model.limits;
        if let Some(v) = s.wind_speed_m_s.filter(|v| v.is_finite()) {
            self.wind_now = Some(self.wind.push(t, v));
        }
        if let Some(len) = s.tether_length_m.filter(|v| v.is_finite()) {
            self.length_m = Some(len);
        }
        let mut n = 0;
        if let Some(tension) = s.winch_tension_n.filter(|v| v.is_finite()) {
            if let Some(a) = l.allowable_tension_n {
                let th = (Some(l.tension_caution_fraction * a), Some(a));
                n += self.update(CheckName::Tension, Sense::Above, t, tension, th);
            }
            let slack = l.slack_fraction * l.net_buoyancy_n;
            n += self.update(
                CheckName::Slack,
                Sense::Below,
                t,
                tension,
                (None, Some(slack)),
            );
        }
        if s.wind_speed_m_s.is_some() {
            if let (Some((mean, gust)), Some(max)) = (self.wind_now, l.max_operating_wind_m_s) {
                let th = (Some(l.wind_caution_fraction * max), Some(max));
                n += self.update(CheckName::Wind, Sense::Above, t, mean, th);
                if let Some(g) = l.max_gust_m_s {
                    let th = (Some(l.wind_caution_fraction * g), Some(g));
                    n += self.update(CheckName::Gust, Sense::Above, t, gust, th);
                }
            } else if let (Some((_, gust)), Some(g)) = (self.wind_now, l.max_gust_m_s) {
                let th = (Some(l.wind_caution_fraction * g), Some(g));
                n += self.update(CheckName::Gust, Sense::Above, t, gust, th);
            }
        }
        if let (Some(rate), Some(len), Some((mean, gust)), Some(c)) = (
            s.winch_rate_m_s.filter(|v| v.is_finite()),
            self.length_m,
            self.wind_now,
            self.model.ceiling.clone(),
        ) {
            let ceiling = c.ceiling_m_s(len, mean).min(c.ceiling_m_s(len, gust));
            let th = (Some(l.payout_caution_fraction * ceiling), Some(ceiling));
            n += self.update(CheckName::PayoutRate, Sense::Above, t, rate, th);
        }
        if let (Some(len), Some(plan)) = (s.tether_length_m, &self.model.plan) {
            let ahead = plan.ahead_fraction(t, len);
            if ahead.is_finite() {
                let th = (Some(l.plan_ahead_fraction), None);
                n += self.update(CheckName::Plan, Sense::Above, t, ahead, th);
            }
        }
        Pushed::Evaluated { transitions: n }
    }

    /// Updates one check's value and both its levels; returns the number
    /// of transitions.
    fn update(
        &mut self,
        name: CheckName,
        sense: Sense,
        t: f64,
        value: f64,
        (caution_at, stop_at): (Option<f64>, Option<f64>),
    ) -> u32 {
        let dwell = self.model.limits.dwell;
        let c = &mut self.checks[name.index()];
        c.value = Some(value);
        c.value_time_s = t;
        c.caution_at = caution_at;
        c.stop_at = stop_at;
        let mut transitions = Vec::new();
        if let Some(th) = caution_at {
            transitions.push((
                Level::Caution,
                c.caution.update(&dwell, sense, t, value, th),
            ));
        }
        if let Some(th) = stop_at {
            transitions.push((Level::Stop, c.stop.update(&dwell, sense, t, value, th)));
        }
        let mut n = 0;
        for (level, tr) in transitions {
            match tr {
                Transition::None => continue,
                Transition::Raised => self.raise(name, level, t),
                Transition::Cleared => self.clear(name, level, t),
            }
            n += 1;
        }
        n
    }

    fn raise(&mut self, check: CheckName, level: Level, t: f64) {
        let index = self.alarms.len();
        self.alarms.push(Alarm {
            check,
            level,
            raised_at_s: t,
            cleared_at_s: None,
            acknowledged_at_s: None,
        });
        let c = &mut self.checks[check.index()];
        if level == Level::Stop {
            c.stop_alarm = Some(index);
            c.unacknowledged_stops += 1;
        } else {
            c.caution_alarm = Some(index);
        }
    }

    fn clear(&mut self, check: CheckName, level: Level, t: f64) {
        let c = &mut self.checks[check.index()];
        let open = if level == Level::Stop {
            c.stop_alarm.take()
        } else {
            c.caution_alarm.take()
        };
        if let Some(i) = open {
            self.alarms[i].cleared_at_s = Some(t);
        }
    }

    /// Acknowledges every alarm not yet acknowledged, at the last sample's
    /// time (0 before any); returns how many.
    pub fn acknowledge(&mut self) -> usize {
        self.acknowledge_at(self.last_sample_time_s.unwrap_or(0.0))
    }

    /// Acknowledges at sample time `time_s` (a replayed acknowledgement).
    pub fn acknowledge_at(&mut self, time_s: f64) -> usize {
        let mut n = 0;
        for a in self
            .alarms
            .iter_mut()
            .filter(|a| a.acknowledged_at_s.is_none())
        {
            a.acknowledged_at_s = Some(time_s);
            n += 1;
        }
        for c in &mut self.checks {
            c.unacknowledged_stops = 0;
        }
        n
    }

    /// The flight at `since_last_arrival_s` seconds (caller's clock) after
    /// the last sample arrived (`None`: none has).
    pub fn status(&self, since_last_arrival_s: Option<f64>) -> Status {
        let l = &self.model.limits;
        let last = self.last_sample_time_s;
        let checks: Vec<CheckStatus> = self
            .model
            .checks()
            .into_iter()
            .map(|name| {
                if name == CheckName::Data {
                    let stale = since_last_arrival_s.is_none_or(|s| !(s <= l.stale_after_s));
                    return CheckStatus {
                        name,
                        state: if stale {
                            Level::Unavailable
                        } else {
                            Level::Normal
                        },
                        value: since_last_arrival_s,
                        caution_at: None,
                        stop_at: None,
                    };
                }
                let c = &self.checks[name.index()];
                let fresh = c.value.is_some()
                    && last.is_some_and(|t| t - c.value_time_s <= l.stale_after_s);
                let state = if c.stop.active || c.unacknowledged_stops > 0 {
                    Level::Stop
                } else if !fresh {
                    Level::Unavailable
                } else if c.caution.active {
                    Level::Caution
                } else {
                    Level::Normal
                };
                CheckStatus {
                    name,
                    state,
                    value: c.value,
                    caution_at: c.caution_at,
                    stop_at: c.stop_at,
                }
            })
            .collect();
        let state = checks
            .iter()
            .map(|c| c.state)
            .max()
            .unwrap_or(Level::Unavailable);
        Status { state, checks }
    }
}
