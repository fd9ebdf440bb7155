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
