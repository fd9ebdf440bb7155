//! `POST /api/v1/equilibrium` and `tetherplan equilibrium`: the static
//! tether in a steady wind (SPEC §6). Validates the request (bounds equal
//! to the schema's), resolves the presets (fields given win), calls
//! [`crate::numerics::tether`] and converts the answer.

pub mod dto;

use crate::contract::RequestError;
use crate::numerics::aero::SteadyFlow;
use crate::numerics::params::{InvalidInput, require_finite};
use crate::numerics::tether::envelope::{Limits, judge};
use crate::numerics::tether::presets::{BodyPreset, CYLINDER_NORMAL_DRAG, CablePreset};
use crate::numerics::tether::{
    Body, Cable, Equilibrium, EquilibriumConfig, EquilibriumProblem, WindProfile,
};
use dto::*;

/// `value` finite and within `[min, max]`; `exclusive_min` excludes `min`.
/// Smallest roughness length z0 (m): below it ln(z/z0) overflows in
/// double precision long before any real surface (smooth ice ≈ 1e-5 m).
pub const MIN_ROUGHNESS_M: f64 = 1e-6;

pub(crate) fn require_range(
    field: &str,
    value: f64,
    min: f64,
    exclusive_min: bool,
    max: f64,
) -> Result<f64, InvalidInput> {
    require_finite(field, value)?;
    let low_ok = if exclusive_min {
        value > min
    } else {
        value >= min
    };
    if !low_ok || value > max {
        let low = if exclusive_min { "above" } else { "at least" };
        return Err(InvalidInput::new(
            field,
            format!("must be {low} {min} and at most {max}, got {value}"),
        ));
    }
    Ok(value)
}

/// A count within `[min, max]`.
pub(crate) fn require_count(
    field: &str,
    value: usize,
    min: usize,
    max: usize,
) -> Result<usize, InvalidInput> {
    if value < min || value > max {
        return Err(InvalidInput::new(
            field,
            format!("must be between {min} and {max}, got {value}"),
        ));
    }
    Ok(value)
}

fn preset_cable(p: CablePresetName) -> CablePreset {
    match p {
        CablePresetName::Dyneema => CablePreset::Dyneema,
        CablePresetName::Aramid => CablePreset::Aramid,
        CablePresetName::Vectran => CablePreset::Vectran,
        CablePresetName::Steel => CablePreset::Steel,
    }
}

impl TetherCableInput {
    /// The tether with the preset filled in; `at` prefixes field names.
    pub fn cable(&self, at: &str) -> Result<Cable, InvalidInput> {
        let f = |name: &str| format!("{at}.{name}");
        let d = require_range(&f("diameter_m"), self.diameter_m, 0.0, true, 1.0)?;
        let preset = self.preset.map(|p| preset_cable(p).at_diameter(d));
        let mass = match (self.mass_per_length_kg_m, preset) {
            (Some(m), _) => m,
            (None, Some(p)) => p.mass_per_length_kg_m,
            (None, None) => {
                return Err(InvalidInput::new(
                    f("mass_per_length_kg_m"),
                    "is required without a preset",
                ));
            }
        };
        let mass = require_range(&f("mass_per_length_kg_m"), mass, 0.0, true, 1000.0)?;
        let cn = self
            .normal_drag_coefficient_nondim
            .or(preset.map(|p| p.normal_drag_coefficient))
            .unwrap_or(CYLINDER_NORMAL_DRAG);
        let cn = require_range(&f("normal_drag_coefficient_nondim"), cn, 0.0, false, 10.0)?;
        let ea = self
            .axial_stiffness_n
            .or(preset.map(|p| p.axial_stiffness_n))
            .map(|v| require_range(&f("axial_stiffness_n"), v, 0.0, true, 1e12))
            .transpose()?;
        let strength = self
            .breaking_strength_n
            .or(preset.map(|p| p.breaking_strength_n))
            .map(|v| require_range(&f("breaking_strength_n"), v, 0.0, true, 1e9))
            .transpose()?;
        Ok(Cable {
            mass_per_length_kg_m: mass,
            diameter_m: d,
            normal_drag_coefficient: cn,
            axial_stiffness_n: ea,
            breaking_strength_n: strength,
        })
    }
}

impl TetherAerostatInput {
    /// The aerostat's loads with the preset filled in; `at` prefixes field names.
    pub fn body(&self, at: &str) -> Result<Body, InvalidInput> {
        let f = |name: &str| format!("{at}.{name}");
        if let Some(r) = self.radius_m {
            require_range(&f("radius_m"), r, 0.0, true, 100.0)?;
        }
        if let Some(v) = self.volume_m3 {
            require_range(&f("volume_m3"), v, 0.0, true, 1e7)?;
        }
        require_range(&f("mass_kg"), self.mass_kg, 0.0, false, 1e7)?;
        let preset = match self.preset {
            None => None,
            Some(name) => {
                let (shape, size) = match name {
                    BodyPresetName::Sphere => (BodyPreset::Sphere, self.radius_m),
                    BodyPresetName::Streamlined => (BodyPreset::Streamlined, self.volume_m3),
                };
                let field = f(shape.size_field());
                match size {
                    Some(size) => Some(shape.properties(size, &field)?),
                    None if self.drag_coefficient_nondim.is_some()
                        && self.reference_area_m2.is_some()
                        && self.lift_coefficient_nondim.is_some() =>
                    {
                        None
                    }
                    None => {
                        return Err(InvalidInput::new(
                            field,
                            "is required by this preset (or give drag_coefficient_nondim, lift_coefficient_nondim and reference_area_m2)",
                        ));
                    }
                }
            }
        };
        let need = |v: Option<f64>, p: Option<f64>, name: &str| {
            v.or(p)
                .ok_or_else(|| InvalidInput::new(f(name), "is required without a preset"))
        };
        let cd = need(
            self.drag_coefficient_nondim,
            preset.map(|p| p.drag_coefficient),
            "drag_coefficient_nondim",
        )?;
        let area = need(
            self.reference_area_m2,
            preset.map(|p| p.reference_area_m2),
            "reference_area_m2",
        )?;
        let cl = self
            .lift_coefficient_nondim
            .or(preset.map(|p| p.lift_coefficient))
            .unwrap_or(0.0);
        Ok(Body {
            net_buoyancy_n: require_range(
                &f("net_buoyancy_n"),
                self.net_buoyancy_n,
                0.0,
                true,
                1e8,
            )?,
            drag_coefficient: require_range(&f("drag_coefficient_nondim"), cd, 0.0, false, 10.0)?,
            lift_coefficient: require_range(&f("lift_coefficient_nondim"), cl, -10.0, false, 10.0)?,
            reference_area_m2: require_range(&f("reference_area_m2"), area, 0.0, true, 1e5)?,
        })
    }
}

impl WindFlowInput {
    /// The profile; `at` is the field path of the flow.
    pub fn profile(&self, at: &str) -> Result<WindProfile, InvalidInput> {
        let f = |name: &str| format!("{at}.{name}");
        Ok(match self {
            Self::Uniform { speed_m_s } => WindProfile::uniform(require_range(
                &f("speed_m_s"),
                *speed_m_s,
                -150.0,
                false,
                150.0,
            )?),
            Self::PowerLaw {
                coefficient_m_s,
                exponent_nondim,
            } => WindProfile::Flow(SteadyFlow::PowerLaw {
                coefficient: require_range(
                    &f("coefficient_m_s"),
                    *coefficient_m_s,
                    -150.0,
                    false,
                    150.0,
                )?,
                exponent: require_range(&f("exponent_nondim"), *exponent_nondim, 0.0, false, 2.0)?,
            }),
            Self::Tabulated { points } => {
                let mut table = Vec::with_capacity(points.len());
                for (i, p) in points.iter().enumerate() {
                    let z = require_range(
                        &format!("{at}.points[{i}].elevation_m"),
                        p.elevation_m,
                        0.0,
                        false,
                        1e5,
                    )?;
                    let u = require_range(
                        &format!("{at}.points[{i}].speed_m_s"),
                        p.speed_m_s,
                        -150.0,
                        false,
                        150.0,
                    )?;
                    table.push((z, u));
                }
                WindProfile::Flow(SteadyFlow::tabulated(&table, &f("points"))?)
            }
            Self::LogLaw {
                reference_speed_m_s,
                reference_height_m,
                roughness_length_m,
            } => {
                require_range(
                    &f("reference_speed_m_s"),
                    *reference_speed_m_s,
                    -150.0,
                    false,
                    150.0,
                )?;
                require_range(
                    &f("reference_height_m"),
                    *reference_height_m,
                    0.0,
                    true,
                    1e4,
                )?;
                require_range(
                    &f("roughness_length_m"),
                    *roughness_length_m,
                    crate::contract::equilibrium::MIN_ROUGHNESS_M,
                    false,
                    10.0,
                )?;
                WindProfile::log_law(
                    *reference_speed_m_s,
                    *reference_height_m,
                    *roughness_length_m,
                    at,
                )?
            }
        })
    }
}

impl EquilibriumRequest {
    /// The validated problem and its configuration.
    pub fn problem(&self) -> Result<(EquilibriumProblem, EquilibriumConfig), InvalidInput> {
        let problem = EquilibriumProblem {
            cable: self.cable.cable("cable")?,
            body: self.aerostat.body("aerostat")?,
            wind: self.wind.flow.profile("wind.flow")?,
            air_density_kg_m3: require_range(
                "wind.air_density_kg_m3",
                self.wind.air_density_kg_m3,
                0.0,
                true,
                5.0,
            )?,
            tether_length_m: require_range(
                "tether_length_m",
                self.tether_length_m,
                0.0,
                true,
                1e5,
            )?,
            gravity_m_s2: require_range("gravity_m_s2", self.gravity_m_s2, 0.0, true, 100.0)?,
        };
        require_range(
            "required_safety_factor_nondim",
            self.required_safety_factor_nondim,
            1.0,
            false,
            100.0,
        )?;
        if let Some(v) = self.payout_rate_m_s {
            require_range("payout_rate_m_s", v, 0.0, false, 1000.0)?;
        }
        let steps = require_count("integration_steps", self.integration_steps, 8, 100_000)?;
        require_count("shape_samples", self.shape_samples, 2, 10_001)?;
        Ok((
            problem,
            EquilibriumConfig {
                steps,
                ..EquilibriumConfig::default()
            },
        ))
    }

    /// Checks everything without solving.
    pub fn validate(&self) -> Result<(), RequestError> {
        self.problem()?;
        Ok(())
    }
}

/// Evenly spaced samples of the shape (ends kept).
fn sample_shape(eq: &Equilibrium, samples: usize) -> Vec<ShapePointOutput> {
    let nodes = &eq.shape;
    let out = |p: &crate::numerics::tether::ShapePoint| ShapePointOutput {
        s_m: p.s_m,
        x_m: p.x_m,
        z_m: p.z_m,
        tension_n: p.tension_n,
    };
    if nodes.len() <= samples {
        return nodes.iter().map(out).collect();
    }
    let last = nodes.len() - 1;
    let mut idx: Vec<usize> = (0..samples)
        .map(|k| ((k as f64) * last as f64 / (samples - 1) as f64).round() as usize)
        .collect();
    idx.dedup();
    idx.into_iter().map(|i| out(&nodes[i])).collect()
}

/// Plain-language account of an equilibrium.
pub(crate) fn explain(eq: &Equilibrium, limit: Option<&str>) -> String {
    let mut s = if eq.aerostat_wind_m_s == 0.0 && eq.grounded_length_m == 0.0 {
        format!(
            "Calm air at the aerostat: the tether stands at {:.1} m, winch tension {:.1} N.",
            eq.altitude_m, eq.winch_tension_n
        )
    } else {
        format!(
            "In {:.1} m/s at the aerostat the tether is blown down {:.1}° (aerostat {:.1} m up, {:.1} m downwind); winch tension {:.1} N, top tension {:.1} N.",
            eq.aerostat_wind_m_s,
            eq.blowdown_angle_deg,
            eq.altitude_m,
            eq.downwind_m,
            eq.winch_tension_n,
            eq.top_tension_n
        )
    };
    if eq.slack {
        s.push_str(&format!(
            " Slack: {:.1} m of tether rests on the ground (the lift cannot carry the whole tether taut off the winch).",
            eq.grounded_length_m
        ));
    }
    if let Some(f) = eq.safety_factor {
        s.push_str(&format!(" Safety factor {f:.2}."));
    }
    if let Some(limit) = limit {
        s.push_str(&format!(" Outside the operating limits: {limit}."));
    }
    if !eq.converged {
        s.push_str(
            " The altitude iteration did not meet its tolerance: treat the answer with care.",
        );
    }
    s
}

/// Answers one equilibrium request.
pub fn equilibrium(req: &EquilibriumRequest) -> Result<EquilibriumResponse, RequestError> {
    let (problem, config) = req.problem()?;
    let eq = problem.solve(&config)?;
    let limits = Limits {
        required_safety_factor: req.required_safety_factor_nondim,
        ceiling_m: None,
        payout_rate_m_s: req.payout_rate_m_s,
    };
    let verdict = judge(&eq, problem.cable.mass_per_length_kg_m, &limits);
    let limit = verdict.limit.map(|l| l.name().to_string());
    let (drag, vertical) = eq.top_force_n;
    let strength = problem.cable.breaking_strength_n;
    Ok(EquilibriumResponse {
        aerostat_altitude_m: eq.altitude_m,
        aerostat_downwind_m: eq.downwind_m,
        winch_tension_n: eq.winch_tension_n,
        top_tension_n: eq.top_tension_n,
        max_tension_n: eq.max_tension_n,
        min_tension_n: eq.min_tension_n,
        safety_factor_nondim: eq.safety_factor,
        required_safety_factor_nondim: req.required_safety_factor_nondim,
        allowable_tension_n: strength.map(|b| b / req.required_safety_factor_nondim),
        meets_required_safety_factor: eq
            .safety_factor
            .map(|f| f >= req.required_safety_factor_nondim),
        blowdown_angle_deg: eq.blowdown_angle_deg,
        winch_angle_from_vertical_deg: eq.winch_angle_from_vertical_deg,
        top_angle_from_vertical_deg: eq.top_angle_from_vertical_deg,
        winch_horizontal_force_n: eq.winch_force_n.0,
        winch_vertical_force_n: eq.winch_force_n.1,
        aerostat_wind_speed_m_s: eq.aerostat_wind_m_s,
        aerostat_drag_n: drag,
        aerostat_lift_n: vertical - problem.body.net_buoyancy_n,
        slack: eq.slack,
        grounded_length_m: eq.grounded_length_m,
        stretched_length_m: eq.stretched_length_m,
        stability_margin_n: verdict.stability_margin_n,
        stable: verdict.stable,
        explanation: explain(&eq, limit.as_deref()),
        binding_limit: limit,
        shape: sample_shape(&eq, req.shape_samples),
        cable: ResolvedCableOutput {
            mass_per_length_kg_m: problem.cable.mass_per_length_kg_m,
            diameter_m: problem.cable.diameter_m,
            normal_drag_coefficient_nondim: problem.cable.normal_drag_coefficient,
            axial_stiffness_n: problem.cable.axial_stiffness_n,
            breaking_strength_n: strength,
        },
        aerostat: ResolvedAerostatOutput {
            net_buoyancy_n: problem.body.net_buoyancy_n,
            drag_coefficient_nondim: problem.body.drag_coefficient,
            lift_coefficient_nondim: problem.body.lift_coefficient,
            reference_area_m2: problem.body.reference_area_m2,
        },
        numerics: EquilibriumNumerics {
            integration_steps: config.steps,
            order_nondim: 4,
            shooting_iterations: eq.iterations,
            residual_m: eq.residual_m,
            converged: eq.converged,
        },
    })
}
