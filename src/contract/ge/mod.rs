//! The geometrically exact (GE) model's requests: the transient run, the
//! critical time and stability, and the deployment chart.

pub mod charts;
pub mod critical;
pub mod numerics;
pub mod quasi_static;
pub mod simulate;

pub use simulate::{
    GeAerostatInput, GeModelInput, GeModelKind, GeSimulateRequest, GeSimulateResponse,
    NewtonInput, simulate_ge,
};
