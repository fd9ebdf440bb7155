//! One hour of a forecast as a steady flow (SPEC §12): the mean speeds at
//! their heights become
//!
//! * a **power law** `U(z) = a (z/z_ref)^p` fitted through two or more
//!   heights by least squares in `(ln z, ln U)` (exact through two), `z_ref`
//!   the lowest height, `p` kept within the §9 bounds `[0, 2]` (a wind that
//!   drops with height is fitted with `p = 0`: the geometric mean of the
//!   speeds, uniform);
//! * a **log law** `U(z) = U_ref ln(z/z0)/ln(z_ref/z0)` of a stated
//!   roughness length `z0` through one height;
//! * a **uniform** flow when every height has the same speed (that speed
//!   exactly; calm when it is zero).
//!
//! Heights whose speed is zero are left out of the fit (the logarithm of
//! zero): one positive speed gives the log law through it. The hour's gust
//! ratio is its gust over the mean at the gust's height (the measured mean
//! there when the hour has one, else the fitted flow's), at least 1; the
//! gust profile is the mean profile times that ratio (SPEC §10), so the gust
//! speed at the flow's reference height is `ratio × U(z_ref)`. A gust over
//! a calm hour (every speed zero) is left out: the §9 gust scales the mean
//! flow and a calm flow has nothing to scale (the answer says so).

/// A fitted steady flow (SI).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FittedFlow {
    Uniform {
        speed_m_s: f64,
    },
    PowerLaw {
        coefficient_m_s: f64,
        exponent_nondim: f64,
        reference_height_m: f64,
    },
    LogLaw {
        speed_m_s: f64,
        reference_height_m: f64,
        roughness_length_m: f64,
    },
}

impl FittedFlow {
    /// The mean speed at height `z_m` (m/s).
    pub fn speed_m_s(&self, z_m: f64) -> f64 {
        match *self {
            Self::Uniform { speed_m_s } => speed_m_s,
            Self::PowerLaw {
                coefficient_m_s,
                exponent_nondim,
                reference_height_m,
            } => coefficient_m_s * (z_m.max(0.0) / reference_height_m).powf(exponent_nondim),
            Self::LogLaw {
                speed_m_s,
                reference_height_m,
                roughness_length_m,
            } => {
                if z_m <= roughness_length_m {
                    0.0
                } else {
                    speed_m_s * (z_m / roughness_length_m).ln()
                        / (reference_height_m / roughness_length_m).ln()
                }
            }
        }
    }

    /// The height the flow's speed (and a gust speed) refers to (m); 10 m
    /// (the anemometer height) for a uniform flow.
    pub fn reference_height_m(&self) -> f64 {
        match *self {
            Self::Uniform { .. } => 10.0,
            Self::PowerLaw {
                reference_height_m, ..
            }
            | Self::LogLaw {
                reference_height_m, ..
            } => reference_height_m,
        }
    }
}

/// One hour's flow and gust.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FittedHour {
    pub flow: FittedFlow,
    /// Gust over mean (≥ 1); `None` without a gust, or over a calm hour.
    pub gust_ratio_nondim: Option<f64>,
    /// The gust speed at the flow's reference height (m/s); `None` without a gust.
    pub gust_at_reference_m_s: Option<f64>,
    /// Whether the fitted exponent was brought into `[0, 2]`.
    pub exponent_clamped: bool,
    /// Whether the gust was below the mean at its height (taken as the
    /// mean: ratio 1).
    pub gust_below_mean: bool,
}

/// Why an hour has no flow.
#[derive(Clone, Debug, PartialEq)]
pub enum FitError {
    /// No speed at all.
    NoWind,
    /// A height or speed that is not a finite number ≥ 0 (height > 0).
    Invalid { index: usize, what: &'static str },
    /// The one height of a log law at or below the roughness length.
    BelowRoughness {
        height_m: f64,
        roughness_length_m: f64,
    },
}

/// Largest power-law exponent (SPEC §9 bounds of `exponent_nondim`).
pub const MAX_EXPONENT: f64 = 2.0;

/// Fits one hour: `winds` the mean speeds `(height_m, speed_m_s)`, `gust`
/// an optional `(height_m, speed_m_s)`, `roughness_length_m` the log law's
/// `z0`.
pub fn fit_hour(
    winds: &[(f64, f64)],
    gust: Option<(f64, f64)>,
    roughness_length_m: f64,
) -> Result<FittedHour, FitError> {
    if winds.is_empty() {
        return Err(FitError::NoWind);
    }
    for (i, &(z, u)) in winds.iter().enumerate() {
        if !(z.is_finite() && z > 0.0) {
            return Err(FitError::Invalid {
                index: i,
                what: "height",
            });
        }
        if !(u.is_finite() && u >= 0.0) {
            return Err(FitError::Invalid {
                index: i,
                what: "speed",
            });
        }
    }
    let mut positive: Vec<(f64, f64)> = winds.iter().copied().filter(|w| w.1 > 0.0).collect();
    positive.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut clamped = false;
    let flow = match positive.len() {
        0 => FittedFlow::Uniform { speed_m_s: 0.0 },
        1 => {
            let (z, u) = positive[0];
            if z <= roughness_length_m {
                return Err(FitError::BelowRoughness {
                    height_m: z,
                    roughness_length_m,
                });
            }
            FittedFlow::LogLaw {
                speed_m_s: u,
                reference_height_m: z,
                roughness_length_m,
            }
        }
        _ if positive.iter().all(|w| w.1 == positive[0].1) => FittedFlow::Uniform {
            // The same speed at every height: that speed exactly.
            speed_m_s: positive[0].1,
        },
        _ => {
            let z_ref = positive[0].0;
            let (p, a, c) = power_law_fit(&positive, z_ref);
            clamped = c;
            FittedFlow::PowerLaw {
                coefficient_m_s: a,
                exponent_nondim: p,
                reference_height_m: z_ref,
            }
        }
    };
    let mut gust_below_mean = false;
    let (ratio, at_ref) = match gust {
        None => (None, None),
        Some((zg, g)) => {
            if !(g.is_finite() && g >= 0.0 && zg.is_finite() && zg > 0.0) {
                return Err(FitError::Invalid {
                    index: winds.len(),
                    what: "gust",
                });
            }
            let measured = winds.iter().find(|w| w.0 == zg && w.1 > 0.0).map(|w| w.1);
            let mean = measured.unwrap_or_else(|| flow.speed_m_s(zg));
            if mean > 0.0 {
                gust_below_mean = g < mean;
                let r = (g / mean).max(1.0);
                (Some(r), Some(r * flow.speed_m_s(flow.reference_height_m())))
            } else {
                // Calm: the §9 gust scales the mean, so there is nothing to scale.
                (None, None)
            }
        }
    };
    Ok(FittedHour {
        flow,
        gust_ratio_nondim: ratio,
        gust_at_reference_m_s: at_ref,
        exponent_clamped: clamped,
        gust_below_mean,
    })
}

/// Least squares of `ln U = ln a + p ln(z/z_ref)` through `points` (at
/// least two distinct heights, speeds > 0): `(p, a, clamped)`, `p` within
/// `[0, MAX_EXPONENT]` and `a` refitted for a clamped `p`.
fn power_law_fit(points: &[(f64, f64)], z_ref: f64) -> (f64, f64, bool) {
    let n = points.len() as f64;
    let xs: Vec<f64> = points.iter().map(|p| (p.0 / z_ref).ln()).collect();
    let ys: Vec<f64> = points.iter().map(|p| p.1.ln()).collect();
    let mx = xs.iter().sum::<f64>() / n;
    let my = ys.iter().sum::<f64>() / n;
    let sxx: f64 = xs.iter().map(|x| (x - mx) * (x - mx)).sum();
    let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let raw = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    let p = raw.clamp(0.0, MAX_EXPONENT);
    let clamped = p != raw;
    // For a fixed p the intercept is the mean of ln U − p x.
    let ln_a = my - p * mx;
    (p, ln_a.exp(), clamped)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_heights_give_the_power_law_through_both() {
        // U = 5 (z/10)^(1/7) at 10 m and 80 m.
        let p = 1.0 / 7.0;
        let u80 = 5.0 * 8f64.powf(p);
        let h = fit_hour(&[(10.0, 5.0), (80.0, u80)], None, 0.03).unwrap();
        let FittedFlow::PowerLaw {
            coefficient_m_s,
            exponent_nondim,
            reference_height_m,
        } = h.flow
        else {
            panic!("{h:?}")
        };
        assert!((exponent_nondim - p).abs() < 1e-14);
        assert!((coefficient_m_s - 5.0).abs() < 1e-13);
        assert_eq!(reference_height_m, 10.0);
        assert!((h.flow.speed_m_s(80.0) - u80).abs() < 1e-13);
    }

    #[test]
    fn one_height_gives_the_log_law_and_the_gust_scales_it() {
        let h = fit_hour(&[(10.0, 6.0)], Some((10.0, 9.0)), 0.03).unwrap();
        assert_eq!(
            h.flow,
            FittedFlow::LogLaw {
                speed_m_s: 6.0,
                reference_height_m: 10.0,
                roughness_length_m: 0.03
            }
        );
        assert_eq!(h.gust_ratio_nondim, Some(1.5));
        // 6 × 1.5 in floating point.
        assert!((h.gust_at_reference_m_s.unwrap() - 9.0).abs() < 1e-12);
        // Log law closed form at 100 m: 6 ln(100/0.03)/ln(10/0.03).
        let want = 6.0 * (100.0f64 / 0.03).ln() / (10.0f64 / 0.03).ln();
        assert!((h.flow.speed_m_s(100.0) - want).abs() < 1e-13);
    }

    #[test]
    fn calm_hours_and_falling_winds() {
        let h = fit_hour(&[(10.0, 0.0), (80.0, 0.0)], Some((10.0, 4.0)), 0.03).unwrap();
        assert_eq!(h.flow, FittedFlow::Uniform { speed_m_s: 0.0 });
        assert_eq!(h.gust_at_reference_m_s, None);
        let h = fit_hour(&[(10.0, 8.0), (80.0, 2.0)], None, 0.03).unwrap();
        assert!(h.exponent_clamped);
        // p = 0: the geometric mean, √(8·2) = 4.
        assert!((h.flow.speed_m_s(500.0) - 4.0).abs() < 1e-14);
        assert_eq!(fit_hour(&[], None, 0.03), Err(FitError::NoWind));
        // A gust below the mean is taken as the mean (ratio 1).
        let h = fit_hour(&[(10.0, 8.0)], Some((10.0, 7.0)), 0.03).unwrap();
        assert_eq!(h.gust_ratio_nondim, Some(1.0));
    }
}
