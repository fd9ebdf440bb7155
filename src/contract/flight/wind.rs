//! The measured wind in a plan's terms: the request's flow scaled so that
//! its speed at the anemometer's height is the measured one (the shape —
//! power law, log law, table — is the plan's; a calm or absent flow
//! becomes uniform), and the measured gust the same way as a gust speed at
//! the flow's reference height (SPEC §10, §13).

use crate::contract::system::{GustInput, WindFlowInput, WindInput};

/// The flow's speed at `z_m` (m/s).
pub fn speed_at_m_s(flow: &WindFlowInput, z_m: f64) -> f64 {
    match flow {
        WindFlowInput::Uniform { speed_m_s } => *speed_m_s,
        WindFlowInput::PowerLaw {
            coefficient_m_s,
            exponent_nondim,
            reference_height_m,
        } => coefficient_m_s * (z_m.max(0.0) / reference_height_m).powf(*exponent_nondim),
        WindFlowInput::LogLaw {
            speed_m_s,
            reference_height_m,
            roughness_length_m,
        } => {
            if z_m <= *roughness_length_m {
                0.0
            } else {
                speed_m_s * (z_m / roughness_length_m).ln()
                    / (reference_height_m / roughness_length_m).ln()
            }
        }
        WindFlowInput::Tabulated { points } => {
            let (Some(first), Some(last)) = (points.first(), points.last()) else {
                return 0.0;
            };
            if z_m <= first.elevation_m {
                return first.speed_m_s;
            }
            if z_m >= last.elevation_m {
                return last.speed_m_s;
            }
            let i = points.partition_point(|p| p.elevation_m <= z_m) - 1;
            let (a, b) = (&points[i], &points[i + 1]);
            let w = (z_m - a.elevation_m) / (b.elevation_m - a.elevation_m);
            a.speed_m_s + w * (b.speed_m_s - a.speed_m_s)
        }
    }
}

/// The flow of the same shape with `measured_m_s` at `height_m`, and the
/// factor it scaled the flow by (`None` when it became uniform).
pub fn scaled_flow(
    flow: Option<&WindFlowInput>,
    height_m: f64,
    measured_m_s: f64,
) -> (WindFlowInput, Option<f64>) {
    let uniform = || {
        (
            WindFlowInput::Uniform {
                speed_m_s: measured_m_s,
            },
            None,
        )
    };
    let Some(flow) = flow else {
        return uniform();
    };
    let here = speed_at_m_s(flow, height_m);
    if !(here.abs() > 1e-9) {
        return uniform();
    }
    let k = measured_m_s / here;
    let scaled = match flow.clone() {
        WindFlowInput::Uniform { .. } => return uniform(),
        WindFlowInput::PowerLaw {
            coefficient_m_s,
            exponent_nondim,
            reference_height_m,
        } => WindFlowInput::PowerLaw {
            coefficient_m_s: coefficient_m_s * k,
            exponent_nondim,
            reference_height_m,
        },
        WindFlowInput::LogLaw {
            speed_m_s,
            reference_height_m,
            roughness_length_m,
        } => WindFlowInput::LogLaw {
            speed_m_s: speed_m_s * k,
            reference_height_m,
            roughness_length_m,
        },
        WindFlowInput::Tabulated { mut points } => {
            for p in &mut points {
                p.speed_m_s *= k;
            }
            WindFlowInput::Tabulated { points }
        }
    };
    (scaled, Some(k))
}

/// The flow's reference height (m): where a gust speed is given.
fn reference_height_m(flow: &WindFlowInput, fallback_m: f64) -> f64 {
    match flow {
        WindFlowInput::PowerLaw {
            reference_height_m, ..
        }
        | WindFlowInput::LogLaw {
            reference_height_m, ..
        } => *reference_height_m,
        _ => fallback_m,
    }
}

/// The plan's air with the measured mean and (optionally) gust at the
/// anemometer's height: density from the plan (1.225 kg/m³ without one).
pub fn measured_wind(
    plan_wind: Option<&WindInput>,
    height_m: f64,
    mean_m_s: f64,
    gust_m_s: Option<f64>,
) -> WindInput {
    let (flow, _) = scaled_flow(plan_wind.map(|w| &w.flow), height_m, mean_m_s);
    let gust = gust_m_s.filter(|g| *g > mean_m_s).map(|g| {
        let at_ref = speed_at_m_s(&flow, reference_height_m(&flow, height_m));
        // the gust factor at the anemometer carried to the reference height
        let factor = if mean_m_s > 0.0 { g / mean_m_s } else { 1.0 };
        GustInput {
            turbulence_intensity_nondim: None,
            peak_factor_nondim: None,
            gust_m_s: Some(at_ref * factor),
        }
    });
    WindInput {
        flow,
        air_density_kg_m3: plan_wind.map_or(1.225, |w| w.air_density_kg_m3),
        gust,
    }
}
