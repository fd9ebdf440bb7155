//! What a run keeps (SPEC §11 outputs): samples at a fixed interval,
//! shapes at stated times, slack events, and the extremes of the winch
//! and segment tensions, every step checked ([`Recorder`]).

use super::blocks::{V2, norm};
use super::integrator::{AirAt, InsideState};
use super::model::{Evaluation, Length};

/// One kept sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    pub time_s: f64,
    /// `|τ(0)|` (N).
    pub winch_tension_n: f64,
    /// `|τ(L)|` (N).
    pub top_tension_n: f64,
    pub aerostat_altitude_m: f64,
    pub aerostat_downwind_m: f64,
    /// Unstretched length (m).
    pub length_m: f64,
    /// Wind at the aerostat (m/s).
    pub aerostat_wind_m_s: f64,
    /// Wind at the fixed probe point ([`super::Run::wind_probe`]) (m/s).
    pub probe_wind_m_s: f64,
}

/// One node of a kept shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeNode {
    /// Unstretched arc length from the winch (m).
    pub s_m: f64,
    pub x_m: f64,
    pub z_m: f64,
    /// Tension of the segment below the node (the winch tension at `s = 0`) (N).
    pub tension_n: f64,
}

/// The shape at one time.
#[derive(Clone, Debug, PartialEq)]
pub struct Shape {
    pub time_s: f64,
    pub nodes: Vec<ShapeNode>,
}

/// A time interval during which some segment carries no tension.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlackEvent {
    pub start_s: f64,
    /// `None`: still slack at the end of the run.
    pub end_s: Option<f64>,
    /// Lowest slack point seen (unstretched arc length from the winch, m).
    pub lowest_s_m: f64,
}

/// An extreme and when it happened.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Extreme {
    pub value: f64,
    pub time_s: f64,
}

/// Collects the outputs step by step (the evaluation must be of the
/// state at the time recorded).
pub(super) struct Recorder {
    pub samples: Vec<Sample>,
    pub shapes: Vec<Shape>,
    pub slack_events: Vec<SlackEvent>,
    pub peak_winch: Extreme,
    pub min_winch: Extreme,
    pub peak: Extreme,
    /// Lowest aerostat altitude at any step (m).
    pub min_altitude: Extreme,
    sample_interval_s: f64,
    next_sample: f64,
    shape_times: Vec<f64>,
    next_shape: usize,
    /// Half the step: a shape is kept at the step nearest its time.
    half_step_s: f64,
    /// The fixed point where the wind is probed `(x, z)` (m).
    probe: V2,
}

impl Recorder {
    pub fn new(
        t0: f64,
        sample_interval_s: f64,
        shape_times_s: &[f64],
        step_s: f64,
        probe: V2,
    ) -> Self {
        let mut shape_times = shape_times_s.to_vec();
        shape_times.sort_by(f64::total_cmp);
        let start = |value: f64| Extreme { value, time_s: t0 };
        Self {
            samples: Vec::new(),
            shapes: Vec::new(),
            slack_events: Vec::new(),
            peak_winch: start(f64::NEG_INFINITY),
            min_winch: start(f64::INFINITY),
            peak: start(f64::NEG_INFINITY),
            min_altitude: start(f64::INFINITY),
            sample_interval_s,
            next_sample: t0,
            shape_times,
            next_shape: 0,
            half_step_s: 0.5 * step_s,
            probe,
        }
    }

    /// Takes the extremes of the sub-step ends inside an outer step (no
    /// sample: samples stay on the step grid).
    pub fn record_inside(&mut self, inside: &[InsideState]) {
        for s in inside {
            self.note_extremes(
                s.time_s,
                s.winch_tension_n,
                s.max_tension_n,
                s.aerostat_altitude_m,
            );
        }
    }

    /// Updates the extremes with one state's winch tension, largest segment
    /// tension and aerostat altitude at `t`.
    fn note_extremes(&mut self, t: f64, winch: f64, largest: f64, altitude: f64) {
        let at = |value: f64| Extreme { value, time_s: t };
        if winch > self.peak_winch.value {
            self.peak_winch = at(winch);
        }
        if winch < self.min_winch.value {
            self.min_winch = at(winch);
        }
        if largest > self.peak.value {
            self.peak = at(largest);
        }
        if altitude < self.min_altitude.value {
            self.min_altitude = at(altitude);
        }
    }

    /// Records the state `x` at `t` of length `len`, with its evaluation
    /// `ev` and the wind `air` at `t`; `force_sample` keeps a sample
    /// whatever the interval (the last step).
    pub fn record(
        &mut self,
        t: f64,
        len: Length,
        x: &[V2],
        ev: &Evaluation,
        air: &AirAt,
        force_sample: bool,
    ) {
        let n = x.len();
        let winch = norm(ev.winch_force);
        let l = len.length_m / n as f64;
        let mut lowest_slack = None;
        let mut largest = f64::NEG_INFINITY;
        for (j, &tj) in ev.tension[..n].iter().enumerate() {
            largest = largest.max(tj);
            if tj <= 0.0 && lowest_slack.is_none() {
                lowest_slack = Some((j as f64 + 0.5) * l);
            }
        }
        let top = x[n - 1];
        self.note_extremes(t, winch, largest, top[1]);
        match (lowest_slack, self.slack_events.last_mut()) {
            (Some(s), Some(e)) if e.end_s.is_none() => e.lowest_s_m = e.lowest_s_m.min(s),
            (Some(s), _) => self.slack_events.push(SlackEvent {
                start_s: t,
                end_s: None,
                lowest_s_m: s,
            }),
            (None, Some(e)) if e.end_s.is_none() => e.end_s = Some(t),
            _ => {}
        }
        let eps = 1e-9 * self.sample_interval_s;
        if force_sample || t >= self.next_sample - eps {
            self.samples.push(Sample {
                time_s: t,
                winch_tension_n: winch,
                top_tension_n: norm(ev.top_force),
                aerostat_altitude_m: top[1],
                aerostat_downwind_m: top[0],
                length_m: len.length_m,
                aerostat_wind_m_s: air.speed(top[0], top[1]),
                probe_wind_m_s: air.speed(self.probe[0], self.probe[1]),
            });
            while self.next_sample <= t + eps {
                self.next_sample += self.sample_interval_s;
            }
        }
        while self.next_shape < self.shape_times.len()
            && self.shape_times[self.next_shape] <= t + self.half_step_s
        {
            let mut nodes = Vec::with_capacity(n + 1);
            nodes.push(ShapeNode {
                s_m: 0.0,
                x_m: 0.0,
                z_m: 0.0,
                tension_n: winch,
            });
            for (i, r) in x.iter().enumerate() {
                nodes.push(ShapeNode {
                    s_m: (i + 1) as f64 * l,
                    x_m: r[0],
                    z_m: r[1],
                    tension_n: ev.tension[i],
                });
            }
            self.shapes.push(Shape { time_s: t, nodes });
            self.next_shape += 1;
        }
    }
}
