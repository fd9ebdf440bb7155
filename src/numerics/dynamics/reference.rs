//! The reference case of issue 23, defined once for every place that runs
//! it (the unit tests here, `tests/verification_dynamics.rs`,
//! `tests/peer_moordyn.rs` and `benches/dynamics.rs`): a 1000 m tether of
//! 0.078 kg/m and 5 mm (`C_n` = 1.2, EA = 1 MN, Kelvin–Voigt c = 10 kN s)
//! under an aerostat of net buoyancy 1000 N and mass 10 kg (`C_D A` =
//! 0.3 × 20 m², no lift, `C_a` = 0.5), in air of 1.225 kg/m³ at
//! g = 9.81 m/s².

use super::problem::{Aerostat, DynamicsConfig, DynamicsProblem, LengthSchedule, Tether};
use super::wind::{GustHistory, SpectrumModel, Turbulence};
use crate::numerics::tether::wind::WindProfile;

/// Length of the reference tether (m).
pub const REFERENCE_LENGTH_M: f64 = 1000.0;

/// The reference tether at a fixed length in a uniform steady wind
/// (m/s), drag on the stretched length (SPEC §6).
pub fn reference_problem(wind_m_s: f64) -> DynamicsProblem {
    DynamicsProblem {
        tether: Tether {
            mass_per_length_kg_m: 0.078,
            diameter_m: 0.005,
            normal_drag_coefficient: 1.2,
            tangential_drag_coefficient: 0.0,
            axial_stiffness_n: 1e6,
            internal_damping_n_s: 1e4,
            drag_on_stretched_length: true,
        },
        aerostat: Aerostat {
            net_buoyancy_n: 1000.0,
            mass_kg: 10.0,
            reference_area_m2: 20.0,
            drag_coefficient: 0.3,
            lift_coefficient: 0.0,
            added_mass_coefficient: 0.5,
        },
        flow: WindProfile::uniform(wind_m_s),
        gusts: vec![],
        turbulence: None,
        air_density_kg_m3: 1.225,
        gravity_m_s2: 9.81,
        length: LengthSchedule::Fixed(REFERENCE_LENGTH_M),
    }
}

/// Duration of the gust case (s).
pub const GUST_CASE_DURATION_S: f64 = 300.0;
/// The gust case's mean wind (m/s), reached by a ramp over [`GUST_CASE_RAMP_S`].
pub const GUST_CASE_MEAN_M_S: f64 = 8.0;
pub const GUST_CASE_RAMP_S: f64 = 30.0;
/// Its `1 − cos` gust: start (s), duration (s), amplitude (m/s).
pub const GUST_CASE_GUST: (f64, f64, f64) = (200.0, 20.0, 6.0);

/// The gust case compared with MoorDyn (`tests/peer_moordyn.rs`): the
/// reference tether upright in calm air, drag on the unstretched length
/// (as MoorDyn puts it); a uniform wind ramps to 8 m/s over 30 s and a
/// `1 − cos` gust of +6 m/s over 20 s starts at 200 s; run for 300 s.
pub fn gust_case() -> DynamicsProblem {
    let mut p = reference_problem(0.0);
    p.tether.drag_on_stretched_length = false;
    let (start, duration, amplitude) = GUST_CASE_GUST;
    p.gusts = vec![
        GustHistory::Ramp {
            start_time_s: 0.0,
            duration_s: GUST_CASE_RAMP_S,
            change_m_s: GUST_CASE_MEAN_M_S,
        },
        GustHistory::OneMinusCosine {
            start_time_s: start,
            duration_s: duration,
            amplitude_m_s: amplitude,
        },
    ];
    p
}

/// The gust case's run: 50 segments, the default step, a sample at every
/// step (asked every 0.05 s, MoorDyn's coupling step) over
/// [`GUST_CASE_DURATION_S`].
pub fn gust_case_config() -> DynamicsConfig {
    DynamicsConfig {
        segments: 50,
        duration_s: GUST_CASE_DURATION_S,
        sample_interval_s: 0.05,
        ..Default::default()
    }
}

/// The turbulence case of the benchmark: the reference tether in a mean
/// 8 m/s with von Kármán turbulence of intensity 0.15 and length scale
/// 150 m from `seed`.
pub fn turbulence_case(seed: u64) -> DynamicsProblem {
    let mut p = reference_problem(8.0);
    p.turbulence = Some(Turbulence {
        model: SpectrumModel::VonKarman,
        intensity: 0.15,
        length_scale_m: 150.0,
        seed,
    });
    p
}
