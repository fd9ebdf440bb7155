//! Gusts (SPEC §10, issue 21): the quasi-static check at the gust speed.
//!
//! The gust speed at a height is the mean times the gust factor
//! `G = 1 + k I` (`I = σ_u/U` the turbulence intensity, `k` the peak
//! factor, default [`DEFAULT_PEAK_FACTOR`]: about the 3-second gust over 10
//! minutes), or a gust speed given at the reference height, `G =
//! gust/U(z_ref)`. The gust enters the equilibrium exactly as a faster mean
//! wind would: [`gust_profile`] is the mean profile with its speeds scaled
//! by `G` (for a uniform flow `U(1 + k I)`), and with `G = 1` (`I = 0`) it
//! is the mean profile bit for bit (every speed times exactly 1).
//!
//! The static equilibrium at the gust speed is conservative for the
//! tension (SPEC §10: a step gust reaches at most 1.00× the new static
//! tension in MoorDyn runs; periodic gusts swing it by well under half the
//! quasi-static swing) and gives the lowest altitude in the gust, the one
//! that must clear terrain and airspace floors.

use crate::numerics::aero::SteadyFlow;
use crate::numerics::params::{InvalidInput, require_finite, require_non_negative};
use crate::numerics::tether::wind::WindProfile;

/// Peak factor `k` unless given.
pub const DEFAULT_PEAK_FACTOR: f64 = 3.0;
/// Reference height (m) of a gust speed for flows that have none of their
/// own (uniform, power law, tabulated): the anemometer height of weather
/// reports (WMO No. 8, 10 m above ground).
pub const DEFAULT_REFERENCE_HEIGHT_M: f64 = 10.0;
/// The factor on the gust check's tension *above the calm-air tension*
/// that covers the 99th percentile of the hourly largest winch tension in
/// the time-domain dynamics with von Kármán turbulence (issue 31 item 5,
/// `docs/gust_check.md`, remade by `cargo run --release --example
/// gust_check_table`). With `T₀` the calm tension, `T_g` the static tension
/// at the `1 + kI` gust and `T₉₉` the dynamic p99, `(T₉₉ − T₀)/(T_g − T₀)`
/// was 0.84–0.86 at 6 m/s, 0.99–1.16 at 10 m/s and 1.17–1.41 at 15 m/s
/// (I 0.1 and 0.2, 200 one-hour seeds each, the §10 1000 m tether, whose
/// calm winch tension is 234.8 N); this is the largest, rounded up. On the
/// increment, not the whole tension: in calm air turbulence adds nothing,
/// and the buoyancy's share of the tension is not amplified.
pub const DYNAMIC_TENSION_FACTOR: f64 = 1.41;
/// The range of the measurement behind [`DYNAMIC_TENSION_FACTOR`]: the mean
/// wind at the reference height (m/s) and the turbulence intensity.
pub const DYNAMIC_FACTOR_MAX_WIND_M_S: f64 = 15.0;
pub const DYNAMIC_FACTOR_MAX_INTENSITY: f64 = 0.2;

/// The factor on the static gust tensions' increment over calm air for
/// `gust` (see [`DYNAMIC_TENSION_FACTOR`]): 1 for a gust given as a speed
/// (a measured or forecast peak, whose tension is the check itself) and for
/// `I = 0` (no turbulence).
pub fn dynamic_tension_factor(gust: &Gust) -> f64 {
    match *gust {
        Gust::Intensity {
            turbulence_intensity,
            ..
        } if turbulence_intensity > 0.0 => DYNAMIC_TENSION_FACTOR,
        _ => 1.0,
    }
}

/// The tension a static gust tension is judged at: `T₀ + k (T_g − T₀)` for
/// `T_g` above the calm tension `T₀`, `T_g` itself otherwise (a gust that
/// unloads the tether is not made lighter).
pub fn dynamic_tension_n(static_n: f64, calm_n: f64, factor: f64) -> f64 {
    if static_n > calm_n {
        calm_n + factor * (static_n - calm_n)
    } else {
        static_n
    }
}

/// The dynamic judgement of one tether's gust tensions: the factor and the
/// calm-air tension its increment is taken over.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DynamicTension {
    /// [`DYNAMIC_TENSION_FACTOR`], or 1.
    pub factor_nondim: f64,
    /// The largest tension in calm air (N): the net buoyancy, at the top.
    pub calm_max_tension_n: f64,
}

impl DynamicTension {
    /// [`dynamic_tension_n`] of a largest tension.
    pub fn max_tension_n(&self, static_n: f64) -> f64 {
        dynamic_tension_n(static_n, self.calm_max_tension_n, self.factor_nondim)
    }
}

/// Largest turbulence intensity and peak factor accepted.
pub const MAX_TURBULENCE_INTENSITY: f64 = 1.0;
pub const MAX_PEAK_FACTOR: f64 = 10.0;

/// How the gust is given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Gust {
    /// `G = 1 + k I`.
    Intensity {
        turbulence_intensity: f64,
        peak_factor: f64,
    },
    /// The gust speed at the reference height (m/s).
    AtReference { gust_m_s: f64 },
}

impl Gust {
    /// Checks the fields (named as in the contract, under `field`).
    pub fn validate(&self, field: &str) -> Result<(), InvalidInput> {
        match *self {
            Self::Intensity {
                turbulence_intensity,
                peak_factor,
            } => {
                let f = format!("{field}.turbulence_intensity_nondim");
                require_finite(&f, turbulence_intensity)?;
                require_non_negative(&f, turbulence_intensity)?;
                if turbulence_intensity > MAX_TURBULENCE_INTENSITY {
                    return Err(InvalidInput::new(
                        f,
                        format!(
                            "must be at most {MAX_TURBULENCE_INTENSITY}, got {turbulence_intensity}"
                        ),
                    ));
                }
                let f = format!("{field}.peak_factor_nondim");
                require_finite(&f, peak_factor)?;
                require_non_negative(&f, peak_factor)?;
                if peak_factor > MAX_PEAK_FACTOR {
                    return Err(InvalidInput::new(
                        f,
                        format!("must be at most {MAX_PEAK_FACTOR}, got {peak_factor}"),
                    ));
                }
            }
            Self::AtReference { gust_m_s } => {
                let f = format!("{field}.gust_m_s");
                require_finite(&f, gust_m_s)?;
                require_non_negative(&f, gust_m_s)?;
            }
        }
        Ok(())
    }
}

/// The reference height (m) of a profile: its own for the log law, else
/// [`DEFAULT_REFERENCE_HEIGHT_M`].
pub fn reference_height_m(mean: &WindProfile) -> f64 {
    match mean {
        WindProfile::LogLaw {
            reference_height_m, ..
        } => *reference_height_m,
        WindProfile::Flow(_) => DEFAULT_REFERENCE_HEIGHT_M,
    }
}

/// The gust factor `G` of `gust` over `mean`; an error names `field`
/// when a gust speed is given over a mean that is zero at the reference
/// height of a sheared flow (nothing to scale).
pub fn gust_factor(gust: &Gust, mean: &WindProfile, field: &str) -> Result<f64, InvalidInput> {
    gust_factor_at(gust, mean, reference_height_m(mean), field)
}

/// [`gust_factor`] with a gust speed given at `reference_height_m` (a
/// power law's own reference height, say).
pub fn gust_factor_at(
    gust: &Gust,
    mean: &WindProfile,
    reference_height_m: f64,
    field: &str,
) -> Result<f64, InvalidInput> {
    gust.validate(field)?;
    Ok(match *gust {
        Gust::Intensity {
            turbulence_intensity,
            peak_factor,
        } => 1.0 + peak_factor * turbulence_intensity,
        Gust::AtReference { gust_m_s } => {
            let u = mean.speed_m_s(reference_height_m).abs();
            if u > 0.0 {
                gust_m_s / u
            } else if gust_m_s == 0.0 {
                1.0
            } else {
                return Err(InvalidInput::new(
                    format!("{field}.gust_m_s"),
                    format!(
                        "the mean wind is zero at the reference height {reference_height_m:.1} m, so a gust of {gust_m_s} m/s cannot scale it; give a uniform flow or turbulence_intensity_nondim"
                    ),
                ));
            }
        }
    })
}

/// The mean profile with every speed scaled by `factor` (see the module docs).
pub fn scaled_profile(mean: &WindProfile, factor: f64) -> WindProfile {
    match mean {
        WindProfile::Flow(SteadyFlow::Uniform { speed_m_s }) => {
            WindProfile::Flow(SteadyFlow::Uniform {
                speed_m_s: speed_m_s * factor,
            })
        }
        WindProfile::Flow(SteadyFlow::PowerLaw {
            coefficient,
            exponent,
        }) => WindProfile::Flow(SteadyFlow::PowerLaw {
            coefficient: coefficient * factor,
            exponent: *exponent,
        }),
        WindProfile::Flow(SteadyFlow::Tabulated {
            elevations_m,
            speeds_m_s,
        }) => WindProfile::Flow(SteadyFlow::Tabulated {
            elevations_m: elevations_m.clone(),
            speeds_m_s: speeds_m_s.iter().map(|u| u * factor).collect(),
        }),
        &WindProfile::LogLaw {
            reference_speed_m_s,
            reference_height_m,
            roughness_length_m,
        } => WindProfile::LogLaw {
            reference_speed_m_s: reference_speed_m_s * factor,
            reference_height_m,
            roughness_length_m,
        },
    }
}

/// The gust profile of `mean` (a uniform mean with a gust speed becomes
/// that uniform speed exactly, blowing the mean's way).
pub fn gust_profile(
    gust: &Gust,
    mean: &WindProfile,
    field: &str,
) -> Result<WindProfile, InvalidInput> {
    gust_profile_at(gust, mean, reference_height_m(mean), field)
}

/// [`gust_profile`] with a gust speed given at `reference_height_m`.
pub fn gust_profile_at(
    gust: &Gust,
    mean: &WindProfile,
    reference_height_m: f64,
    field: &str,
) -> Result<WindProfile, InvalidInput> {
    if let (Gust::AtReference { gust_m_s }, WindProfile::Flow(SteadyFlow::Uniform { speed_m_s })) =
        (gust, mean)
    {
        gust.validate(field)?;
        return Ok(WindProfile::uniform(if *speed_m_s < 0.0 {
            -gust_m_s
        } else {
            *gust_m_s
        }));
    }
    Ok(scaled_profile(
        mean,
        gust_factor_at(gust, mean, reference_height_m, field)?,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gust_of_a_uniform_flow_is_u_times_one_plus_k_i() {
        let g = Gust::Intensity {
            turbulence_intensity: 0.15,
            peak_factor: 3.0,
        };
        let p = gust_profile(&g, &WindProfile::uniform(8.0), "wind.gust").unwrap();
        assert_eq!(p, WindProfile::uniform(8.0 * (1.0 + 3.0 * 0.15)));
        let p = gust_profile(
            &Gust::AtReference { gust_m_s: 13.0 },
            &WindProfile::uniform(8.0),
            "wind.gust",
        )
        .unwrap();
        assert_eq!(p, WindProfile::uniform(13.0));
    }

    #[test]
    fn zero_intensity_is_the_mean_profile_bit_for_bit() {
        let zero = Gust::Intensity {
            turbulence_intensity: 0.0,
            peak_factor: 3.0,
        };
        for mean in [
            WindProfile::uniform(7.3),
            WindProfile::log_law(6.1, 10.0, 0.03, "w").unwrap(),
            WindProfile::Flow(SteadyFlow::PowerLaw {
                coefficient: 3.1,
                exponent: 0.14,
            }),
        ] {
            assert_eq!(gust_profile(&zero, &mean, "wind.gust").unwrap(), mean);
        }
    }

    #[test]
    fn a_gust_speed_scales_a_log_law_at_its_reference_height() {
        let mean = WindProfile::log_law(6.0, 10.0, 0.03, "w").unwrap();
        let p = gust_profile(&Gust::AtReference { gust_m_s: 9.0 }, &mean, "wind.gust").unwrap();
        assert!((p.speed_m_s(10.0) - 9.0).abs() < 1e-12);
        assert!((p.speed_m_s(500.0) / mean.speed_m_s(500.0) - 1.5).abs() < 1e-12);
        let calm = WindProfile::log_law(0.0, 10.0, 0.03, "w").unwrap();
        let e = gust_profile(&Gust::AtReference { gust_m_s: 9.0 }, &calm, "wind.gust").unwrap_err();
        assert_eq!(e.field, "wind.gust.gust_m_s");
    }
}
