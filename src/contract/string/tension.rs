//! Tension outputs of the string-model answers (`critical`, `charts`):
//! the roller and aerostat tensions of the vertical cable at a deployment
//! state, with its rate and acceleration terms
//! ([`crate::numerics::tether::string_tension`]).

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::numerics::params::{AerostatSystem, Kinematics};
use crate::numerics::tether::string_tension::StringTension;

/// Tensions of the vertical cable at one deployment state.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct TensionOutput {
    /// Cable length of the state (m).
    pub length_m: f64,
    /// At the aerostat: F − m a (N).
    pub top_tension_n: f64,
    /// At the winch roller: F − m a − ρA(g + a)L (N); linear in between.
    pub winch_tension_n: f64,
    /// Kinematic term ρA v² (N).
    pub kinematic_tension_n: f64,
    /// Winch tension − ρA v² (N): zero at the continuum stability limit.
    pub effective_winch_tension_n: f64,
    /// Breaking strength / largest tension; null without `cable.breaking_strength_n`.
    pub safety_factor_nondim: Option<f64>,
    /// Tension vanishes somewhere along the cable (an outcome, not an error).
    pub slack: bool,
}

impl TensionOutput {
    pub fn at(sys: &AerostatSystem, k: Kinematics, breaking_strength_n: Option<f64>) -> Self {
        let t = StringTension::at(sys, k);
        Self {
            length_m: k.length_m,
            top_tension_n: t.top_n,
            winch_tension_n: t.winch_n,
            kinematic_tension_n: t.kinematic_n,
            effective_winch_tension_n: t.effective_winch_n,
            safety_factor_nondim: breaking_strength_n
                .filter(|_| t.max_n > 0.0)
                .map(|b| b / t.max_n),
            slack: t.slack,
        }
    }
}

/// Tension of the vertical cable along a transient run (`simulate`), from
/// the profile's kinematics at each output time: `T(L) = F − m a` at the
/// aerostat, `T(0) = F − m a − ρA (g + a) L` at the winch, linear between
/// ([`StringTension`]). The linear string's tension is the quasi-static
/// one of the deployment (the transverse motion is second order in it).
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct TensionSeriesOutput {
    /// At the winch roller, per output time (N).
    pub winch_tension_n: Vec<f64>,
    /// At the aerostat, per output time (N).
    pub top_tension_n: Vec<f64>,
    /// Winch tension − ρA L̇², per output time (N): zero at the continuum
    /// stability limit.
    pub effective_winch_tension_n: Vec<f64>,
    /// Smallest tension anywhere along the cable over the run (N).
    pub min_tension_n: f64,
    /// When it occurs (s).
    pub min_tension_time_s: f64,
    /// Largest tension anywhere along the cable over the run (N).
    pub max_tension_n: f64,
    /// The tension vanished somewhere at some output time (an outcome).
    pub slack: bool,
    /// First output time with a slack cable (s); null when never slack.
    pub first_slack_time_s: Option<f64>,
    /// Breaking strength / largest tension over the run; null without
    /// `cable.breaking_strength_n` (or when the cable never pulls).
    pub safety_factor_nondim: Option<f64>,
}

impl TensionSeriesOutput {
    /// The tensions at `times_s` of a run of `profile`.
    pub fn of(
        sys: &AerostatSystem,
        profile: &crate::numerics::profile::Profile,
        times_s: &[f64],
        breaking_strength_n: Option<f64>,
    ) -> Self {
        let mut out = Self {
            winch_tension_n: Vec::with_capacity(times_s.len()),
            top_tension_n: Vec::with_capacity(times_s.len()),
            effective_winch_tension_n: Vec::with_capacity(times_s.len()),
            min_tension_n: f64::INFINITY,
            min_tension_time_s: 0.0,
            max_tension_n: f64::NEG_INFINITY,
            slack: false,
            first_slack_time_s: None,
            safety_factor_nondim: None,
        };
        for &t in times_s {
            let s = StringTension::at(sys, profile.kinematics(t));
            out.winch_tension_n.push(s.winch_n);
            out.top_tension_n.push(s.top_n);
            out.effective_winch_tension_n.push(s.effective_winch_n);
            let min = s.top_n.min(s.winch_n);
            if min < out.min_tension_n {
                out.min_tension_n = min;
                out.min_tension_time_s = t;
            }
            out.max_tension_n = out.max_tension_n.max(s.max_n);
            if s.slack && out.first_slack_time_s.is_none() {
                out.slack = true;
                out.first_slack_time_s = Some(t);
            }
        }
        if times_s.is_empty() {
            out.min_tension_n = 0.0;
            out.max_tension_n = 0.0;
        }
        out.safety_factor_nondim = breaking_strength_n
            .filter(|_| out.max_tension_n > 0.0)
            .map(|b| b / out.max_tension_n);
        out
    }
}
