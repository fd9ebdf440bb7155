//! Telemetry in (issue 33): a batch of samples as `application/json` (an
//! array of [`TelemetrySampleInput`]), `text/csv` (a header of the same
//! names) or `text/plain` NMEA 0183 `$--MWV` lines from an anemometer,
//! each prefixed `time_s,` or taken at the arrival time.
//!
//! A sample that cannot be used is refused naming its line (1-based: the
//! array element, or the text line with a CSV's header as line 1) and its
//! field, and the good ones are kept ([`Parsed`]). A body that is not a
//! batch at all (not a JSON array, a CSV header without `time_s` or with
//! an unknown column, an unknown content type) is refused whole.
//!
//! NMEA: the sentence is checked (checksum, shape, `MWV`) by the `nmea`
//! crate; the speed is read again from its text as `f64` (the crate keeps
//! `f32`, 7 digits) and converted exactly: `N` knots × 1852/3600, `K` km/h
//! × 1000/3600, `S` mph × 1609.344/3600, `M` m/s as is. A sentence flagged
//! `V` (invalid) by the instrument is not used.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::contract::error::RequestError;
use crate::contract::json::parse_value;
use crate::numerics::monitor::Sample;
use crate::numerics::params::InvalidInput;

/// One telemetry sample. Only `time_s` is required.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, ToSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct TelemetrySampleInput {
    /// Seconds from the flight's start (the committed plan's t = 0).
    #[schema(minimum = 0.0, maximum = 10000000.0, example = 12.5)]
    pub time_s: f64,
    /// Tether length paid out (m).
    #[schema(minimum = 0.0, maximum = 1000000.0, example = 250.0)]
    pub tether_length_m: Option<f64>,
    /// Winch rate, positive paying out (m/s).
    #[schema(minimum = -1000.0, maximum = 1000.0, example = 2.0)]
    pub winch_rate_m_s: Option<f64>,
    /// Tension at the winch (N); a load cell may read slightly negative.
    #[schema(minimum = -1000000.0, maximum = 1000000000.0, example = 1800.0)]
    pub winch_tension_n: Option<f64>,
    /// Wind speed at the anemometer (m/s).
    #[schema(minimum = 0.0, maximum = 150.0, example = 6.2)]
    pub wind_speed_m_s: Option<f64>,
    /// Height of the anemometer (m).
    #[schema(minimum = 0.0, maximum = 10000.0, example = 10.0)]
    pub wind_height_m: Option<f64>,
    /// Altitude of the aerostat above the winch (m).
    #[schema(minimum = -1000.0, maximum = 100000.0, example = 240.0)]
    pub aerostat_altitude_m: Option<f64>,
}

/// The column names of a CSV batch, the fields of a JSON sample.
pub const FIELDS: [&str; 7] = [
    "time_s",
    "tether_length_m",
    "winch_rate_m_s",
    "winch_tension_n",
    "wind_speed_m_s",
    "wind_height_m",
    "aerostat_altitude_m",
];

/// The plausible range of each field, as in the schema.
const RANGES: [(f64, f64); 7] = [
    (0.0, 1e7),
    (0.0, 1e6),
    (-1000.0, 1000.0),
    (-1e6, 1e9),
    (0.0, 150.0),
    (0.0, 1e4),
    (-1000.0, 1e5),
];

/// Largest number of samples in one batch.
pub const MAX_BATCH_SAMPLES: usize = 200_000;

/// A sample refused.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct RejectedSampleOutput {
    /// 1-based: the array element (JSON) or the text line (CSV with its header as line 1, NMEA).
    pub line: usize,
    /// The field at fault (`time_s`, `wind_speed_m_s`, …; NMEA: `sentence`, `data_valid`, …).
    pub field: String,
    pub reason: String,
}

/// A parsed batch: the usable samples and the refused ones.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Parsed {
    pub samples: Vec<Sample>,
    pub rejected: Vec<RejectedSampleOutput>,
}

/// The batch's format, from its content type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Json,
    Csv,
    Nmea,
}

impl Format {
    /// From a `Content-Type` (parameters ignored); `None` when unknown.
    pub fn from_content_type(ct: &str) -> Option<Self> {
        let essence = ct
            .split(';')
            .next()
            .unwrap_or("")
            .trim()
            .to_ascii_lowercase();
        match essence.as_str() {
            "application/json" => Some(Self::Json),
            "text/csv" => Some(Self::Csv),
            "text/plain" => Some(Self::Nmea),
            _ => None,
        }
    }
}

impl Format {
    /// From the content itself, for feeds without a content type (MQTT
    /// payloads): JSON when it starts with `[` or `{`, NMEA when its first
    /// line holds a `$` sentence, CSV otherwise.
    pub fn sniff(payload: &[u8]) -> Self {
        let text = String::from_utf8_lossy(payload);
        let text = text.trim_start();
        if text.starts_with('[') || text.starts_with('{') {
            Self::Json
        } else if text.lines().next().is_some_and(|l| l.contains('$')) {
            Self::Nmea
        } else {
            Self::Csv
        }
    }
}

fn reject(line: usize, field: &str, reason: impl Into<String>) -> RejectedSampleOutput {
    RejectedSampleOutput {
        line,
        field: field.into(),
        reason: reason.into(),
    }
}

fn invalid(field: &str, reason: impl std::fmt::Display) -> RequestError {
    RequestError::Invalid(InvalidInput::new(field, reason))
}

/// Checks the ranges and makes the sample; `Err((field, reason))`.
fn checked(values: [Option<f64>; 7]) -> Result<Sample, (&'static str, String)> {
    for (i, v) in values.iter().enumerate() {
        let Some(v) = *v else {
            if i == 0 {
                return Err((FIELDS[0], "is required".into()));
            }
            continue;
        };
        let (lo, hi) = RANGES[i];
        if !(v.is_finite() && v >= lo && v <= hi) {
            return Err((FIELDS[i], format!("must be between {lo} and {hi}, got {v}")));
        }
    }
    Ok(Sample {
        time_s: values[0].unwrap_or(0.0),
        tether_length_m: values[1],
        winch_rate_m_s: values[2],
        winch_tension_n: values[3],
        wind_speed_m_s: values[4],
        wind_height_m: values[5],
        aerostat_altitude_m: values[6],
    })
}

impl TelemetrySampleInput {
    fn values(&self) -> [Option<f64>; 7] {
        [
            Some(self.time_s),
            self.tether_length_m,
            self.winch_rate_m_s,
            self.winch_tension_n,
            self.wind_speed_m_s,
            self.wind_height_m,
            self.aerostat_altitude_m,
        ]
    }
}

/// Parses a batch. `arrival_time_s`: the flight time at which it arrived,
/// for NMEA lines without a time.
pub fn parse_batch(
    format: Format,
    body: &[u8],
    arrival_time_s: f64,
) -> Result<Parsed, RequestError> {
    let parsed = match format {
        Format::Json => parse_json(body)?,
        Format::Csv => parse_csv(text(body)?)?,
        Format::Nmea => parse_nmea(text(body)?, arrival_time_s),
    };
    if parsed.samples.len() + parsed.rejected.len() > MAX_BATCH_SAMPLES {
        return Err(invalid(
            "body",
            format!("at most {MAX_BATCH_SAMPLES} samples per batch: send the rest in another"),
        ));
    }
    Ok(parsed)
}

fn text(body: &[u8]) -> Result<&str, RequestError> {
    std::str::from_utf8(body).map_err(|e| invalid("body", format!("is not UTF-8 text: {e}")))
}

fn parse_json(body: &[u8]) -> Result<Parsed, RequestError> {
    let value: serde_json::Value =
        serde_json::from_slice(body).map_err(|e| RequestError::Malformed(e.to_string()))?;
    let serde_json::Value::Array(items) = value else {
        return Err(invalid("body", "must be a JSON array of samples"));
    };
    if items.len() > MAX_BATCH_SAMPLES {
        return Err(invalid(
            "body",
            format!(
                "at most {MAX_BATCH_SAMPLES} samples per batch, got {}",
                items.len()
            ),
        ));
    }
    let mut out = Parsed::default();
    for (i, item) in items.iter().enumerate() {
        let line = i + 1;
        match parse_value::<TelemetrySampleInput>(item) {
            Ok(s) => match checked(s.values()) {
                Ok(s) => out.samples.push(s),
                Err((field, reason)) => out.rejected.push(reject(line, field, reason)),
            },
            Err(RequestError::Invalid(e)) => out.rejected.push(reject(line, &e.field, e.reason)),
            Err(e) => out.rejected.push(reject(line, "sample", e.to_string())),
        }
    }
    Ok(out)
}

fn parse_csv(text: &str) -> Result<Parsed, RequestError> {
    let mut lines = text.lines().enumerate();
    let header = loop {
        match lines.next() {
            Some((_, l)) if l.trim().is_empty() => continue,
            Some((_, l)) => break l,
            None => return Err(invalid("body", "an empty CSV: a header line is needed")),
        }
    };
    let mut columns = Vec::new();
    for name in header.split(',') {
        let name = name.trim().trim_matches('"');
        let Some(i) = FIELDS.iter().position(|f| *f == name) else {
            return Err(invalid(
                name,
                format!(
                    "unknown column in the CSV header; the columns are {}",
                    FIELDS.join(", ")
                ),
            ));
        };
        if columns.contains(&i) {
            return Err(invalid(name, "appears twice in the CSV header"));
        }
        columns.push(i);
    }
    if !columns.contains(&0) {
        return Err(invalid(
            "time_s",
            "the CSV header must name a time_s column",
        ));
    }
    let mut out = Parsed::default();
    for (i, l) in lines {
        let line = i + 1;
        if l.trim().is_empty() {
            continue;
        }
        let cells: Vec<&str> = l.split(',').collect();
        if cells.len() != columns.len() {
            out.rejected.push(reject(
                line,
                "line",
                format!("has {} cells, the header {}", cells.len(), columns.len()),
            ));
            continue;
        }
        let mut values = [None; 7];
        let mut bad = None;
        for (cell, &col) in cells.iter().zip(&columns) {
            let cell = cell.trim();
            if cell.is_empty() {
                continue;
            }
            match cell.parse::<f64>() {
                Ok(v) => values[col] = Some(v),
                Err(_) => {
                    bad = Some((FIELDS[col], format!("is not a number: {cell:?}")));
                    break;
                }
            }
        }
        let result = match bad {
            Some(b) => Err(b),
            None => checked(values),
        };
        match result {
            Ok(s) => out.samples.push(s),
            Err((field, reason)) => out.rejected.push(reject(line, field, reason)),
        }
    }
    Ok(out)
}

/// Metres per second per unit of an MWV unit letter (exact).
pub fn mwv_unit_m_s(letter: &str) -> Option<f64> {
    match letter {
        "M" => Some(1.0),
        "N" => Some(1852.0 / 3600.0),
        "K" => Some(1000.0 / 3600.0),
        "S" => Some(1609.344 / 3600.0),
        _ => None,
    }
}

/// One `$--MWV` sentence to a wind speed (m/s); `Err((field, reason))`.
pub fn mwv_speed_m_s(sentence: &str) -> Result<f64, (&'static str, String)> {
    let parsed =
        nmea::parse_str(sentence).map_err(|e| ("sentence", format!("not NMEA 0183: {e}")))?;
    let nmea::ParseResult::MWV(data) = parsed else {
        return Err((
            "sentence",
            format!(
                "only $--MWV (wind speed and angle) is read, got {:?}",
                parsed_kind(sentence)
            ),
        ));
    };
    if !data.data_valid {
        return Err((
            "data_valid",
            "flagged V (not valid) by the instrument: not used".into(),
        ));
    }
    // the fields again as text: direction, reference, speed, unit, status
    let body = nmea::parse_nmea_sentence(sentence)
        .map_err(|e| ("sentence", format!("not NMEA 0183: {e}")))?
        .data;
    let fields: Vec<&str> = body.split(',').collect();
    let (speed, unit) = match (fields.get(2), fields.get(3)) {
        (Some(s), Some(u)) if !s.is_empty() => (*s, *u),
        _ => return Err(("wind_speed", "the sentence has no wind speed".into())),
    };
    let factor = mwv_unit_m_s(unit).ok_or((
        "wind_speed_units",
        format!("unit letter {unit:?}: expected N (knots), M (m/s), K (km/h) or S (mph)"),
    ))?;
    let v: f64 = speed
        .parse()
        .map_err(|_| ("wind_speed", format!("is not a number: {speed:?}")))?;
    let v = v * factor;
    if !(v.is_finite() && (0.0..=150.0).contains(&v)) {
        return Err((
            "wind_speed",
            format!("must be between 0 and 150 m/s, got {v}"),
        ));
    }
    Ok(v)
}

fn parsed_kind(sentence: &str) -> String {
    sentence.get(3..6).unwrap_or("?").to_string()
}

fn parse_nmea(text: &str, arrival_time_s: f64) -> Parsed {
    let mut out = Parsed::default();
    for (i, l) in text.lines().enumerate() {
        let line = i + 1;
        let l = l.trim();
        if l.is_empty() {
            continue;
        }
        let (time, sentence) = if l.starts_with('$') {
            (Ok(arrival_time_s), l)
        } else {
            match l.split_once(',') {
                Some((t, s)) => (
                    t.trim()
                        .parse::<f64>()
                        .map_err(|_| ("time_s", format!("is not a number: {:?}", t.trim()))),
                    s.trim(),
                ),
                None => (
                    Err((
                        "sentence",
                        "expected `time_s,$--MWV,…` or `$--MWV,…`".into(),
                    )),
                    l,
                ),
            }
        };
        let result = time.and_then(|t| {
            let speed = mwv_speed_m_s(sentence)?;
            let mut values = [None; 7];
            values[0] = Some(t);
            values[4] = Some(speed);
            checked(values)
        });
        match result {
            Ok(s) => out.samples.push(s),
            Err((field, reason)) => out.rejected.push(reject(line, field, reason)),
        }
    }
    out
}
