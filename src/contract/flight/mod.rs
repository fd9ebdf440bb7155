//! Live flights (SPEC §13, issue 33): the JSON contract around the pure
//! monitor of [`crate::numerics::monitor`]. [`telemetry`] parses the
//! batches of samples (JSON, CSV, NMEA `$--MWV`), [`dto`] holds the
//! flight's limits and answers, [`model`] commits a flight (its plan, its
//! limits, its ceiling table) and turns the monitor into JSON, [`wind`]
//! carries a measured wind into the plan's flow, [`replan`] plans again from now,
//! [`report`] sums a flight up (JSON, CSV, HTML), [`simulate`] flies a flight
//! in the dynamics model through a wind event and writes its telemetry log,
//! [`feed`] cuts a recorded log into batches for `tetherplan feed`.

pub mod dto;
pub mod feed;
pub mod model;
pub mod replan;
pub mod report;
pub mod simulate;
pub mod telemetry;
pub mod wind;
