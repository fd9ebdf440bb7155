//! Speed of the linear-string core (issue targets in brackets), thesis data:
//! full-spectrum stability solve n = 50 [≤ 3 ms] and n = 200 [≤ 80 ms];
//! constant-rate critical time to 1e-9 in length [≤ 50 µs]; chart of
//! 100 rates × 3 buoyancies on rayon [≤ 20 ms on 2 cores]; constant-
//! acceleration critical time [≤ 20 ms].

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use tetherplan::numerics::parallel::Parallelism;
use tetherplan::numerics::params::{AerostatSystem, Kinematics};
use tetherplan::numerics::profile::Profile;
use tetherplan::numerics::string::StringModel;
use tetherplan::numerics::string::chart;
use tetherplan::numerics::string::critical::{self, SearchConfig, constant_rate_lengthening};

fn benches(c: &mut Criterion) {
    let sys = AerostatSystem::thesis();
    let state = sys.to_nondim(Kinematics {
        length_m: 500.0,
        rate_m_s: 10.0,
        acceleration_m_s2: 0.0,
    });
    for n in [50, 200] {
        let model = StringModel::new(sys, n).unwrap();
        c.bench_function(&format!("stability_full_spectrum_n{n}"), |b| {
            b.iter(|| model.spectrum(black_box(state)).unwrap())
        });
    }
    let model = StringModel::new(sys, 50).unwrap();
    c.bench_function("critical_time_constant_rate_n50", |b| {
        b.iter(|| constant_rate_lengthening(&model, black_box(10.0), None))
    });
    c.bench_function("critical_time_constant_rate_confirmed_by_qep_n50", |b| {
        let p = Profile::constant_rate(1.0, 10.0, None).unwrap();
        b.iter(|| {
            critical::critical_time(
                &model,
                black_box(&p),
                SearchConfig {
                    confirm_with_qep: true,
                },
            )
            .unwrap()
        })
    });
    c.bench_function("critical_time_constant_acceleration_n50", |b| {
        let p = Profile::constant_acceleration(1.0, 0.5, None).unwrap();
        b.iter(|| critical::critical_time(&model, black_box(&p), SearchConfig::default()).unwrap())
    });
    c.bench_function("safe_rate_n50", |b| {
        b.iter(|| critical::safe_rate(&model, black_box(1200.0)).unwrap())
    });
    let rates = chart::rate_grid(1.0, 100.0, 100).unwrap();
    c.bench_function("chart_100x3_n50_rayon", |b| {
        b.iter(|| {
            chart::deployment_chart(
                &sys,
                50,
                black_box(&rates),
                &[500.0, 1000.0, 2000.0],
                Parallelism::Rayon,
                &|_, _| {},
            )
            .unwrap()
        })
    });
}

criterion_group!(string, benches);
criterion_main!(string);
