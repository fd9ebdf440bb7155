//! The flight report (issue 33): `GET /api/v1/flights/{id}/report` as
//! JSON ([`FlightReportOutput`]), CSV ([`to_csv`]) or a printable,
//! self-contained HTML page ([`to_html`]).
//!
//! From the stored samples in time order: the committed schedule's length
//! at the sample times against the measured length (at most
//! [`MAX_TRACK_POINTS`] evenly picked samples, the last one kept), the
//! alarms with their raise, clear and acknowledgement times (the flight's,
//! as its monitor has them), and the peaks, each with the sample time it
//! was reached at (the first such sample): the largest and smallest winch
//! tension, the largest wind mean and gust (the monitor's figures: the
//! mean of the last 10 minutes and the largest 3 s mean of the last 10
//! minutes, after each sample), the largest payout rate (the largest
//! `winch_rate_m_s`; positive pays out) and the lowest aerostat altitude.
//! A peak of a quantity no sample carried is null.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::contract::flight::dto::{AlarmOutput, FlightLimitsOutput, FlightOutput};
use crate::numerics::monitor::window::WindWindow;
use crate::numerics::monitor::{PlanTrace, Sample};

/// Most points of the planned-against-measured track.
pub const MAX_TRACK_POINTS: usize = 1000;

/// One point of the track.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct TrackPointOutput {
    pub time_s: f64,
    /// The committed schedule's length at `time_s` (m); null without a schedule.
    pub planned_length_m: Option<f64>,
    /// The measured tether length (m).
    pub measured_length_m: f64,
}

/// A peak and the sample time it was reached at.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct PeakOutput {
    /// In the unit its name gives.
    pub value: f64,
    /// Sample time (s) of the first sample at this value.
    pub time_s: f64,
}

/// The flight's extremes; null when no sample carried the quantity.
#[derive(Clone, Debug, Default, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct ReportPeaksOutput {
    /// Largest winch tension (N).
    pub max_winch_tension_n: Option<PeakOutput>,
    /// Smallest winch tension (N).
    pub min_winch_tension_n: Option<PeakOutput>,
    /// Largest 10-minute mean wind at the anemometer (m/s).
    pub max_wind_mean_m_s: Option<PeakOutput>,
    /// Largest gust: the largest 3 s mean wind (m/s).
    pub max_gust_m_s: Option<PeakOutput>,
    /// Largest payout rate (`winch_rate_m_s`, positive paying out) (m/s).
    pub max_payout_rate_m_s: Option<PeakOutput>,
    /// Lowest aerostat altitude (m).
    pub min_aerostat_altitude_m: Option<PeakOutput>,
}

/// `GET /api/v1/flights/{id}/report`.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct FlightReportOutput {
    pub id: i64,
    pub name: String,
    pub created_at: String,
    pub ended_at: Option<String>,
    /// The state now (`normal`, `caution`, `stop` or `unavailable`).
    pub state: String,
    /// First and last sample time (s); null before any sample.
    pub first_sample_time_s: Option<f64>,
    pub last_sample_time_s: Option<f64>,
    /// Last minus first sample time (s); null before any sample.
    pub duration_s: Option<f64>,
    /// Samples stored.
    pub samples_received: u64,
    /// The committed plan's duration (s).
    pub plan_duration_s: Option<f64>,
    /// The committed plan's final length (m).
    pub plan_final_length_m: Option<f64>,
    pub peaks: ReportPeaksOutput,
    /// Every alarm raised, in the order raised.
    pub alarms: Vec<AlarmOutput>,
    /// Largest |measured − planned| length over the samples (m) and when.
    pub max_length_deviation_m: Option<PeakOutput>,
    /// Planned against measured length.
    pub track: Vec<TrackPointOutput>,
    pub limits: FlightLimitsOutput,
}

fn better(best: &mut Option<PeakOutput>, v: f64, t: f64, larger: bool) {
    let take = match best {
        None => true,
        Some(b) => {
            if larger {
                v > b.value
            } else {
                v < b.value
            }
        }
    };
    if take && v.is_finite() {
        *best = Some(PeakOutput {
            value: v,
            time_s: t,
        });
    }
}

/// The report of a flight from its answer (`flight`), its schedule, the
/// monitor's wind windows (s) and its samples in time order.
pub fn report(
    flight: &FlightOutput,
    plan: Option<&PlanTrace>,
    plan_duration_s: Option<f64>,
    wind_windows_s: (f64, f64),
    samples: &[Sample],
) -> FlightReportOutput {
    let mut peaks = ReportPeaksOutput::default();
    let mut wind = WindWindow::new(wind_windows_s.0, wind_windows_s.1);
    let mut deviation = None;
    let with_length: Vec<(f64, f64)> = samples
        .iter()
        .filter_map(|s| s.tether_length_m.map(|l| (s.time_s, l)))
        .collect();
    for s in samples {
        let t = s.time_s;
        if let Some(v) = s.winch_tension_n {
            better(&mut peaks.max_winch_tension_n, v, t, true);
            better(&mut peaks.min_winch_tension_n, v, t, false);
        }
        if let Some(v) = s.wind_speed_m_s.filter(|v| v.is_finite()) {
            let (mean, gust) = wind.push(t, v);
            better(&mut peaks.max_wind_mean_m_s, mean, t, true);
            better(&mut peaks.max_gust_m_s, gust, t, true);
        }
        if let Some(v) = s.winch_rate_m_s {
            better(&mut peaks.max_payout_rate_m_s, v, t, true);
        }
        if let Some(v) = s.aerostat_altitude_m {
            better(&mut peaks.min_aerostat_altitude_m, v, t, false);
        }
        if let (Some(p), Some(l)) = (plan, s.tether_length_m) {
            better(&mut deviation, (l - p.length_at_m(t)).abs(), t, true);
        }
    }
    let step = with_length.len().div_ceil(MAX_TRACK_POINTS).max(1);
    let mut track: Vec<TrackPointOutput> = with_length
        .iter()
        .enumerate()
        .filter(|(i, _)| i % step == 0 || *i + 1 == with_length.len())
        .map(|(_, &(t, l))| TrackPointOutput {
            time_s: t,
            planned_length_m: plan.map(|p| p.length_at_m(t)),
            measured_length_m: l,
        })
        .collect();
    track.dedup_by(|a, b| a.time_s == b.time_s);
    let first = samples.first().map(|s| s.time_s);
    let last = samples.last().map(|s| s.time_s);
    FlightReportOutput {
        id: flight.id,
        name: flight.name.clone(),
        created_at: flight.created_at.clone(),
        ended_at: flight.ended_at.clone(),
        state: flight.state.clone(),
        first_sample_time_s: first,
        last_sample_time_s: last,
        duration_s: first.zip(last).map(|(a, b)| b - a),
        samples_received: flight.samples_received,
        plan_duration_s,
        plan_final_length_m: plan.map(|p| p.length_at_m(f64::INFINITY)),
        peaks,
        alarms: flight.alarms.clone(),
        max_length_deviation_m: deviation,
        track,
        limits: flight.limits.clone(),
    }
}

/// The peaks as `(name, unit, peak)`, in the report's order.
pub fn peak_rows(p: &ReportPeaksOutput) -> [(&'static str, &'static str, Option<PeakOutput>); 6] {
    [
        ("max_winch_tension_n", "N", p.max_winch_tension_n),
        ("min_winch_tension_n", "N", p.min_winch_tension_n),
        ("max_wind_mean_m_s", "m/s", p.max_wind_mean_m_s),
        ("max_gust_m_s", "m/s", p.max_gust_m_s),
        ("max_payout_rate_m_s", "m/s", p.max_payout_rate_m_s),
        ("min_aerostat_altitude_m", "m", p.min_aerostat_altitude_m),
    ]
}

fn cell(v: Option<f64>) -> String {
    v.map(|v| format!("{v}")).unwrap_or_default()
}

/// Text as one CSV cell (quoted when it needs to be).
fn text_cell(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// The CSV header of [`to_csv`].
pub const CSV_HEADER: &str =
    "record,name,value,unit,time_s,planned_value,cleared_at_s,acknowledged_at_s";

/// The report as one CSV table, a record a line: `summary` (name, value,
/// unit), `peak` (name with its unit, value, unit, the sample time),
/// `alarm` (name `check/level`, `time_s` raised, then cleared and
/// acknowledged times), `track` (`tether_length_m`, measured value,
/// time, `planned_value`). Absent values are empty cells.
pub fn to_csv(r: &FlightReportOutput) -> String {
    let mut out = String::from(CSV_HEADER);
    out.push('\n');
    let mut line = |cells: [String; 8]| {
        out.push_str(&cells.join(","));
        out.push('\n');
    };
    let summary = |name: &str, v: Option<f64>, unit: &str| {
        [
            "summary".into(),
            name.into(),
            cell(v),
            unit.into(),
            String::new(),
            String::new(),
            String::new(),
            String::new(),
        ]
    };
    line([
        "summary".into(),
        "name".into(),
        text_cell(&r.name),
        String::new(),
        String::new(),
        String::new(),
        String::new(),
        String::new(),
    ]);
    line([
        "summary".into(),
        "state".into(),
        r.state.clone(),
        String::new(),
        String::new(),
        String::new(),
        String::new(),
        String::new(),
    ]);
    line(summary("duration_s", r.duration_s, "s"));
    line(summary(
        "samples_received",
        Some(r.samples_received as f64),
        "count",
    ));
    line(summary("first_sample_time_s", r.first_sample_time_s, "s"));
    line(summary("last_sample_time_s", r.last_sample_time_s, "s"));
    line(summary("plan_duration_s", r.plan_duration_s, "s"));
    for (name, unit, p) in peak_rows(&r.peaks) {
        line([
            "peak".into(),
            name.into(),
            cell(p.map(|p| p.value)),
            unit.into(),
            cell(p.map(|p| p.time_s)),
            String::new(),
            String::new(),
            String::new(),
        ]);
    }
    if let Some(d) = r.max_length_deviation_m {
        line([
            "peak".into(),
            "max_length_deviation_m".into(),
            cell(Some(d.value)),
            "m".into(),
            cell(Some(d.time_s)),
            String::new(),
            String::new(),
            String::new(),
        ]);
    }
    for a in &r.alarms {
        line([
            "alarm".into(),
            format!("{}/{}", a.check, a.level),
            String::new(),
            "s".into(),
            cell(Some(a.raised_at_s)),
            String::new(),
            cell(a.cleared_at_s),
            cell(a.acknowledged_at_s),
        ]);
    }
    for p in &r.track {
        line([
            "track".into(),
            "tether_length_m".into(),
            cell(Some(p.measured_length_m)),
            "m".into(),
            cell(Some(p.time_s)),
            cell(p.planned_length_m),
            String::new(),
            String::new(),
        ]);
    }
    out
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
        .replace('\'', "&#39;")
}

fn num(v: Option<f64>) -> String {
    v.map(|v| format!("{v}")).unwrap_or_else(|| "—".into())
}

/// An inline SVG of planned (dashed) against measured length.
fn chart(r: &FlightReportOutput) -> String {
    if r.track.len() < 2 {
        return "<p>No length measured yet.</p>".into();
    }
    let (w, h, m) = (720.0, 260.0, 40.0);
    let t0 = r.track[0].time_s;
    let t1 = r.track[r.track.len() - 1].time_s.max(t0 + 1e-9);
    let top = r
        .track
        .iter()
        .flat_map(|p| [Some(p.measured_length_m), p.planned_length_m])
        .flatten()
        .fold(1e-9, f64::max);
    let x = |t: f64| m + (t - t0) / (t1 - t0) * (w - 2.0 * m);
    let y = |l: f64| h - m - l / top * (h - 2.0 * m);
    let path = |f: &dyn Fn(&TrackPointOutput) -> Option<f64>| {
        r.track
            .iter()
            .filter_map(|p| f(p).map(|l| format!("{:.1},{:.1}", x(p.time_s), y(l))))
            .collect::<Vec<_>>()
            .join(" ")
    };
    format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" role=\"img\" \
         aria-label=\"planned against measured tether length\">\
         <rect x=\"{m}\" y=\"{m}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#999\"/>\
         <polyline fill=\"none\" stroke=\"#888\" stroke-dasharray=\"6 4\" points=\"{}\"/>\
         <polyline fill=\"none\" stroke=\"#0b5\" stroke-width=\"2\" points=\"{}\"/>\
         <text x=\"{m}\" y=\"{}\" font-size=\"12\">0 m</text>\
         <text x=\"{m}\" y=\"{}\" font-size=\"12\">{top:.1} m</text>\
         <text x=\"{m}\" y=\"{}\" font-size=\"12\">t = {t0} s</text>\
         <text x=\"{}\" y=\"{}\" font-size=\"12\" text-anchor=\"end\">t = {t1} s</text>\
         </svg><p class=\"key\">dashed: planned length; solid: measured length</p>",
        w - 2.0 * m,
        h - 2.0 * m,
        path(&|p| p.planned_length_m),
        path(&|p| Some(p.measured_length_m)),
        h - m + 14.0,
        m - 6.0,
        h - 6.0,
        w - m,
        h - 6.0,
    )
}

/// The report as a printable, self-contained HTML page (no scripts, no
/// external resources).
pub fn to_html(r: &FlightReportOutput) -> String {
    let mut peaks = String::new();
    for (name, unit, p) in peak_rows(&r.peaks) {
        peaks.push_str(&format!(
            "<tr><td>{name}</td><td class=\"n\">{}</td><td>{unit}</td><td class=\"n\">{}</td></tr>",
            num(p.map(|p| p.value)),
            num(p.map(|p| p.time_s)),
        ));
    }
    if let Some(d) = r.max_length_deviation_m {
        peaks.push_str(&format!(
            "<tr><td>max_length_deviation_m</td><td class=\"n\">{}</td><td>m</td><td class=\"n\">{}</td></tr>",
            d.value, d.time_s
        ));
    }
    let mut alarms = String::new();
    for a in &r.alarms {
        alarms.push_str(&format!(
            "<tr><td>{}</td><td>{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td></tr>",
            escape(&a.check),
            escape(&a.level),
            a.raised_at_s,
            num(a.cleared_at_s),
            num(a.acknowledged_at_s),
        ));
    }
    if r.alarms.is_empty() {
        alarms.push_str("<tr><td colspan=\"5\">No alarm was raised.</td></tr>");
    }
    let title = format!("Flight report: {}", escape(&r.name));
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{title}</title>\
         <style>body{{font-family:sans-serif;margin:2em;color:#111}}table{{border-collapse:collapse;margin:1em 0}}\
         td,th{{border:1px solid #aaa;padding:.2em .6em;text-align:left}}td.n{{text-align:right;font-variant-numeric:tabular-nums}}\
         .key{{font-size:.85em;color:#555}}@media print{{body{{margin:0}}svg{{max-width:100%}}}}</style></head><body>\
         <h1>{title}</h1>\
         <table><tr><th>flight id</th><td>{id}</td></tr><tr><th>created at</th><td>{created}</td></tr>\
         <tr><th>ended at</th><td>{ended}</td></tr><tr><th>state now</th><td>{state}</td></tr>\
         <tr><th>duration_s</th><td class=\"n\">{duration}</td></tr>\
         <tr><th>samples_received</th><td class=\"n\">{samples}</td></tr>\
         <tr><th>first_sample_time_s</th><td class=\"n\">{first}</td></tr>\
         <tr><th>last_sample_time_s</th><td class=\"n\">{last}</td></tr>\
         <tr><th>plan_duration_s</th><td class=\"n\">{plan}</td></tr></table>\
         <h2>Planned against measured length</h2>{chart}\
         <h2>Peaks</h2><table><tr><th>quantity</th><th>value</th><th>unit</th><th>time_s</th></tr>{peaks}</table>\
         <h2>Alarms</h2><table><tr><th>check</th><th>level</th><th>raised_at_s</th><th>cleared_at_s</th>\
         <th>acknowledged_at_s</th></tr>{alarms}</table></body></html>\n",
        id = r.id,
        created = escape(&r.created_at),
        ended = escape(r.ended_at.as_deref().unwrap_or("flying")),
        state = escape(&r.state),
        duration = num(r.duration_s),
        samples = r.samples_received,
        first = num(r.first_sample_time_s),
        last = num(r.last_sample_time_s),
        plan = num(r.plan_duration_s),
        chart = chart(r),
    )
}
