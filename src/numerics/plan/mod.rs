//! The deployment plan (SPEC §7): the fastest winch schedule `L(t)` that
//! keeps every instant stable with a lift reserve, within the winch limits
//! and within the tether's tension rating; the retrieval plan and the
//! growth of an oscillation while hauling in; the haul-down deadline under
//! a wind forecast.
//!
//! **Stability criterion** (continuum limit of the FE QEP, SPEC §1, §5).
//! With the net buoyancy reduced to `(1 − r)F`, the effective tension at
//! the roller, `T(0) − l̇²/l` of SPEC §1 in SI, is
//!
//! ```text
//! T_eff(L, L̇, L̈) = (1 − r)F − m L̈ − ρA (g + L̈) L − ρA L̇²      (N)
//! ```
//!
//! and the state is stable (the FE critical length converges to its zero
//! from above, so the criterion is the converged, conservative limit). The
//! plan keeps `T_eff ≥ ε (1 − r)F` with the safety margin
//! [`STABILITY_MARGIN`]. Accelerating payout lowers the rate ceiling
//! `√((T_eff + ρA L̇²)/ρA)`; braking raises it. With the air's data the
//! aerostat's own drag while it climbs is taken off too ([`ascent`]).
//!
//! **Tension.** The axial force is `T(x) = F − m L̈ − ρA (g + L̈)(L − x)`:
//! largest at the aerostat (`F − m L̈`) unless `L̈ < −g`; the winch holds
//! `T(0)`. With a rating, `max_x T(x) ≤ breaking strength / safety factor`.
//!
//! Modules: [`schedule`] (the forward/backward speed-profile pass, the
//! static-ceiling bound, the best constant-rate plan), [`retrieval`]
//! (WKB amplification, transient check of a schedule), [`deadline`] (wind
//! forecast → latest haul-down start).

pub mod air;
pub mod ascent;
pub mod boundary;
pub mod deadline;
pub mod ge_stability;
pub mod jerk;
pub mod pass;
pub mod retrieval;
pub mod schedule;
pub mod sparse;

use crate::numerics::params::{AerostatSystem, InvalidInput, require_positive};

/// Fraction of the reserve buoyancy `(1 − r)F` kept as effective tension
/// at the roller at every instant of a plan.
pub const STABILITY_MARGIN: f64 = 1e-3;
/// Largest winch rate accepted (m/s).
pub const MAX_WINCH_RATE_M_S: f64 = 1000.0;
/// Largest winch acceleration accepted (m/s²).
pub const MAX_WINCH_ACCELERATION_M_S2: f64 = 100.0;
/// Largest winch jerk accepted (m/s³).
pub const MAX_WINCH_JERK_M_S3: f64 = 1e4;
/// Largest lift reserve accepted.
pub const MAX_LIFT_RESERVE: f64 = 0.9;
/// Segments of the length grid of the speed-profile pass.
pub const DEFAULT_GRID_SEGMENTS: usize = 4000;
/// Largest target length accepted (m).
pub const MAX_TARGET_LENGTH_M: f64 = 1e6;

/// Winch limits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Winch {
    pub max_rate_m_s: f64,
    pub max_acceleration_m_s2: f64,
}

impl Winch {
    pub fn new(max_rate_m_s: f64, max_acceleration_m_s2: f64) -> Result<Self, InvalidInput> {
        require_positive("winch.max_rate_m_s", max_rate_m_s)?;
        require_positive("winch.max_acceleration_m_s2", max_acceleration_m_s2)?;
        if max_rate_m_s > MAX_WINCH_RATE_M_S {
            return Err(InvalidInput::new(
                "winch.max_rate_m_s",
                format!("must be at most {MAX_WINCH_RATE_M_S} m/s, got {max_rate_m_s}"),
            ));
        }
        if max_acceleration_m_s2 > MAX_WINCH_ACCELERATION_M_S2 {
            return Err(InvalidInput::new(
                "winch.max_acceleration_m_s2",
                format!(
                    "must be at most {MAX_WINCH_ACCELERATION_M_S2} m/s², got {max_acceleration_m_s2}"
                ),
            ));
        }
        Ok(Self {
            max_rate_m_s,
            max_acceleration_m_s2,
        })
    }
}

/// Checks a jerk limit (`winch.max_jerk_m_s3`).
pub fn validate_jerk(max_jerk_m_s3: f64) -> Result<f64, InvalidInput> {
    require_positive("winch.max_jerk_m_s3", max_jerk_m_s3)?;
    if max_jerk_m_s3 > MAX_WINCH_JERK_M_S3 {
        return Err(InvalidInput::new(
            "winch.max_jerk_m_s3",
            format!("must be at most {MAX_WINCH_JERK_M_S3} m/s³, got {max_jerk_m_s3}"),
        ));
    }
    Ok(max_jerk_m_s3)
}

/// What a plan must respect.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanProblem {
    /// The system at full buoyancy; `initial_length_m` is where the plan starts.
    pub system: AerostatSystem,
    pub target_length_m: f64,
    pub winch: Winch,
    /// `r`: stay stable with the net buoyancy reduced to `(1 − r)F`.
    pub lift_reserve: f64,
    /// Breaking strength / safety factor (N), if rated.
    pub allowable_tension_n: Option<f64>,
    /// Segments of the length grid.
    pub grid_segments: usize,
}

impl PlanProblem {
    pub fn new(
        system: AerostatSystem,
        target_length_m: f64,
        winch: Winch,
        lift_reserve: f64,
        allowable_tension_n: Option<f64>,
    ) -> Result<Self, InvalidInput> {
        require_positive("target_elevation_m", target_length_m)?;
        if target_length_m > MAX_TARGET_LENGTH_M {
            return Err(InvalidInput::new(
                "target_elevation_m",
                format!("must be at most {MAX_TARGET_LENGTH_M} m, got {target_length_m}"),
            ));
        }
        if target_length_m == system.initial_length_m {
            return Err(InvalidInput::new(
                "target_elevation_m",
                format!("equals initial_length_m ({target_length_m} m): there is nothing to plan"),
            ));
        }
        if !(lift_reserve.is_finite() && (0.0..=MAX_LIFT_RESERVE).contains(&lift_reserve)) {
            return Err(InvalidInput::new(
                "lift_reserve_nondim",
                format!("must be between 0 and {MAX_LIFT_RESERVE}, got {lift_reserve}"),
            ));
        }
        if let Some(t) = allowable_tension_n {
            require_positive("tether.breaking_strength_n", t)?;
        }
        Ok(Self {
            system,
            target_length_m,
            winch,
            lift_reserve,
            allowable_tension_n,
            grid_segments: DEFAULT_GRID_SEGMENTS,
        })
    }

    /// `+1` deploying (lengthening), `−1` retrieving.
    pub fn direction(&self) -> f64 {
        (self.target_length_m - self.system.initial_length_m).signum()
    }

    /// The same problem from `start` to `end` (a haul-down after a deployment).
    pub fn between(&self, start_m: f64, end_m: f64) -> Self {
        let mut p = *self;
        p.system.initial_length_m = start_m;
        p.target_length_m = end_m;
        p
    }

    /// Net buoyancy with the reserve taken off, `(1 − r)F` (N).
    pub fn reserve_buoyancy_n(&self) -> f64 {
        (1.0 - self.lift_reserve) * self.system.net_buoyancy_n
    }

    /// Length at which the cable weight equals the reserve buoyancy less the
    /// margin (m): no plan may end or start above it.
    pub fn lift_limit_m(&self) -> f64 {
        let s = &self.system;
        self.reserve_buoyancy_n() * (1.0 - STABILITY_MARGIN)
            / (s.mass_per_length_kg_m * s.gravity_m_s2)
    }

    /// Effective tension at the roller with the reserve (N): `≥ 0` is stable.
    pub fn effective_tension_n(&self, length_m: f64, rate_m_s: f64, accel_m_s2: f64) -> f64 {
        let s = &self.system;
        let rho_a = s.mass_per_length_kg_m;
        self.reserve_buoyancy_n()
            - s.aerostat_mass_kg * accel_m_s2
            - rho_a * (s.gravity_m_s2 + accel_m_s2) * length_m
            - rho_a * rate_m_s * rate_m_s
    }

    /// Largest stable rate at this length and acceleration with the reserve
    /// (m/s); 0 when even rest is unstable.
    pub fn rate_ceiling_m_s(&self, length_m: f64, accel_m_s2: f64) -> f64 {
        let rho_a = self.system.mass_per_length_kg_m;
        ((self.effective_tension_n(length_m, 0.0, accel_m_s2)) / rho_a)
            .max(0.0)
            .sqrt()
    }

    /// Axial tension at the winch, `F − m L̈ − ρA (g + L̈) L` (N), full buoyancy.
    pub fn winch_tension_n(&self, length_m: f64, accel_m_s2: f64) -> f64 {
        let s = &self.system;
        s.net_buoyancy_n
            - s.aerostat_mass_kg * accel_m_s2
            - s.mass_per_length_kg_m * (s.gravity_m_s2 + accel_m_s2) * length_m
    }

    /// Largest axial tension along the cable (N), full buoyancy.
    pub fn max_tension_n(&self, length_m: f64, accel_m_s2: f64) -> f64 {
        let top = self.system.net_buoyancy_n - self.system.aerostat_mass_kg * accel_m_s2;
        top.max(self.winch_tension_n(length_m, accel_m_s2))
    }

    /// Smallest `L̈` (m/s²) the tension rating allows at this length
    /// (`−∞` without a rating or when nothing binds).
    fn tension_accel_floor(&self, length_m: f64) -> f64 {
        let Some(allow) = self.allowable_tension_n else {
            return f64::NEG_INFINITY;
        };
        let s = &self.system;
        let (f, m, rho_a, g) = (
            s.net_buoyancy_n,
            s.aerostat_mass_kg,
            s.mass_per_length_kg_m,
            s.gravity_m_s2,
        );
        // F − m a ≤ allow and F − m a − ρA(g + a)L ≤ allow.
        let top = if m > 0.0 {
            (f - allow) / m
        } else if f > allow {
            f64::INFINITY
        } else {
            f64::NEG_INFINITY
        };
        let winch = (f - rho_a * g * length_m - allow) / (m + rho_a * length_m);
        top.max(winch)
    }
}

/// Why no schedule exists.
#[derive(Clone, Debug, PartialEq)]
pub enum BindingLimit {
    /// The end (or start) length exceeds the static lift limit with the reserve.
    StaticLift { length_m: f64, limit_m: f64 },
    /// The tension at rest already exceeds the allowable tension.
    Tension { tension_n: f64, allowable_n: f64 },
    /// In the gust (SPEC §10) the tension at rest exceeds the allowable
    /// tension, while the mean wind's is within it.
    GustTension {
        tension_n: f64,
        mean_tension_n: f64,
        allowable_n: f64,
    },
    /// Where the plan leaves the aerostat flying it is below the floor
    /// `min_altitude_m` (in the gust when there are gusts: the lowest).
    MinAltitude {
        altitude_m: f64,
        floor_m: f64,
        in_gust: bool,
    },
    /// A retrieval's oscillation growth exceeds the limit at every rate tried.
    Amplification { amplification: f64, limit: f64 },
    /// No jerk-limited schedule kept every limit after the tightenings.
    Jerk {
        max_jerk_m_s3: f64,
        stability_shortfall_n: f64,
        tension_excess_n: f64,
    },
    /// In wind the target altitude is above the highest the aerostat
    /// reaches within the lift limit (the tether is blown down).
    WindAltitude { altitude_m: f64, reachable_m: f64 },
    /// The end (or start) length exceeds the quasi-static GE maximum safe
    /// length with the reserve (the GE criterion's static limit).
    QuasiStaticGe { length_m: f64, limit_m: f64 },
    /// The local GE QEP found a checked sample unstable after the
    /// tightenings of the GE criterion.
    QuasiStaticGeCheck {
        time_s: f64,
        length_m: f64,
        rate_m_s: f64,
        max_real_1_s: f64,
    },
}

impl BindingLimit {
    /// Machine-readable name.
    pub fn name(&self) -> &'static str {
        match self {
            Self::StaticLift { .. } => "static_lift_limit",
            Self::Tension { .. } => "tension_limit",
            Self::GustTension { .. } => "gust_tension_limit",
            Self::MinAltitude { .. } => "min_altitude",
            Self::Amplification { .. } => "amplification_limit",
            Self::Jerk { .. } => "jerk_limit",
            Self::WindAltitude { .. } => "wind_blowdown",
            Self::QuasiStaticGe { .. } => "quasi_static_ge_limit",
            Self::QuasiStaticGeCheck { .. } => "quasi_static_ge_check",
        }
    }

    /// Plain-language reason.
    pub fn reason(&self, reserve: f64) -> String {
        match *self {
            Self::StaticLift { length_m, limit_m } => format!(
                "{length_m:.1} m exceeds the static lift limit with a {:.1} % lift reserve, {limit_m:.1} m: \
                 there the cable weight alone exceeds the reserve buoyancy, so the aerostat cannot even hang \
                 stably at rest",
                100.0 * reserve
            ),
            Self::Tension {
                tension_n,
                allowable_n,
            } => format!(
                "the tension at rest, {tension_n:.1} N, already exceeds the allowable tension \
                 (breaking strength / safety factor) of {allowable_n:.1} N"
            ),
            Self::GustTension {
                tension_n,
                mean_tension_n,
                allowable_n,
            } => format!(
                "in the gust the tension at rest, {tension_n:.1} N, exceeds the allowable tension \
                 (breaking strength / safety factor) of {allowable_n:.1} N (the mean wind's, {mean_tension_n:.1} N, \
                 is within it)"
            ),
            Self::MinAltitude {
                altitude_m,
                floor_m,
                in_gust,
            } => format!(
                "{} the aerostat is blown down to {altitude_m:.1} m where the plan leaves it, below the floor \
                 min_altitude_m = {floor_m:.1} m",
                if in_gust {
                    "in the gust"
                } else {
                    "in this wind"
                }
            ),
            Self::Amplification {
                amplification,
                limit,
            } => format!(
                "an oscillation grows by {amplification:.3}× over the retrieval, above the limit {limit:.3}×, \
                 even at the slowest rate tried; the WKB growth depends only on the start and end lengths"
            ),
            Self::Jerk {
                max_jerk_m_s3,
                stability_shortfall_n,
                tension_excess_n,
            } => format!(
                "no schedule with the jerk limit {max_jerk_m_s3} m/s³ kept every limit: after tightening the \
                 margins the S-curve still fell {stability_shortfall_n:.3} N short of the stability margin and \
                 exceeded the allowable tension by {tension_excess_n:.3} N"
            ),
            Self::WindAltitude {
                altitude_m,
                reachable_m,
            } => format!(
                "in this wind the tether is blown down: {altitude_m:.1} m is above the highest altitude reached \
                 within the lift limit with a {:.1} % lift reserve, {reachable_m:.1} m",
                100.0 * reserve
            ),
            Self::QuasiStaticGe { length_m, limit_m } => format!(
                "{length_m:.1} m exceeds the quasi-static GE maximum safe length with a {:.1} % lift reserve, \
                 {limit_m:.1} m: beyond it the geometrically exact tether is unstable even at rest (at a vanishing \
                 payout rate) in this air",
                100.0 * reserve
            ),
            Self::QuasiStaticGeCheck {
                time_s,
                length_m,
                rate_m_s,
                max_real_1_s,
            } => format!(
                "the local quasi-static GE check of the schedule found it unstable at t = {time_s:.2} s \
                 (L = {length_m:.1} m, L̇ = {rate_m_s:.2} m/s, growth rate {max_real_1_s:.3e} 1/s) even after \
                 tightening the GE criterion"
            ),
        }
    }
}
