//! The `equilibrium` analysis kind ([`Analysis`], SPEC §6).

use crate::contract::analysis::Analysis;
use crate::contract::equilibrium::dto::{EquilibriumRequest, EquilibriumResponse};
use crate::contract::error::{Progress, RequestError};
use crate::contract::estimate::{self as est, Estimate};

impl Analysis for EquilibriumRequest {
    const NAME: &'static str = "equilibrium";
    const SUMMARY: &'static str = "Static equilibrium of the tether in a steady wind: altitude, downwind\n\
        distance, winch and top tension, safety factor, blow-down and shape.";
    const DESCRIPTION: &'static str = "A heavy, optionally elastic tether under its weight, normal wind drag\n\
        and the aerostat's drag, lift and net buoyancy, integrated from the\n\
        aerostat down (RK4, shooting on the altitude). Slack (part of the\n\
        tether on the ground) is an answer, not an error. Presets\n\
        (`cable.preset`, `aerostat.preset`) fill the fields left out.";
    const ABOUT: &'static str =
        "Static tether in a steady wind: altitude, blow-down, tensions, shape.";
    type Response = EquilibriumResponse;
    fn parse(body: &[u8]) -> Result<Self, RequestError> {
        crate::contract::parse_plain(body)
    }
    fn prepare(&self) -> Result<(), RequestError> {
        EquilibriumRequest::validate(self)
    }
    fn run(&self, _: &dyn Progress) -> Result<EquilibriumResponse, RequestError> {
        super::equilibrium(self)
    }
    fn estimate(&self) -> Estimate {
        Estimate::new(
            "shape_samples",
            est::SIMULATE_BASE + self.shape_samples as u64 * est::PER_SHAPE_SAMPLE,
        )
    }
}
