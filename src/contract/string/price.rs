//! What a linear-string chart on a fixed mesh costs in CPU seconds (issue
//! 34, item 2): chart points × a point's cost, which grows faster than the
//! elements (measured through the route, server CPU time, 2-core machine,
//! release build: 1 000 points on 500 elements 0.15 CPU-s, on 2 000
//! elements 6.65 CPU-s; a point as `elements^2.75`). Converged charts
//! (`model.elements` omitted) are bounded by the point limits alone
//! (20 000 points: 0.13 CPU-s).

use crate::contract::dto::ChartRequest;
use crate::contract::price::Price;
use crate::contract::string::run;

/// One chart point on 500 elements, s (1.2 times the measurement).
pub const CHART_POINT_500_S: f64 = 1.8e-4;
/// A point's cost grows as `elements^CHART_ELEMENT_POWER`.
pub const CHART_ELEMENT_POWER: f64 = 2.75;

/// `POST /api/v1/charts` of the linear string on a fixed mesh (None:
/// converged, not priced).
pub fn chart(req: &ChartRequest) -> Option<Price> {
    let elements = req.system.model.elements? as f64;
    let points = run::chart_points(req) as f64;
    Some(Price {
        cpu_s: points * CHART_POINT_500_S * (elements / 500.0).powf(CHART_ELEMENT_POWER),
        field: "model.elements".into(),
        counts: format!("{points:.0} chart points on {elements:.0} elements"),
    })
}
