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
