//! `POST /api/v1/equilibrium` and `tetherplan equilibrium`: the static
//! tether in a steady wind (SPEC §6). Validates the request (bounds equal
//! to the schema's), resolves the presets (fields given win), calls
//! [`crate::numerics::tether`] and converts the answer.

pub mod dto;
pub mod kind;

use crate::contract::RequestError;
use crate::numerics::params::InvalidInput;
use crate::numerics::tether::envelope::{Limits, judge};
use crate::numerics::tether::{Equilibrium, EquilibriumConfig, EquilibriumProblem};
use dto::*;

use crate::contract::system::bounds;
pub(crate) use crate::contract::system::validate::{require_count, require_range};

impl EquilibriumRequest {
    /// The validated problem and its configuration.
    pub fn problem(&self) -> Result<(EquilibriumProblem, EquilibriumConfig), InvalidInput> {
        let problem = EquilibriumProblem {
            cable: self.cable.cable("cable")?,
            body: self.aerostat.body("aerostat")?,
            wind: self.wind.flow.profile("wind.flow")?,
            air_density_kg_m3: self.wind.air_density()?,
            tether_length_m: require_range(
                "tether_length_m",
                self.tether_length_m,
                0.0,
                true,
                1e5,
            )?,
            gravity_m_s2: bounds::GRAVITY_M_S2.check(self.gravity_m_s2)?,
        };
        bounds::REQUIRED_SAFETY_FACTOR.check(self.required_safety_factor_nondim)?;
        if let Some(v) = self.payout_rate_m_s {
            bounds::PAYOUT_RATE_M_S.check(v)?;
        }
        let steps = bounds::INTEGRATION_STEPS.check(self.integration_steps)?;
        require_count("shape_samples", self.shape_samples, 2, 10_001)?;
        crate::contract::system::validate::check_rest(
            self.winch.as_ref(),
            self.initial_length_m,
            self.lift_reserve_nondim,
        )?;
        self.wind.gust_wind(&problem.wind)?;
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

/// The state of one equilibrium judged against the limits.
fn state_output(
    eq: &Equilibrium,
    problem: &EquilibriumProblem,
    req: &EquilibriumRequest,
) -> EquilibriumStateOutput {
    let limits = Limits {
        required_safety_factor: req.required_safety_factor_nondim,
        ceiling_m: None,
        min_altitude_m: None,
        payout_rate_m_s: req.payout_rate_m_s,
        dynamic_tension: None,
    };
    let verdict = judge(eq, problem.cable.mass_per_length_kg_m, &limits);
    let limit = verdict.limit.map(|l| l.name().to_string());
    let (drag, vertical) = eq.top_force_n;
    EquilibriumStateOutput {
        aerostat_altitude_m: eq.altitude_m,
        aerostat_downwind_m: eq.downwind_m,
        winch_tension_n: eq.winch_tension_n,
        top_tension_n: eq.top_tension_n,
        max_tension_n: eq.max_tension_n,
        min_tension_n: eq.min_tension_n,
        safety_factor_nondim: eq.safety_factor,
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
        explanation: explain(eq, limit.as_deref()),
        binding_limit: limit,
        shape: sample_shape(eq, req.shape_samples),
    }
}

fn numerics_output(eq: &Equilibrium, config: &EquilibriumConfig) -> EquilibriumNumerics {
    EquilibriumNumerics {
        integration_steps: config.steps,
        order_nondim: 4,
        shooting_iterations: eq.iterations,
        residual_m: eq.residual_m,
        converged: eq.converged,
    }
}

/// Answers one equilibrium request: the mean wind, and with `wind.gust`
/// the same problem at the gust speed beside it.
pub fn equilibrium(req: &EquilibriumRequest) -> Result<EquilibriumResponse, RequestError> {
    let (problem, config) = req.problem()?;
    let gust = req.wind.gust_wind(&problem.wind)?;
    let eq = problem.solve(&config)?;
    let gust = match gust {
        Some(g) => {
            let gp = EquilibriumProblem {
                wind: g.profile.clone(),
                ..problem.clone()
            };
            let ge = gp.solve(&config)?;
            Some(EquilibriumGustOutput {
                gust_factor_nondim: g.factor,
                reference_height_m: g.reference_height_m,
                reference_speed_m_s: g.reference_speed_m_s,
                state: state_output(&ge, &gp, req),
                numerics: numerics_output(&ge, &config),
            })
        }
        None => None,
    };
    let strength = problem.cable.breaking_strength_n;
    Ok(EquilibriumResponse {
        state: state_output(&eq, &problem, req),
        required_safety_factor_nondim: req.required_safety_factor_nondim,
        allowable_tension_n: strength.map(|b| b / req.required_safety_factor_nondim),
        gust,
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
        numerics: numerics_output(&eq, &config),
    })
}
