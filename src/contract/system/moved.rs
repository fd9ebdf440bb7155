//! The system's moved names (the plan's old `wind.cable_*`,
//! `wind.aerostat_*` and `tether.*`), refused naming where each moved:
//! before any parse, on every route that takes a system.

use serde_json::Value;

use crate::numerics::params::InvalidInput;

/// The moved names: (old path, new path).
pub const MOVED: &[(&str, &str)] = &[
    ("wind.cable_diameter_m", "cable.diameter_m"),
    (
        "wind.cable_normal_drag_coefficient_nondim",
        "cable.normal_drag_coefficient_nondim",
    ),
    (
        "wind.aerostat_drag_coefficient_nondim",
        "aerostat.drag_coefficient_nondim",
    ),
    (
        "wind.aerostat_reference_area_m2",
        "aerostat.reference_area_m2",
    ),
    (
        "wind.aerostat_lift_coefficient_nondim",
        "aerostat.lift_coefficient_nondim",
    ),
    ("wind.shape", "wind.flow"),
    ("tether.breaking_strength_n", "cable.breaking_strength_n"),
    (
        "tether.safety_factor_nondim",
        "required_safety_factor_nondim",
    ),
];

fn get<'a>(v: &'a Value, path: &str) -> Option<&'a Value> {
    path.split('.').try_fold(v, |node, key| node.get(key))
}

/// Refuses the old names of the system (the plan's `wind.cable_*`,
/// `wind.aerostat_*`, `tether.*`), naming where each moved.
pub fn refuse_moved(v: &Value) -> Result<(), InvalidInput> {
    for (old, new) in MOVED {
        if get(v, old).is_some() {
            return Err(InvalidInput::new(*old, format!("moved to {new}")));
        }
    }
    if v.get("tether").is_some() {
        return Err(InvalidInput::new(
            "tether",
            "moved: the breaking strength is cable.breaking_strength_n and the safety factor \
             required_safety_factor_nondim",
        ));
    }
    Ok(())
}
