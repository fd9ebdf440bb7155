//! The plan's stability ceiling at rest, length by length: the largest
//! payout rate `v` with `ρA v² + δ(v) ≤ S(L) − ε(1 − r)F` (the pass's own
//! criterion, [`crate::numerics::plan::air`], with the aerostat's ascent
//! drag `δ`), in the request's air. The live-flight monitor tabulates it
//! once per flight over lengths × measured winds
//! ([`crate::numerics::monitor::CeilingTable`]).

use crate::contract::RequestError;
use crate::contract::plan::dto::PlanRequest;
use crate::contract::plan::validate::validate_with;
use crate::numerics::plan::STABILITY_MARGIN;

/// The ceiling (m/s, ≥ 0) at each of `lengths_m` in the request's air.
pub fn rate_ceilings_m_s(req: &PlanRequest, lengths_m: &[f64]) -> Result<Vec<f64>, RequestError> {
    let v = validate_with(req, false)?;
    let p = v.problem;
    let s = p.system;
    let margin_n = STABILITY_MARGIN * p.reserve_buoyancy_n();
    let loads = v.options.air.rest_loads_at(&p, lengths_m);
    Ok(lengths_m
        .iter()
        .zip(loads)
        .map(|(&l, (rest, _))| {
            let budget = rest.effective_tension_n(&s, l, 0.0, 0.0) - margin_n;
            let c = rest.ascent.ceiling_m_s(s.mass_per_length_kg_m, budget);
            if c.is_finite() { c } else { 0.0 }
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn calm_air_is_the_closed_form() {
        // √(((1 − r)(1 − ε)F − ρA g L)/ρA), no drag data: no ascent term
        let req: PlanRequest = serde_json::from_value(serde_json::json!({
            "cable": {"mass_per_length_kg_m": 0.078},
            "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
            "initial_length_m": 1.0,
            "target_elevation_m": 1000.0,
            "winch": {"max_rate_m_s": 5.0, "max_acceleration_m_s2": 1.0},
            "lift_reserve_nondim": 0.05
        }))
        .unwrap();
        let lengths = [0.0, 100.0, 600.0, 1200.0, 2000.0];
        let c = rate_ceilings_m_s(&req, &lengths).unwrap();
        for (l, c) in lengths.iter().zip(c) {
            let budget = 0.95 * (1.0 - STABILITY_MARGIN) * 1000.0 - 0.078 * 9.81 * l;
            let exact = (budget / 0.078).max(0.0).sqrt();
            assert!((c - exact).abs() <= 1e-9 * exact.max(1.0), "{l}: {c} vs {exact}");
        }
    }
}
