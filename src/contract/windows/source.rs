//! A forecast as it came (`{"format", "data"}`), parsed into members of
//! periods with their winds at heights (m/s) and gusts; each error names
//! `forecast.data` with the key and index (JSON) or the line (text).

use crate::contract::windows::dto::{ForecastFormat, ForecastInput};
pub use crate::contract::windows::forecast::{Member, ParsedForecast, RawPeriod, field};
use crate::contract::windows::{aviation, csv, open_meteo};
use crate::numerics::params::InvalidInput;

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
        ForecastFormat::Metar => aviation::parse_metars(text()?)?,
        ForecastFormat::Taf => aviation::parse_tafs(text()?)?,
    };
    if parsed.members.iter().all(|m| m.periods.is_empty()) {
        return Err(InvalidInput::new(
            "forecast.data",
            "has no wind: no period with a wind speed",
        ));
    }
    Ok(parsed)
}

/// A forecast as fetched from a source (`GET /api/v1/forecast`): the bytes
/// it answered made into the request's `forecast` object (the JSON object
/// for `open_meteo`, the text for the others) and parsed, so that what is
/// handed on is known to be readable. `Err`: why not, in plain words.
pub fn forecast_from_source(
    format: ForecastFormat,
    bytes: &[u8],
) -> Result<(ForecastInput, ParsedForecast), String> {
    let text = std::str::from_utf8(bytes)
        .map_err(|e| format!("the source answered text that is not UTF-8 ({e})"))?;
    let data = match format {
        ForecastFormat::OpenMeteo => {
            let v: serde_json::Value = serde_json::from_str(text)
                .map_err(|e| format!("the source answered no JSON ({e})"))?;
            if !v.is_object() {
                return Err("the source answered JSON that is not an object".into());
            }
            v
        }
        _ => serde_json::Value::String(text.to_string()),
    };
    let forecast = ForecastInput {
        format,
        data,
        roughness_length_m: None,
    };
    let parsed = parse_forecast(&forecast).map_err(|e| {
        format!(
            "the source's answer is not a readable {}: {} {}",
            format.describe(),
            e.field,
            e.reason
        )
    })?;
    Ok((forecast, parsed))
}
