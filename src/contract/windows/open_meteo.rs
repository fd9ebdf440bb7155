//! Open-Meteo's hourly forecast JSON, as its API returns it
//! (<https://open-meteo.com/en/docs>): `hourly.time` (ISO 8601 local times,
//! or Unix seconds with `timeformat=unixtime`), `hourly.wind_speed_<h>m`
//! (10, 80, 120, 180 m), `hourly.wind_gusts_10m`, `hourly.wind_direction_*`
//! (not used: the tether's plane follows the wind), the units in
//! `hourly_units` (`km/h` by default, `m/s`, `kn`, `mp/h`). The ensemble API
//! (<https://open-meteo.com/en/docs/ensemble-api>) gives the control run
//! under the plain keys and the members under `…_member01`, `…_member02`, …
//! The older names `windspeed_10m`, `windgusts_10m` are read alike. Other
//! variables are ignored; an hour with no speed at any height is left out
//! (and said so); `null` values are missing values.

use std::collections::BTreeMap;

use serde_json::Value;

use crate::contract::windows::forecast::{Member, ParsedForecast, RawPeriod, field};
use crate::contract::windows::time::{TimeStyle, parse_iso_zoned};
use crate::numerics::forecast::units::SpeedUnit;
use crate::numerics::params::InvalidInput;

/// What a key of `hourly` holds.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Series {
    Speed(f64),
    Gust(f64),
}

/// `wind_speed_80m_member03` → (Speed(80), "member03").
fn classify(key: &str) -> Option<(Series, String)> {
    let (base, member) = match key.find("_member") {
        Some(i) => (&key[..i], key[i + 1..].to_string()),
        None => (key, "control".to_string()),
    };
    let (kind, rest) = if let Some(r) = base
        .strip_prefix("wind_speed_")
        .or_else(|| base.strip_prefix("windspeed_"))
    {
        (0, r)
    } else if let Some(r) = base
        .strip_prefix("wind_gusts_")
        .or_else(|| base.strip_prefix("windgusts_"))
    {
        (1, r)
    } else {
        return None;
    };
    let h: f64 = rest.strip_suffix('m')?.parse().ok()?;
    if !(h.is_finite() && h > 0.0) {
        return None;
    }
    if member != "control" && !(member.len() > 6 && member[6..].bytes().all(|b| b.is_ascii_digit()))
    {
        return None;
    }
    Some((
        if kind == 0 {
            Series::Speed(h)
        } else {
            Series::Gust(h)
        },
        member,
    ))
}

pub fn parse(data: &Value) -> Result<ParsedForecast, InvalidInput> {
    let obj = data.as_object().ok_or_else(|| {
        InvalidInput::new(
            "forecast.data",
            "must be the JSON object of an Open-Meteo hourly forecast (with `hourly` and `hourly_units`)",
        )
    })?;
    if obj.get("error").and_then(Value::as_bool) == Some(true) {
        return Err(InvalidInput::new(
            "forecast.data.error",
            format!(
                "the forecast is an Open-Meteo error: {}",
                obj.get("reason")
                    .and_then(Value::as_str)
                    .unwrap_or("no reason given")
            ),
        ));
    }
    let hourly = obj
        .get("hourly")
        .and_then(Value::as_object)
        .ok_or_else(|| {
            InvalidInput::new(
                field(".hourly"),
                "is required: the object of hourly series (`time`, `wind_speed_10m`, …)",
            )
        })?;
    let units = match obj.get("hourly_units") {
        None => None,
        Some(Value::Object(u)) => Some(u),
        Some(_) => {
            return Err(InvalidInput::new(
                field(".hourly_units"),
                "must be an object of unit strings",
            ));
        }
    };
    let mut notes = Vec::new();
    if units.is_none() {
        notes.push("hourly_units absent: speeds read in km/h, Open-Meteo's default".to_string());
    }
    let times = hourly
        .get("time")
        .and_then(Value::as_array)
        .ok_or_else(|| {
            InvalidInput::new(
                field(".hourly.time"),
                "is required: the list of the hours' times",
            )
        })?;
    let mut style = TimeStyle::Iso;
    let mut ts = Vec::with_capacity(times.len());
    for (i, t) in times.iter().enumerate() {
        let f = || field(&format!(".hourly.time[{i}]"));
        let v = match t {
            Value::String(s) => {
                let (t, zone) = parse_iso_zoned(s).ok_or_else(|| {
                    InvalidInput::new(
                        f(),
                        format!("`{s}` is not an ISO 8601 date-time (2026-12-03T14:00)"),
                    )
                })?;
                if let (Some(o), 0) = (zone, i) {
                    style = TimeStyle::IsoOffset(o);
                }
                t
            }
            Value::Number(n) => {
                style = TimeStyle::Unix;
                n.as_f64().filter(|x| x.is_finite()).ok_or_else(|| {
                    InvalidInput::new(f(), "must be an ISO 8601 date-time or Unix seconds")
                })?
            }
            _ => {
                return Err(InvalidInput::new(
                    f(),
                    "must be an ISO 8601 date-time or Unix seconds",
                ));
            }
        };
        if let Some(&prev) = ts.last()
            && v <= prev
        {
            return Err(InvalidInput::new(
                f(),
                format!("times must increase: {} is not after {}", t, times[i - 1]),
            ));
        }
        ts.push(v);
    }
    // member → (speeds by height, gusts by height), each a series of values.
    type Cols = Vec<(f64, Vec<Option<f64>>)>;
    let mut members: BTreeMap<String, (Cols, Cols)> = BTreeMap::new();
    for (key, v) in hourly {
        let Some((series, member)) = classify(key) else {
            continue;
        };
        let arr = v.as_array().ok_or_else(|| {
            InvalidInput::new(
                field(&format!(".hourly.{key}")),
                "must be a list of numbers (or null)",
            )
        })?;
        if arr.len() != ts.len() {
            return Err(InvalidInput::new(
                field(&format!(".hourly.{key}")),
                format!("has {} values for {} times", arr.len(), ts.len()),
            ));
        }
        let unit = match units {
            None => SpeedUnit::KilometresPerHour,
            Some(u) => {
                let label = u.get(key).and_then(Value::as_str).ok_or_else(|| {
                    InvalidInput::new(
                        field(&format!(".hourly_units.{key}")),
                        "is required: the unit of this series (m/s, km/h, kn or mp/h)",
                    )
                })?;
                SpeedUnit::from_label(label).ok_or_else(|| {
                    InvalidInput::new(
                        field(&format!(".hourly_units.{key}")),
                        format!("unknown unit `{label}`: expected m/s, km/h, kn or mp/h"),
                    )
                })?
            }
        };
        let mut values = Vec::with_capacity(arr.len());
        for (i, x) in arr.iter().enumerate() {
            values.push(match x {
                Value::Null => None,
                Value::Number(n) => {
                    let s = n
                        .as_f64()
                        .filter(|s| s.is_finite() && *s >= 0.0)
                        .ok_or_else(|| {
                            InvalidInput::new(
                                field(&format!(".hourly.{key}[{i}]")),
                                format!("must be a speed ≥ 0, got {n}"),
                            )
                        })?;
                    Some(unit.to_m_s(s))
                }
                other => {
                    return Err(InvalidInput::new(
                        field(&format!(".hourly.{key}[{i}]")),
                        format!("must be a number or null, got {other}"),
                    ));
                }
            });
        }
        let entry = members.entry(member).or_default();
        match series {
            Series::Speed(h) => entry.0.push((h, values)),
            Series::Gust(h) => entry.1.push((h, values)),
        }
    }
    if members.values().all(|(speeds, _)| speeds.is_empty()) {
        return Err(InvalidInput::new(
            field(".hourly"),
            "has no wind: expected wind_speed_10m, wind_speed_80m, wind_speed_120m or wind_speed_180m",
        ));
    }
    if ts.is_empty() {
        return Err(InvalidInput::new(
            field(".hourly.time"),
            "has no wind: no hours",
        ));
    }
    let mut out = Vec::new();
    // The control first, then the members in order.
    let mut names: Vec<String> = members.keys().cloned().collect();
    names.sort_by_key(|n| (n != "control", n.clone()));
    for name in names {
        let (mut speeds, mut gusts) = members.remove(&name).unwrap_or_default();
        if speeds.is_empty() {
            return Err(InvalidInput::new(
                field(".hourly"),
                format!("{name} has gusts but no wind speed"),
            ));
        }
        speeds.sort_by(|a, b| a.0.total_cmp(&b.0));
        gusts.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut periods = Vec::with_capacity(ts.len());
        let mut skipped = 0;
        let mut gustless = 0;
        for (i, &t) in ts.iter().enumerate() {
            let winds: Vec<(f64, f64)> = speeds
                .iter()
                .filter_map(|(h, v)| v[i].map(|u| (*h, u)))
                .collect();
            if winds.is_empty() {
                skipped += 1;
                continue;
            }
            let gust = gusts.iter().find_map(|(h, v)| v[i].map(|g| (*h, g)));
            if gust.is_none() && !gusts.is_empty() {
                gustless += 1;
            }
            let step = if i + 1 < ts.len() {
                ts[i + 1] - t
            } else if i > 0 {
                t - ts[i - 1]
            } else {
                3600.0
            };
            periods.push(RawPeriod {
                time: match &times[i] {
                    Value::String(s) => s.clone(),
                    _ => style.format(t),
                },
                start_s: t,
                end_s: t + step,
                winds,
                gust,
                group: None,
            });
        }
        if skipped > 0 {
            notes.push(format!(
                "{name}: {skipped} hour(s) with no wind speed at any height left out"
            ));
        }
        if gustless > 0 {
            notes.push(format!(
                "{name}: {gustless} hour(s) with no gust (null) judged in the mean wind only, without the gust's checks"
            ));
        }
        out.push(Member { name, periods });
    }
    Ok(ParsedForecast {
        members: out,
        origin_s: ts[0],
        style,
        notes,
    })
}
