//! Transient-run benchmarks (issue 4): a 150 s, n = 50 deployment with wind
//! and eigenvalues every second (target ≤ 1 s on one core), and a
//! 64-frequency response surface of that deployment (target ≤ 15 s on
//! 2 cores).

use criterion::{Criterion, criterion_group, criterion_main};

use tetherplan::numerics::aero::{Aerodynamics, AerostatBody, AirFlow, ForceModel, SteadyFlow};
use tetherplan::numerics::parallel::Parallelism;
use tetherplan::numerics::params::AerostatSystem;
use tetherplan::numerics::profile::Profile;
use tetherplan::numerics::string::StringModel;
use tetherplan::numerics::string::transient::{
    self, EigenTracking, InitialState, Silent, TransientConfig,
};

fn setup() -> (StringModel, Profile, TransientConfig) {
    let model = StringModel::new(AerostatSystem::thesis(), 50).unwrap();
    // the thesis's 1.1 km deployment: 10 m/s, 5 s ramps
    let profile = Profile::trapezoidal(1.0, 10.0, 5.0, 5.0, 1100.0).unwrap();
    let body = AerostatBody::new(0.5, 1.205, None).unwrap();
    let aero = Aerodynamics::new(
        AirFlow::Steady(SteadyFlow::power_law(0.1, 1.0 / 3.0).unwrap()),
        ForceModel::Drag {
            drag_coefficient: 0.5,
            reference_area_m2: body.frontal_area_m2(),
        },
        body,
        10.0,
    )
    .unwrap();
    let config = TransientConfig {
        duration_s: 150.0,
        time_step_s: None,
        samples: 1500,
        initial: InitialState::Rest,
        aero: Some(aero),
        eigen: Some(EigenTracking {
            interval_s: 1.0,
            count: 3,
        }),
    };
    (model, profile, config)
}

fn deployment(c: &mut Criterion) {
    let (model, profile, config) = setup();
    let mut group = c.benchmark_group("transient");
    group.sample_size(10);
    group.bench_function("deployment_150s_n50_wind_eigen_1s", |b| {
        b.iter(|| transient::simulate(&model, &profile, &config, &Silent).unwrap())
    });
    group.finish();
}

fn frequency_response(c: &mut Criterion) {
    let (model, profile, mut config) = setup();
    config.eigen = None;
    config.samples = 300;
    let frequencies: Vec<f64> = (1..=64).map(|i| 0.125 * i as f64).collect();
    let mut group = c.benchmark_group("transient");
    group.sample_size(10);
    group.bench_function("frequency_response_64_150s_n50_rayon", |b| {
        b.iter(|| {
            tetherplan::numerics::string::frequency_response::frequency_response(
                &model,
                &profile,
                &config,
                10.0,
                &frequencies,
                Parallelism::Rayon,
                &Silent,
            )
            .unwrap()
        })
    });
    group.finish();
}

criterion_group!(benches, deployment, frequency_response);
criterion_main!(benches);
