//! Forecasts and launch windows (SPEC §12, issue 32): the JSON contract of
//! `POST /api/v1/windows` and `tetherplan windows` ([`dto`]), the sources
//! (`open_meteo` JSON, `metar` and `taf` reports in `aviation`, `csv`),
//! parsed in [`source`] with every error naming `forecast.data` and its key,
//! index or line, times in `time`, and the run ([`run`]): each period's
//! flow fitted, planned by `/plan`'s own code, judged and gathered into
//! windows, with an ensemble's shares.

mod aviation;
mod csv;
pub mod dto;
pub mod forecast;
mod open_meteo;
pub mod points;
pub mod run;
pub mod source;
pub mod time;

pub use dto::{WindowsRequest, WindowsResponse};
pub use points::haul_down_points;
pub use run::{Prepared, prepare, windows};

use crate::contract::RequestError;

/// Parses a windows request (one pass, unknown fields refused, field paths kept).
pub fn parse_windows(body: &[u8]) -> Result<WindowsRequest, RequestError> {
    crate::contract::parse_plain(body)
}
