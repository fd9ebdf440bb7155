//! METAR and TAF reports (parsed by the `metar-taf-parser` crate): the
//! wind group `dddffGggKT` / `MPS` / `MPH` (`VRB` a variable direction, the
//! speed kept; `00000KT` calm), read at 10 m (the standard anemometer
//! height). A METAR is an observation: one period, the hour after it. A TAF
//! gives one period per group with a wind: the base forecast from the
//! validity's start to the first `FM` (or the validity's end), each `FM` to
//! the next, each `BECMG` from its start to the next `FM` or the end (the new
//! wind then holds), each `TEMPO` and `PROB` over its own period (they
//! overlap the others: a time is judged by every group covering it). An
//! `FM` group without a wind is refused (it replaces the whole forecast);
//! a `BECMG`, `TEMPO` or `PROB` group without one leaves the wind as it
//! was. Times
//! are day-of-month, hour, minute (`DDHHMMZ`); a report crossing the end of
//! a month is taken to cross it after its issue day. Lead times count from
//! the issue time.

use metar_taf_parser::metar::models::wind::{Wind, WindUnit};
use metar_taf_parser::taf::models::forecast::TafForecastKind;

use crate::contract::windows::forecast::{Member, ParsedForecast, RawPeriod};
use crate::contract::windows::time::TimeStyle;
use crate::numerics::forecast::units::SpeedUnit;
use crate::numerics::params::InvalidInput;

/// The height of a surface wind report (m).
pub const ANEMOMETER_HEIGHT_M: f64 = 10.0;

fn speed(unit: &WindUnit, v: u16) -> f64 {
    match unit {
        WindUnit::KT => SpeedUnit::Knots,
        WindUnit::MPS => SpeedUnit::MetresPerSecond,
        WindUnit::MPH => SpeedUnit::MilesPerHour,
    }
    .to_m_s(f64::from(v))
}

/// The wind of a group: `(winds, gust)`; `Err` for `/////KT`.
fn wind_of(w: &Wind, what: &str) -> Result<(Vec<(f64, f64)>, Option<(f64, f64)>), InvalidInput> {
    if w.indeterminate {
        return Err(InvalidInput::new(
            "forecast.data",
            format!("{what}: the wind group is not determinable (/////)"),
        ));
    }
    Ok((
        vec![(ANEMOMETER_HEIGHT_M, speed(&w.unit, w.speed))],
        w.gust.map(|g| (ANEMOMETER_HEIGHT_M, speed(&w.unit, g))),
    ))
}

/// Day, hour and minute on the report's axis (s); days before `day0` are in
/// the next month of `day0` days.
fn axis(day0: u8, (d, h, m): (u8, u8, u8)) -> f64 {
    let d = if d < day0 {
        i64::from(d) + i64::from(day0)
    } else {
        i64::from(d)
    };
    (d * 86_400 + i64::from(h) * 3600 + i64::from(m) * 60) as f64
}

fn text(style: TimeStyle, t: f64) -> String {
    style.format(t)
}

pub fn parse_metar(s: &str) -> Result<ParsedForecast, InvalidInput> {
    let m = metar_taf_parser::parse_metar(s.trim())
        .map_err(|e| InvalidInput::new("forecast.data", format!("is not a METAR report: {e}")))?;
    let w = m.wind.as_ref().ok_or_else(|| {
        InvalidInput::new(
            "forecast.data",
            "has no wind: the METAR has no wind group (dddffKT)",
        )
    })?;
    let (winds, gust) = wind_of(w, "METAR")?;
    let (day0, t) = match &m.time {
        Some(t) => (t.day, (t.day, t.hour, t.minute)),
        None => {
            return Err(InvalidInput::new(
                "forecast.data",
                "the METAR has no time group (DDHHMMZ)",
            ));
        }
    };
    // One observation never crosses a month end.
    let style = TimeStyle::Aviation {
        month_days: i64::MAX,
    };
    let start = axis(day0, t);
    Ok(ParsedForecast {
        members: vec![Member {
            name: "control".into(),
            periods: vec![RawPeriod {
                time: text(style, start),
                start_s: start,
                end_s: start + 3600.0,
                winds,
                gust,
                group: Some("metar".into()),
            }],
        }],
        origin_s: start,
        style,
        notes: vec!["METAR: an observation, taken to hold for the hour after it".into()],
    })
}

pub fn parse_taf(s: &str) -> Result<ParsedForecast, InvalidInput> {
    let taf = metar_taf_parser::parse_taf(s.trim())
        .map_err(|e| InvalidInput::new("forecast.data", format!("is not a TAF report: {e}")))?;
    let v = taf.validity.as_ref().ok_or_else(|| {
        InvalidInput::new("forecast.data", "the TAF has no validity group (DDHH/DDHH)")
    })?;
    let day0 = taf.issued_at.as_ref().map_or(v.from_day, |i| i.day);
    // Days before the issue day are in the next month (of `day0` days).
    let mut days = vec![v.from_day, v.to_day];
    for f in &taf.forecasts {
        days.extend(f.from.map(|t| t.0));
        days.extend(
            f.period
                .as_ref()
                .map(|p| [p.from.0, p.to.0])
                .into_iter()
                .flatten(),
        );
    }
    let style = TimeStyle::Aviation {
        month_days: if days.iter().any(|d| *d < day0) {
            i64::from(day0)
        } else {
            i64::MAX
        },
    };
    let valid_from = axis(day0, (v.from_day, v.from_hour, 0));
    let valid_to = axis(day0, (v.to_day, v.to_hour, 0));
    if valid_to <= valid_from {
        return Err(InvalidInput::new(
            "forecast.data",
            format!(
                "the TAF's validity {:02}{:02}/{:02}{:02} ends before it starts",
                v.from_day, v.from_hour, v.to_day, v.to_hour
            ),
        ));
    }
    let origin = taf
        .issued_at
        .as_ref()
        .map_or(valid_from, |i| axis(day0, (i.day, i.hour, i.minute)));
    // Start of each group; FM groups end at the next FM.
    let starts: Vec<f64> = taf
        .forecasts
        .iter()
        .map(|f| match f.kind {
            TafForecastKind::Base => valid_from,
            TafForecastKind::FM => f.from.map_or(valid_from, |t| axis(day0, t)),
            _ => f.period.as_ref().map_or(valid_from, |p| axis(day0, p.from)),
        })
        .collect();
    let next_fm = |after: f64| {
        taf.forecasts
            .iter()
            .zip(&starts)
            .filter(|(f, s)| f.kind == TafForecastKind::FM && **s > after)
            .map(|(_, s)| *s)
            .fold(valid_to, f64::min)
    };
    let mut periods = Vec::new();
    let mut last_start = f64::NEG_INFINITY;
    for (i, (f, &start)) in taf.forecasts.iter().zip(&starts).enumerate() {
        let (group, end) = match f.kind {
            TafForecastKind::Base => ("base", next_fm(start)),
            TafForecastKind::FM => ("fm", next_fm(start)),
            TafForecastKind::BECMG => ("becmg", next_fm(start)),
            TafForecastKind::TEMPO => (
                "tempo",
                f.period.as_ref().map_or(valid_to, |p| axis(day0, p.to)),
            ),
            TafForecastKind::PROB => (
                "prob",
                f.period.as_ref().map_or(valid_to, |p| axis(day0, p.to)),
            ),
        };
        if start < last_start {
            return Err(InvalidInput::new(
                "forecast.data",
                format!(
                    "TAF group {} ({group}) starts at {} before the group before it ({}): groups must be in time order",
                    i + 1,
                    text(style, start),
                    text(style, last_start)
                ),
            ));
        }
        last_start = start;
        let Some(w) = &f.wind else {
            // An FM group replaces the whole forecast from its time on
            // (ICAO Annex 3), so its wind is needed: without one, the time
            // after it would be judged by no wind at all. A BECMG, TEMPO or
            // PROB group may change other elements only; the wind before
            // it then holds.
            if f.kind == TafForecastKind::FM {
                return Err(InvalidInput::new(
                    "forecast.data",
                    format!(
                        "TAF group {} (fm, from {}) has no wind group that can be read (dddffKT, dddffGggKT, VRBffKT or MPS): an FM group starts a complete new forecast, so its wind is needed",
                        i + 1,
                        text(style, start)
                    ),
                ));
            }
            continue;
        };
        if end <= start {
            continue;
        }
        let (winds, gust) = wind_of(w, &format!("TAF group {} ({group})", i + 1))?;
        periods.push(RawPeriod {
            time: text(style, start),
            start_s: start,
            end_s: end.min(valid_to),
            winds,
            gust,
            group: Some(group.into()),
        });
    }
    if periods.is_empty() {
        return Err(InvalidInput::new(
            "forecast.data",
            "has no wind: no group of the TAF has a wind group",
        ));
    }
    Ok(ParsedForecast {
        members: vec![Member {
            name: "control".into(),
            periods,
        }],
        origin_s: origin,
        style,
        notes: vec![],
    })
}
