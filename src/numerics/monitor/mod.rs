//! The live-flight monitor (SPEC §13, issue 33): a committed plan against
//! its telemetry. Pure: samples in, checks, levels and alarms out; the
//! storage, the clock and the transport are the caller's.
//!
//! - [`sample`]: the sample, the checks, the levels, the limits and the
//!   committed schedule as a trace;
//! - [`window`]: the rolling 10-minute wind mean and 3 s gust, O(1)
//!   amortised per sample;
//! - [`level`]: one level's raise/clear with dwell and hysteresis;
//! - [`ceiling`]: the payout rate's stability ceiling, tabulated once per
//!   flight from the plan's criterion;
//! - [`engine`]: the monitor itself (order, latching, acknowledgement,
//!   staleness, the flight's state).

pub mod ceiling;
pub mod engine;
pub mod level;
pub mod sample;
pub mod window;

pub use ceiling::{CeilingTable, RateCeiling};
pub use engine::{Alarm, CheckStatus, Event, FlightModel, Monitor, Pushed, Status};
pub use level::{Dwell, Sense};
pub use sample::{CheckName, Level, Limits, PlanTrace, Sample};
