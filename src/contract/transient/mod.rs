//! Transient runs and frequency responses (SPEC §2).

pub mod any;
pub mod simulate;

pub use simulate::{
    FrequencyResponseParams, FrequencyResponseRequest, FrequencyResponseResponse,
    SimulateParams, SimulateRequest, SimulateResponse, frequency_response,
    frequency_response_runs, simulate,
};
