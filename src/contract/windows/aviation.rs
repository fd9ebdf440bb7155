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
//! was. A text holding several reports (a history, or a TAF and its
//! amendment) is split at each `METAR`, `SPECI` or `TAF` (or each line
//! opening with a station and a time) and the latest is judged, with a
//! note; read together, later groups would overwrite earlier ones. Times
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

/// The reports of a text that may hold several (a history pasted from a
/// weather service, an amended TAF after the first): split before each
/// word in `keywords` (`METAR`, `SPECI`, `TAF`) or, without one, before
/// each line that opens with a station and a time (`EGLL 051150Z`).
fn split_reports<'a>(s: &'a str, keywords: &[&str]) -> Vec<&'a str> {
    let s = s.trim();
    let word_at = |i: usize| {
        let before_ok = i == 0 || s[..i].ends_with(char::is_whitespace);
        before_ok
            && keywords
                .iter()
                .any(|k| s[i..].starts_with(k) && s[i + k.len()..].starts_with(char::is_whitespace))
    };
    let mut starts: Vec<usize> = s
        .char_indices()
        .map(|(i, _)| i)
        .filter(|&i| word_at(i))
        .collect();
    if starts.is_empty() {
        let mut at = 0;
        for line in s.split_inclusive('\n') {
            let b = line.trim_start().as_bytes();
            let opens = b.len() >= 12
                && b[..4].iter().all(u8::is_ascii_uppercase)
                && b[4] == b' '
                && b[5..11].iter().all(u8::is_ascii_digit)
                && b[11] == b'Z';
            if opens {
                starts.push(at);
            }
            at += line.len();
        }
    }
    // Text before the first report (a date line) stays with it.
    match starts.first_mut() {
        Some(first) => *first = 0,
        None => starts.push(0),
    }
    starts.push(s.len());
    starts
        .windows(2)
        .map(|w| s[w[0]..w[1]].trim())
        .filter(|r| !r.is_empty())
        .collect()
}

/// Of several reports, the latest (by its time on its own axis), with a
/// note naming it; one report as it is.
fn latest_of(
    text: &str,
    keywords: &[&str],
    what: &str,
    parse: fn(&str) -> Result<ParsedForecast, InvalidInput>,
) -> Result<ParsedForecast, InvalidInput> {
    let reports = split_reports(text, keywords);
    if reports.len() <= 1 {
        return parse(text);
    }
    let mut parsed = Vec::with_capacity(reports.len());
    for (i, r) in reports.iter().enumerate() {
        parsed.push(parse(r).map_err(|e| InvalidInput {
            field: e.field,
            reason: format!("{what} {} of {}: {}", i + 1, reports.len(), e.reason),
        })?);
    }
    let n = parsed.len();
    let mut latest = parsed
        .into_iter()
        .max_by(|a, b| a.origin_s.total_cmp(&b.origin_s))
        .expect("two or more reports");
    let at = latest.style.format(latest.origin_s);
    latest.notes.insert(
        0,
        format!("{n} {what} reports given: the latest, of {at}, is judged, the others left out"),
    );
    Ok(latest)
}

/// A METAR, or the latest of several.
pub fn parse_metars(s: &str) -> Result<ParsedForecast, InvalidInput> {
    latest_of(s, &["METAR", "SPECI"], "METAR", parse_metar)
}

/// A TAF, or the latest of several (an amendment after the first).
pub fn parse_tafs(s: &str) -> Result<ParsedForecast, InvalidInput> {
    latest_of(s, &["TAF"], "TAF", parse_taf)
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
