//! The operating envelope (SPEC §6): static equilibria over a grid of wind
//! speed × tether length, each point judged against four limits, in this
//! order (the first one violated is the point's *binding limit*):
//!
//! 1. **slack** — part of the tether rests on the ground or its tension vanishes;
//! 2. **tension** — breaking strength / largest tension below the required factor;
//! 3. **ceiling** — the altitude above an operating ceiling;
//! 4. **min_altitude** — the altitude below a floor (terrain, airspace):
//!    with gusts the floor is judged on the gust's equilibrium, the lowest;
//! 5. **stability** — with a payout rate `v`: the continuum string criterion
//!    of SPEC §1 (`h* = (F/ρA − v²)/g`, i.e. unstable once the winch tension
//!    no longer exceeds the kinematic term `ρA v²`), applied to the smallest
//!    tension of the blown-down tether: stable iff `min T − ρA v² > 0`. In
//!    calm air this is exactly the closed-form `h*` of the linear string.
//!
//! Each point is the same computation as a single equilibrium (the shape is
//! not kept); points fan out on rayon and the result does not depend on it.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use rayon::prelude::*;

use crate::numerics::aero::SteadyFlow;
use crate::numerics::parallel::Parallelism;
use crate::numerics::params::{InvalidInput, require_finite, require_positive};
use crate::numerics::tether::equilibrium::{Equilibrium, EquilibriumConfig, EquilibriumProblem};
use crate::numerics::tether::wind::WindProfile;

/// Largest number of points of one envelope.
pub const MAX_ENVELOPE_POINTS: usize = 250_000;

/// How the wind speed of the grid sets the profile.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum WindShape {
    /// `U(z) = U`.
    Uniform,
    /// `U(z) = U (z/z_ref)^p`.
    PowerLaw {
        exponent: f64,
        reference_height_m: f64,
    },
    /// `U(z) = U ln(z/z0)/ln(z_ref/z0)`.
    LogLaw {
        roughness_length_m: f64,
        reference_height_m: f64,
    },
}

impl WindShape {
    /// The profile whose speed at the reference height is `speed_m_s`.
    pub fn profile(&self, speed_m_s: f64) -> WindProfile {
        match *self {
            Self::Uniform => WindProfile::uniform(speed_m_s),
            Self::PowerLaw {
                exponent,
                reference_height_m,
            } => WindProfile::Flow(SteadyFlow::PowerLaw {
                coefficient: speed_m_s / reference_height_m.powf(exponent),
                exponent,
            }),
            Self::LogLaw {
                roughness_length_m,
                reference_height_m,
            } => WindProfile::LogLaw {
                reference_speed_m_s: speed_m_s,
                reference_height_m,
                roughness_length_m,
            },
        }
    }
}

/// Why a point is outside the envelope.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Limit {
    Slack,
    Tension,
    Ceiling,
    /// The altitude below the floor `min_altitude_m`.
    MinAltitude,
    Stability,
    /// The shooting did not meet its tolerance (should not happen).
    NotConverged,
}

impl Limit {
    /// The limit of a [`Limit::name`].
    pub fn from_name(name: &str) -> Option<Self> {
        [
            Self::Slack,
            Self::Tension,
            Self::Ceiling,
            Self::MinAltitude,
            Self::Stability,
            Self::NotConverged,
        ]
        .into_iter()
        .find(|l| l.name() == name)
    }

    pub fn name(self) -> &'static str {
        match self {
            Self::Slack => "slack",
            Self::Tension => "tension",
            Self::Ceiling => "ceiling",
            Self::MinAltitude => "min_altitude",
            Self::Stability => "stability",
            Self::NotConverged => "not_converged",
        }
    }
}

/// The limits a point is judged against.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits {
    /// Required breaking strength / largest tension (used when the tether has a strength).
    pub required_safety_factor: f64,
    /// Highest allowed altitude (m).
    pub ceiling_m: Option<f64>,
    /// Lowest allowed altitude (m).
    pub min_altitude_m: Option<f64>,
    /// Payout rate for the stability criterion (m/s).
    pub payout_rate_m_s: Option<f64>,
    /// The largest tension judged at its dynamic value (a gust of a
    /// turbulence intensity, `docs/gust_check.md`); `None`: as it is.
    pub dynamic_tension: Option<crate::numerics::tether::gust::DynamicTension>,
}

impl Limits {
    /// The safety factor `eq` is judged on: breaking strength over its
    /// largest tension, taken at its dynamic value when asked.
    pub fn safety_factor(&self, eq: &Equilibrium) -> Option<f64> {
        let sf = eq.safety_factor?;
        Some(match &self.dynamic_tension {
            Some(d) => sf * eq.max_tension_n / d.max_tension_n(eq.max_tension_n),
            None => sf,
        })
    }
}

/// The verdict on one equilibrium.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Verdict {
    /// `min T − ρA v²` (N), when a payout rate is given.
    pub stability_margin_n: Option<f64>,
    pub stable: Option<bool>,
    /// The first limit violated; `None` inside the envelope.
    pub limit: Option<Limit>,
}

/// Judges one equilibrium (also used by the single-point answer).
pub fn judge(eq: &Equilibrium, mass_per_length_kg_m: f64, limits: &Limits) -> Verdict {
    let stability_margin_n = limits
        .payout_rate_m_s
        .map(|v| eq.min_tension_n - mass_per_length_kg_m * v * v);
    let stable = stability_margin_n.map(|m| m > 0.0 && !eq.slack);
    judge_with(eq, limits, stability_margin_n, stable)
}

/// Judges one equilibrium with a stability verdict made elsewhere (the
/// quasi-static GE of [`super::envelope_ge`]): the static limits first, in
/// the order of the module docs, then `stable`.
pub fn judge_with(
    eq: &Equilibrium,
    limits: &Limits,
    stability_margin_n: Option<f64>,
    stable: Option<bool>,
) -> Verdict {
    let limit = if !eq.converged {
        Some(Limit::NotConverged)
    } else if eq.slack || eq.min_tension_n <= 0.0 {
        Some(Limit::Slack)
    } else if limits
        .safety_factor(eq)
        .is_some_and(|f| f < limits.required_safety_factor)
    {
        Some(Limit::Tension)
    } else if limits.ceiling_m.is_some_and(|c| eq.altitude_m > c) {
        Some(Limit::Ceiling)
    } else if limits.min_altitude_m.is_some_and(|f| eq.altitude_m < f) {
        Some(Limit::MinAltitude)
    } else if stable == Some(false) {
        Some(Limit::Stability)
    } else {
        None
    };
    Verdict {
        stability_margin_n,
        stable,
        limit,
    }
}

/// The sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvelopeProblem {
    /// Cable, body, air and gravity; its `wind` and `tether_length_m` are replaced per point.
    pub base: EquilibriumProblem,
    pub wind: WindShape,
    pub wind_speeds_m_s: Vec<f64>,
    pub tether_lengths_m: Vec<f64>,
    pub limits: Limits,
}

/// One grid point.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvelopePoint {
    pub wind_speed_m_s: f64,
    pub tether_length_m: f64,
    pub equilibrium: Equilibrium,
    pub verdict: Verdict,
}

/// The envelope: points row by row (one row per wind speed, lengths inside).
#[derive(Clone, Debug, PartialEq)]
pub struct Envelope {
    pub points: Vec<EnvelopePoint>,
    /// Per length: the largest grid wind up to which every wind is inside
    /// (`None`: not even the lowest), and the limit met just above it.
    pub max_wind_per_length: Vec<(Option<f64>, Option<Limit>)>,
    /// Per wind: the highest altitude inside the envelope, and its length.
    pub max_altitude_per_wind: Vec<Option<(f64, f64)>>,
}

impl EnvelopeProblem {
    pub fn validate(&self) -> Result<(), InvalidInput> {
        self.base.validate()?;
        if self.wind_speeds_m_s.is_empty() || self.tether_lengths_m.is_empty() {
            return Err(InvalidInput::new(
                "wind_speeds_m_s",
                "the grid needs at least one wind speed and one tether length",
            ));
        }
        let n = self.wind_speeds_m_s.len() * self.tether_lengths_m.len();
        if n > MAX_ENVELOPE_POINTS {
            return Err(InvalidInput::new(
                "tether_lengths_m.count",
                format!("the envelope would have {n} points; at most {MAX_ENVELOPE_POINTS}"),
            ));
        }
        for (i, &u) in self.wind_speeds_m_s.iter().enumerate() {
            require_finite(&format!("wind_speeds_m_s[{i}]"), u)?;
        }
        for (i, &l) in self.tether_lengths_m.iter().enumerate() {
            require_positive(&format!("tether_lengths_m[{i}]"), l)?;
        }
        require_positive(
            "required_safety_factor_nondim",
            self.limits.required_safety_factor,
        )?;
        Ok(())
    }

    /// The single problem at one grid point.
    pub fn point_problem(&self, wind_speed_m_s: f64, tether_length_m: f64) -> EquilibriumProblem {
        EquilibriumProblem {
            wind: self.wind.profile(wind_speed_m_s),
            tether_length_m,
            ..self.base.clone()
        }
    }

    /// Computes the envelope; `progress(done, total)` after each wind row;
    /// `None` when `cancelled()` stopped it.
    pub fn solve(
        &self,
        config: &EquilibriumConfig,
        parallelism: Parallelism,
        progress: &(dyn Fn(usize, usize) + Sync),
        cancelled: &(dyn Fn() -> bool + Sync),
    ) -> Result<Option<Envelope>, InvalidInput> {
        self.validate()?;
        let config = EquilibriumConfig {
            keep_shape: false,
            ..*config
        };
        let total = self.wind_speeds_m_s.len();
        let done = AtomicUsize::new(0);
        let stop = AtomicBool::new(false);
        let row = |&u: &f64| -> Result<Vec<EnvelopePoint>, InvalidInput> {
            if stop.load(Ordering::Relaxed) || cancelled() {
                stop.store(true, Ordering::Relaxed);
                return Ok(Vec::new());
            }
            let out = self
                .tether_lengths_m
                .iter()
                .map(|&l| {
                    let eq = self.point_problem(u, l).solve(&config)?;
                    let verdict = judge(&eq, self.base.cable.mass_per_length_kg_m, &self.limits);
                    Ok(EnvelopePoint {
                        wind_speed_m_s: u,
                        tether_length_m: l,
                        equilibrium: eq,
                        verdict,
                    })
                })
                .collect::<Result<Vec<_>, _>>()?;
            progress(done.fetch_add(1, Ordering::Relaxed) + 1, total);
            Ok(out)
        };
        let rows: Vec<Vec<EnvelopePoint>> = match parallelism {
            Parallelism::Serial => self
                .wind_speeds_m_s
                .iter()
                .map(row)
                .collect::<Result<_, _>>()?,
            Parallelism::Rayon => self
                .wind_speeds_m_s
                .par_iter()
                .map(row)
                .collect::<Result<_, _>>()?,
        };
        if stop.load(Ordering::Relaxed) {
            return Ok(None);
        }
        Ok(Some(summarise(
            rows,
            &self.wind_speeds_m_s,
            self.tether_lengths_m.len(),
        )))
    }
}

/// The envelope from its rows (one per wind speed, in grid order).
pub fn summarise(rows: Vec<Vec<EnvelopePoint>>, winds: &[f64], lengths: usize) -> Envelope {
    // Winds in increasing order for "every wind up to".
    let mut order: Vec<usize> = (0..winds.len()).collect();
    order.sort_by(|&a, &b| winds[a].abs().total_cmp(&winds[b].abs()));
    let max_wind_per_length = (0..lengths)
        .map(|j| {
            let mut best = None;
            for &i in &order {
                match rows[i][j].verdict.limit {
                    None => best = Some(winds[i]),
                    Some(limit) => return (best, Some(limit)),
                }
            }
            (best, None)
        })
        .collect();
    let max_altitude_per_wind = rows
        .iter()
        .map(|row| {
            row.iter()
                .filter(|p| p.verdict.limit.is_none())
                .map(|p| (p.equilibrium.altitude_m, p.tether_length_m))
                .max_by(|a, b| a.0.total_cmp(&b.0))
        })
        .collect();
    Envelope {
        points: rows.into_iter().flatten().collect(),
        max_wind_per_length,
        max_altitude_per_wind,
    }
}
