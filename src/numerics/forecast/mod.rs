//! Forecasts and launch windows (SPEC §12): the pure numbers behind
//! `POST /api/v1/windows`. [`units`] the exact unit conversions at the
//! boundary (1 kn = 1852/3600 m/s, 1 mph = 1609.344/3600 m/s, 1 ft =
//! 0.3048 m); [`profile`] one hour's winds at their heights turned into a
//! steady flow (a power law fitted through two or more heights, a log law
//! of a stated roughness through one) and its gust ratio; [`windows`] the
//! lead-time factor that shrinks the wind limits as the forecast ages, the
//! runs of time in which a deployment, the time aloft and the haul-down
//! fit, and an ensemble's share of GO with its Wilson interval and the
//! percentiles of a member figure.
//!
//! Parsing the sources (Open-Meteo JSON, METAR, TAF, CSV) and running the
//! plan per hour belong to `contract::windows`; nothing here does I/O.

pub mod profile;
pub mod units;
pub mod windows;
