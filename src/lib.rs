//! tetherplan: deployment planning for tethered aerostats.
//!
//! * [`numerics`]: the pure numerical core (no I/O): cable models, the
//!   quadratic eigenvalue stability analysis, critical-time searches and
//!   deployment charts.
//! * [`contract`]: the JSON request/response types shared by the CLI, the
//!   HTTP API and the job queue (SI units, field names end in their unit),
//!   and the functions that run one request.
//! * [`api`]: the HTTP service (axum), its OpenAPI document and error body.
//! * [`jobs`]: persisted batch jobs (SQLite) and their worker.
//! * [`config`]: settings of `serve` (flags with `TETHERPLAN_*` fallbacks);
//!   above [`jobs`], which never names it.
//! * [`limits`]: the service's and the job queue's limits (a plain struct
//!   `config` fills and the queue carries).
//! * [`price`]: what a synchronous request costs in CPU seconds (measured
//!   unit costs) and the budget past which it goes to the job queue.
//!
//! Invariants: `numerics` never touches serde, tokio, axum or SQLite;
//! invalid input is an `Err` naming the field; physical outcomes
//! ("unstable at t = 0", "no safe rate") are answers, not errors.

pub mod api;
pub mod config;
pub mod contract;
pub mod jobs;
pub mod limits;
pub mod numerics;
pub mod price;
