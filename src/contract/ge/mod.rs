//! The geometrically exact (GE) model's requests: the model input every
//! GE request shares ([`model`]), the transient run ([`simulate`]), the critical
//! time ([`critical`], both methods), the stability query ([`stability`]),
//! the deployment chart ([`charts`]), the base-excitation frequency
//! response ([`base_response`]), and the numerics settings they share
//! ([`numerics`]).

pub mod base_response;
pub mod charts;
pub mod critical;
pub mod kind;
pub mod model;
pub mod numerics;
pub mod price;
pub mod simulate;
pub mod stability;

pub use simulate::{
    GeAerostatInput, GeModelInput, GeModelKind, GeSimulateRequest, GeSimulateResponse, NewtonInput,
    simulate_ge,
};
