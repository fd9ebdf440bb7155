//! The JSON contract shared by the CLI, the HTTP API and the job queue:
//! request/response types ([`dto`]), parsing with field paths in errors,
//! conversion to the numerical core, and one function per request kind
//! ([`run`]). Everything here is synchronous and CPU-bound.

pub mod bands;
pub mod dynamics;
pub mod envelope;
pub mod equilibrium;
pub mod error;
pub mod flight;
pub mod finite;
pub mod ge;
pub mod json;
pub mod json_keys;
pub mod parse;
pub mod plan;
pub mod ranges;
pub mod string;
pub mod system;
pub mod transient;
pub mod windows;

// The old paths of the modules that moved into their domain folders, kept
// for the API, the jobs, the CLI and the tests.
pub use ge::{charts as ge_charts, critical as ge_critical, numerics as ge_numerics};
pub use string::{chunks as chart_chunks, dto, run, tension};
pub use transient::any as simulate;

pub use error::{Progress, RequestError};
pub use json::{describe_json, parse_value, plain_words};
pub use parse::{parse, parse_ge, parse_plain};
