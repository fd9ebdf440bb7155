//! The converged, conservative stability criterion of the GE tether in a
//! steady wind (issue 21): the string criterion of the continuum tether in
//! that wind, `T_min(L) − ρA v² > 0`, because the local GE onset does not
//! exist there as a usable limit.
//!
//! **Why not the GE spectrum in wind.** In calm air the sliding tether
//! loses stability by divergence where its effective tension `T − ρA v²`
//! vanishes at the guide (plus the bending lift of the Airy layer,
//! [`super::airy_onset`]): a bifurcation of the straight state. In wind
//! the drag is a transverse load on that state, and the bifurcation is an
//! *imperfect* one. The continuum moving tether satisfies
//! `(T − ρA v²) κ = q_n` (normal load `q_n`, curvature `κ`): the
//! quasi-static blow-down is amplified by `T/(T − ρA v²)` and its
//! curvature at the winch grows without bound as the effective tension
//! there goes to zero; past it the string has no tensioned shape at all.
//! The GE model (small `EI`) shows exactly this on the branch continued
//! in the payout rate (`tests/verification_ge_wind_onset.rs`,
//! [`super::qs_wind_onset`]; thesis tether, EI = 1 N m², 1000 m): in
//! 8 m/s the aerostat is 5 % lower at 42 m/s and down at the guide's
//! height near 175 m/s, with no onset of the local QEP up to 190 m/s on
//! 20, 40 or 80 elements; in 2 m/s the first QEP instability is at
//! 173–177 m/s with a crossing frequency that does not converge (0.65 /
//! 2.28 / 6.53 rad/s), a mesh artifact of a collapsed state; only near
//! calm (0.1 m/s) is the onset the calm divergence (55.10 ± 0.03 m/s
//! against 55.18 in calm air and the string's 54.87). So the linear onset
//! jumps from ≈ 56 to ≈ 175 m/s between 0.1 and 2 m/s of wind: not a
//! criterion an operator may act on.
//!
//! **The criterion.** In wind the critical payout rate at a length is the
//! string's `√(T_min/ρA)` and the critical length at a rate the root of
//! `T_min(L) = ρA v²` (bisected to [`string_onset::LENGTH_RTOL`]), with
//! `T_min` the smallest tension of the static continuum tether of the same
//! GE system ([`super::qs_wind::continuum_problem`]: 0.007 % from MoorDyn;
//! the GE branch converges to it at second order). It is on the safe side
//! of the moving tether's own effective tension (blown further down, it
//! carries less of its weight along itself, so its winch effective tension
//! is at least the static one less `ρA v²`) and of the GE onset (bending
//! only lifts it: `EI^(1/3)`, 0.2 % of the length at EI = 1 N m²), and it
//! tends to the calm string criterion as the wind falls. Its error is the
//! bisection width (the RK4 shooting's own is below 10⁻⁸ relative):
//! `converged` always.

use super::GeModel;
use super::air_load::AirLoads;
use super::qs_converged::{ConvergedOnset, ConvergedOutcome, ConvergedSearch, OnsetKind};
use super::qs_critical::OnsetState;
use super::qs_wind::continuum_problem;
use crate::numerics::params::InvalidInput;
use crate::numerics::tether::equilibrium::{EquilibriumConfig, EquilibriumProblem};
use crate::numerics::tether::string_onset::{self, LENGTH_RTOL, StringLengthOnset};

/// What the answers call this criterion.
pub const WIND_CRITERION: &str = "string_in_wind";

fn config() -> EquilibriumConfig {
    EquilibriumConfig {
        keep_shape: false,
        ..EquilibriumConfig::default()
    }
}

fn state(problem: &EquilibriumProblem) -> OnsetState {
    match problem.solve(&config()) {
        Ok(e) => OnsetState {
            root_axial_force_n: e.winch_tension_n,
            tip_altitude_m: e.altitude_m,
            tip_downwind_m: e.downwind_m,
        },
        Err(_) => OnsetState {
            root_axial_force_n: f64::NAN,
            tip_altitude_m: f64::NAN,
            tip_downwind_m: f64::NAN,
        },
    }
}

fn during(value: f64, error: f64, at: OnsetState, equilibria: usize) -> ConvergedSearch {
    ConvergedSearch {
        outcome: ConvergedOutcome::During(ConvergedOnset {
            value,
            error_estimate: error,
            safe_value: value - error,
            converged: true,
            order: f64::NAN,
            levels: Vec::new(),
            first_elements: Vec::new(),
            at_safe: at,
            kind: OnsetKind::Divergence,
            frequency_rad_s: None,
        }),
        flutter: None,
        equilibria,
    }
}

/// The critical length at payout rate `rate_m_s` over `[lo, hi]` (m).
pub fn critical_length(
    model: &GeModel,
    net_buoyancy_n: f64,
    air: &AirLoads,
    rate_m_s: f64,
    (lo, hi): (f64, f64),
) -> Result<ConvergedSearch, InvalidInput> {
    let base = continuum_problem(model, air, net_buoyancy_n, lo);
    let onset = string_onset::critical_length(&base, rate_m_s, (lo, hi), &config())?;
    let bisections = (((hi - lo) / (LENGTH_RTOL * hi)).log2().ceil().max(0.0)) as usize + 2;
    Ok(match onset {
        StringLengthOnset::During { length_m } => {
            let error = LENGTH_RTOL * length_m;
            let at = state(&continuum_problem(
                model,
                air,
                net_buoyancy_n,
                length_m - error,
            ));
            during(length_m, error, at, bisections + 1)
        }
        StringLengthOnset::Never { up_to_m } => ConvergedSearch {
            outcome: ConvergedOutcome::Never { up_to: up_to_m },
            flutter: None,
            equilibria: 2,
        },
        StringLengthOnset::Immediate => ConvergedSearch {
            outcome: ConvergedOutcome::Immediate,
            flutter: None,
            equilibria: 1,
        },
    })
}

/// The critical payout rate at `length_m` (m/s), `Never` up to
/// `rate_max_m_s` when the string's is above it, `Immediate` when the
/// tether is slack (or unsolved) at rest.
pub fn critical_rate(
    model: &GeModel,
    net_buoyancy_n: f64,
    air: &AirLoads,
    length_m: f64,
    rate_max_m_s: f64,
) -> Result<ConvergedSearch, InvalidInput> {
    let p = continuum_problem(model, air, net_buoyancy_n, length_m);
    let Some(v) = string_onset::critical_rate_m_s(&p, &config())? else {
        return Ok(ConvergedSearch {
            outcome: ConvergedOutcome::Immediate,
            flutter: None,
            equilibria: 1,
        });
    };
    if v > rate_max_m_s {
        return Ok(ConvergedSearch {
            outcome: ConvergedOutcome::Never {
                up_to: rate_max_m_s,
            },
            flutter: None,
            equilibria: 1,
        });
    }
    // the closed form of a solved tension: its error is the shooting's,
    // below 10⁻⁸ relative; stated as 10⁻⁸ of the rate
    Ok(during(v, 1e-8 * v, state(&p), 2))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::ge::{Section, TipBody};
    use crate::numerics::tether::WindProfile;

    fn model() -> GeModel {
        let s = Section::new(1e6, 1e6, 1.0, 0.078, 0.078 * 0.005 * 0.005 / 16.0).unwrap();
        GeModel::new(
            s,
            20,
            TipBody {
                mass_kg: 10.0,
                link_length_m: 0.0,
            },
            9.81,
        )
        .unwrap()
    }

    fn air(u: f64) -> AirLoads {
        AirLoads {
            wind: WindProfile::uniform(u),
            air_density_kg_m3: 1.225,
            cable_diameter_m: 0.005,
            cable_normal_drag_coefficient: 1.2,
            aerostat_drag_area_m2: 0.9,
            aerostat_lift_area_m2: 0.0,
        }
    }

    /// The rate at a length and the length at that rate invert each other,
    /// and the onset state's winch tension is ρA v² there.
    #[test]
    fn rate_and_length_invert_each_other() {
        let m = model();
        let ConvergedOutcome::During(r) = critical_rate(&m, 1000.0, &air(8.0), 1000.0, 500.0)
            .unwrap()
            .outcome
        else {
            panic!()
        };
        // √(T_min/ρA) of the 8 m/s tether at 1000 m: 61.14 m/s (the
        // 20-element GE guide force gave 61.1)
        assert!((r.value - 61.14).abs() < 0.01, "{}", r.value);
        assert!(r.safe_value < r.value && r.converged);
        let c = critical_length(&m, 1000.0, &air(8.0), r.value, (10.0, 1200.0)).unwrap();
        let ConvergedOutcome::During(l) = c.outcome else {
            panic!("{:?}", c.outcome)
        };
        assert!((l.value - 1000.0).abs() < 1e-4, "{}", l.value);
        assert!(l.safe_value <= l.value && l.safe_value > l.value - 1e-5);
        let t = l.at_safe.root_axial_force_n;
        assert!((t - 0.078 * r.value * r.value).abs() < 1e-3, "{t}");
    }

    /// Calm air is the string's closed form (F/ρA − v²)/g.
    #[test]
    fn calm_is_the_closed_form() {
        let c = critical_length(&model(), 1000.0, &air(0.0), 10.0, (1.0, 3000.0)).unwrap();
        let ConvergedOutcome::During(l) = c.outcome else {
            panic!()
        };
        let closed = (1000.0 / 0.078 - 100.0) / 9.81;
        assert!(
            (l.value - closed).abs() < 1e-6 * closed,
            "{} vs {closed}",
            l.value
        );
    }
}
