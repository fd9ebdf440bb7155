//! The linear string model's requests: stability, critical time, safe
//! rate and the deployment chart.

pub mod chunks;
pub mod dto;
pub mod kind;
pub mod price;
pub mod run;
pub mod tension;
