//! Transient runs and frequency responses (SPEC §2): the linear string's
//! transient run ([`simulate`]) and wind frequency response
//! ([`frequency`]), the wind on the aerostat they share ([`aero`]), and the
//! dispatch of `simulate` on `model.kind` ([`any`]).

pub mod aero;
pub mod any;
pub mod frequency;
pub mod kind;
pub mod price;
pub mod simulate;

pub use frequency::{
    FrequencyResponseParams, FrequencyResponseRequest, FrequencyResponseResponse,
    frequency_response, frequency_response_runs,
};
pub use simulate::{SimulateParams, SimulateRequest, SimulateResponse, simulate};
