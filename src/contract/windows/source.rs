//! A forecast as it came (`{"format", "data"}`), parsed into members of
//! periods with their winds at heights (m/s) and gusts; each error names
//! `forecast.data` with the key and index (JSON) or the line (text).

use crate::contract::windows::dto::{ForecastFormat, ForecastInput};
use crate::contract::windows::time::TimeStyle;
use crate::contract::windows::{aviation, csv, open_meteo};
use crate::numerics::params::InvalidInput;

/// One period of one member: `[start_s, end_s)`.
#[derive(Clone, Debug, PartialEq)]
pub struct RawPeriod {
    /// The time as the source wrote it.
    pub time: String,
    pub start_s: f64,
    pub end_s: f64,
    /// `(height_m, speed_m_s)`.
    pub winds: Vec<(f64, f64)>,
    /// `(height_m, gust_m_s)`.
    pub gust: Option<(f64, f64)>,
    /// TAF: `base`, `fm`, `becmg`, `tempo` or `prob`.
    pub group: Option<String>,
}

/// One member (an ensemble has many; the first is the control).
#[derive(Clone, Debug, PartialEq)]
pub struct Member {
    /// `control`, `member01`, …
    pub name: String,
    pub periods: Vec<RawPeriod>,
}

/// A parsed forecast.
#[derive(Clone, Debug, PartialEq)]
pub struct ParsedForecast {
    pub members: Vec<Member>,
    /// Lead times count from here (s on the same axis as the periods).
    pub origin_s: f64,
    pub style: TimeStyle,
    /// What the parser assumed or left out.
    pub notes: Vec<String>,
}

/// The `forecast.data` field name with a suffix (`.hourly.time[3]`, ` line 4`).
pub fn field(suffix: &str) -> String {
    format!("forecast.data{suffix}")
}

/// Parses the forecast of a request.
pub fn parse_forecast(f: &ForecastInput) -> Result<ParsedForecast, InvalidInput> {
    let text = || {
        f.data.as_str().ok_or_else(|| {
            InvalidInput::new(
                "forecast.data",
                format!(
                    "must be the text of the {} as a JSON string",
                    f.format.describe()
                ),
            )
        })
    };
    let parsed = match f.format {
        ForecastFormat::OpenMeteo => open_meteo::parse(&f.data)?,
        ForecastFormat::Csv => csv::parse(text()?)?,
        ForecastFormat::Metar => aviation::parse_metar(text()?)?,
        ForecastFormat::Taf => aviation::parse_taf(text()?)?,
    };
    if parsed.members.iter().all(|m| m.periods.is_empty()) {
        return Err(InvalidInput::new(
            "forecast.data",
            "has no wind: no period with a wind speed",
        ));
    }
    Ok(parsed)
}
