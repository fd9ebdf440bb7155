//! Tether tension and steady wind (SPEC §6, beyond the thesis): the static
//! large-deflection shape of a heavy, optionally elastic tether under its
//! weight, normal wind drag and the aerostat's drag, lift and net buoyancy
//! ([`equilibrium`], its shootings continued along a sequence of lengths
//! in [`continuation`]); wind profiles including the log law ([`wind`]);
//! tether and aerostat presets with their sources ([`presets`]); the
//! operating envelope over wind speed × tether length ([`envelope`]).

pub mod continuation;
pub mod envelope;
pub mod envelope_ge;
pub mod equilibrium;
pub mod gust;
pub mod presets;
pub mod string_onset;
pub mod string_tension;
pub mod wind;

pub use equilibrium::{
    Body, Cable, Equilibrium, EquilibriumConfig, EquilibriumProblem, ShapePoint, catenary_top,
};
pub use wind::WindProfile;
