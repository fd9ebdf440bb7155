//! Dynamic tether (SPEC §11): one hour of von Kármán turbulence (I = 0.15,
//! L_u = 150 m, mean 8 m/s) on the issue-23 tether (50 segments, 1000 m,
//! 0.078 kg/m, 5 mm, F = 1000 N, EA = 1 MN) at h = 0.05 s; and the 300 s
//! gust case of `tests/peer_moordyn.rs` (whose output prints MoorDyn's CPU
//! time on the same case, side by side).

use criterion::{Criterion, criterion_group, criterion_main};
use tetherplan::numerics::dynamics::{
    self, Aerostat, DynamicsConfig, DynamicsProblem, GustHistory, LengthSchedule, SpectrumModel,
    Tether, Turbulence,
};
use tetherplan::numerics::tether::wind::WindProfile;

fn problem() -> DynamicsProblem {
    DynamicsProblem {
        tether: Tether {
            mass_per_length_kg_m: 0.078,
            diameter_m: 0.005,
            normal_drag_coefficient: 1.2,
            tangential_drag_coefficient: 0.0,
            axial_stiffness_n: 1e6,
            internal_damping_n_s: 1e4,
            drag_on_stretched_length: false,
        },
        aerostat: Aerostat {
            net_buoyancy_n: 1000.0,
            mass_kg: 10.0,
            reference_area_m2: 20.0,
            drag_coefficient: 0.3,
            lift_coefficient: 0.0,
            added_mass_coefficient: 0.5,
        },
        flow: WindProfile::uniform(8.0),
        gusts: vec![],
        turbulence: None,
        air_density_kg_m3: 1.225,
        gravity_m_s2: 9.81,
        length: LengthSchedule::Fixed(1000.0),
    }
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("dynamics");
    g.sample_size(10);
    let mut turbulent = problem();
    turbulent.turbulence = Some(Turbulence {
        model: SpectrumModel::VonKarman,
        intensity: 0.15,
        length_scale_m: 150.0,
        seed: 7,
    });
    let hour = DynamicsConfig {
        duration_s: 3600.0,
        time_step_s: 0.05,
        sample_interval_s: 1.0,
        ..Default::default()
    };
    g.bench_function("hour_of_turbulence_50_segments", |b| {
        b.iter(|| dynamics::simulate(&turbulent, &hour).unwrap())
    });
    let mut gust = problem();
    gust.flow = WindProfile::calm();
    gust.gusts = vec![
        GustHistory::Ramp {
            start_time_s: 0.0,
            duration_s: 30.0,
            change_m_s: 8.0,
        },
        GustHistory::OneMinusCosine {
            start_time_s: 200.0,
            duration_s: 20.0,
            amplitude_m_s: 6.0,
        },
    ];
    let short = DynamicsConfig {
        duration_s: 300.0,
        time_step_s: 0.05,
        sample_interval_s: 0.05,
        ..Default::default()
    };
    g.bench_function("moordyn_gust_case_300s", |b| {
        b.iter(|| dynamics::simulate(&gust, &short).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
