//! The numerical core: pure functions of `f64`, faer and rayon. No I/O, no
//! serialisation, no async (a test in `tests/tidy.rs` keeps it so).
//! Inputs are SI; inside, the models work non-dimensionally (SPEC §1).

pub mod aero;
pub mod dynamics;
pub mod forecast;
pub mod ge;
pub mod mesh;
pub mod monitor;
pub mod newmark;
pub mod parallel;
pub mod params;
pub mod plan;
pub mod profile;
pub mod qep;
pub mod string;
pub mod tether;
pub mod tridiag;
pub mod uncertainty;
