//! A forecast as a request gives it ([`ForecastInput`]: its format and
//! data) and as the parsers read it ([`ParsedForecast`]: members of
//! periods of winds at heights). Below the request types (`dto`, and the
//! plan's `source`), the dispatch on the format (`source`) and the
//! parsers of each format (`open_meteo`, `aviation`, `csv`).

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::contract::windows::time::TimeStyle;

/// The source format of `forecast.data`.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, ToSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum ForecastFormat {
    /// The JSON object of an Open-Meteo hourly forecast (or of its ensemble API).
    OpenMeteo,
    /// The text of one METAR report.
    Metar,
    /// The text of one TAF report.
    Taf,
    /// CSV text: `time,height_m,speed_m_s,gust_m_s` rows.
    Csv,
}

impl ForecastFormat {
    pub fn describe(self) -> &'static str {
        match self {
            Self::OpenMeteo => "Open-Meteo forecast",
            Self::Metar => "METAR report",
            Self::Taf => "TAF report",
            Self::Csv => "CSV forecast",
        }
    }
}

/// A forecast as it comes.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct ForecastInput {
    pub format: ForecastFormat,
    /// `open_meteo`: the JSON object as the API returns it; `metar`, `taf`,
    /// `csv`: the text, as a JSON string.
    #[schema(schema_with = data_schema)]
    pub data: serde_json::Value,
    /// Roughness length z0 of the log law through an hour with one height
    /// (m); default 0.03 (open terrain).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = 0.03, minimum = 0.000001, maximum = 10.0)]
    pub roughness_length_m: Option<f64>,
}

/// `forecast.data`'s schema: an object (`open_meteo`) or a string (the
/// text formats).
fn data_schema() -> utoipa::openapi::schema::Schema {
    use utoipa::openapi::schema::{ObjectBuilder, OneOfBuilder, Schema, Type};
    Schema::OneOf(
        OneOfBuilder::new()
            .item(
                ObjectBuilder::new()
                    .schema_type(Type::Object)
                    .description(Some("`open_meteo`: the JSON object as the API returns it")),
            )
            .item(
                ObjectBuilder::new()
                    .schema_type(Type::String)
                    .description(Some("`metar`, `taf`, `csv`: the report's text")),
            )
            .build(),
    )
}

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
