//! The CSV form of a forecast: a header `time,height_m,speed_m_s,gust_m_s`
//! (the gust column may be left out, or empty in a row), then one row per
//! time and height; the rows of one time together, times in order (ISO 8601
//! or seconds). Blank lines and lines starting with `#` are skipped. Each
//! time is one period, to the next time (the last as long as the one
//! before it, an hour when alone); its gust is the one of its lowest height
//! that has one.

use crate::contract::windows::forecast::{Member, ParsedForecast, RawPeriod, field};
use crate::contract::windows::time::{TimeStyle, parse_iso_zoned};
use crate::numerics::params::InvalidInput;

const HEADER: [&str; 4] = ["time", "height_m", "speed_m_s", "gust_m_s"];

fn err(line: usize, msg: impl std::fmt::Display) -> InvalidInput {
    InvalidInput::new(field(&format!(" line {line}")), msg)
}

fn number(line: usize, name: &str, s: &str) -> Result<f64, InvalidInput> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| err(line, format!("{name} `{}` is not a number", s.trim())))?;
    if !v.is_finite() || v < 0.0 {
        return Err(err(
            line,
            format!("{name} must be a finite number ≥ 0, got {v}"),
        ));
    }
    Ok(v)
}

pub fn parse(text: &str) -> Result<ParsedForecast, InvalidInput> {
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let Some((hline, header)) = lines.next() else {
        return Err(InvalidInput::new(
            "forecast.data",
            "is empty: expected the header `time,height_m,speed_m_s,gust_m_s` and rows",
        ));
    };
    let cols: Vec<&str> = header.split(',').map(str::trim).collect();
    if !(cols == HEADER || cols == HEADER[..3]) {
        return Err(err(
            hline,
            format!("the header must be `time,height_m,speed_m_s,gust_m_s`, got `{header}`"),
        ));
    }
    let mut style = TimeStyle::Iso;
    // (time text, t, line, winds, gust)
    let mut rows: Vec<(String, f64, usize, Vec<(f64, f64)>, Option<(f64, f64)>)> = Vec::new();
    for (n, line) in lines {
        let f: Vec<&str> = line.split(',').map(str::trim).collect();
        if f.len() != cols.len() && !(cols.len() == 4 && f.len() == 3) {
            return Err(err(
                n,
                format!(
                    "expected {} comma-separated values, got {}",
                    cols.len(),
                    f.len()
                ),
            ));
        }
        let t = match parse_iso_zoned(f[0]) {
            Some((t, zone)) => {
                // Times written with an offset are written back with the
                // first row's (ends and windows alike).
                if let (Some(o), true) = (zone, rows.is_empty()) {
                    style = TimeStyle::IsoOffset(o);
                }
                t
            }
            None => match f[0].parse::<f64>() {
                Ok(t) if t.is_finite() => {
                    style = TimeStyle::Unix;
                    t
                }
                _ => {
                    return Err(err(
                        n,
                        format!(
                            "time `{}` is neither an ISO 8601 date-time (2026-12-03T14:00) nor seconds",
                            f[0]
                        ),
                    ));
                }
            },
        };
        let z = number(n, "height_m", f[1])?;
        if z <= 0.0 {
            return Err(err(n, "height_m must be above 0"));
        }
        let u = number(n, "speed_m_s", f[2])?;
        let g = match f.get(3) {
            Some(s) if !s.is_empty() => Some(number(n, "gust_m_s", s)?),
            _ => None,
        };
        match rows.last_mut() {
            Some(last) if last.1 == t => {
                if last.3.iter().any(|w| w.0 == z) {
                    return Err(err(
                        n,
                        format!("height {z} m is given twice at time {}", f[0]),
                    ));
                }
                last.3.push((z, u));
                if let Some(g) = g
                    && last.4.is_none_or(|(zg, _)| z < zg)
                {
                    last.4 = Some((z, g));
                }
            }
            Some(last) if t < last.1 => {
                return Err(err(
                    n,
                    format!(
                        "time {} is before {} (line {}): rows must be in time order",
                        f[0], last.0, last.2
                    ),
                ));
            }
            _ => rows.push((f[0].to_string(), t, n, vec![(z, u)], g.map(|g| (z, g)))),
        }
    }
    if rows.is_empty() {
        return Err(InvalidInput::new(
            "forecast.data",
            "has no wind: the header is followed by no rows",
        ));
    }
    let mut periods = Vec::with_capacity(rows.len());
    for i in 0..rows.len() {
        let step = if i + 1 < rows.len() {
            rows[i + 1].1 - rows[i].1
        } else if i > 0 {
            rows[i].1 - rows[i - 1].1
        } else {
            3600.0
        };
        let (time, t, _, winds, gust) = rows[i].clone();
        periods.push(RawPeriod {
            time,
            start_s: t,
            end_s: t + step,
            winds,
            gust,
            group: None,
        });
    }
    let origin_s = periods[0].start_s;
    Ok(ParsedForecast {
        members: vec![Member {
            name: "control".into(),
            periods,
        }],
        origin_s,
        style,
        notes: vec![],
    })
}
