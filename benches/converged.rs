//! Speed of the converged linear-string answers (issue 10 targets in
//! brackets), thesis data, default tolerance 1e-4: constant-rate critical
//! time [≤ 50 µs]; chart of 100 rates × 3 buoyancies = 300 points on rayon
//! [≤ 10 ms on 2 cores]; constant-acceleration critical time with its QEP
//! confirmation [≤ 5 ms]; safe rate to 1200 m.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use tetherplan::numerics::chart::{self, Discretisation, Parallelism};
use tetherplan::numerics::params::AerostatSystem;
use tetherplan::numerics::string::converged::{self, DEFAULT_RELATIVE_TOLERANCE as TOL};

fn benches(c: &mut Criterion) {
    let sys = AerostatSystem::thesis();
    c.bench_function("converged_critical_time_constant_rate", |b| {
        b.iter(|| converged::constant_rate(&sys, black_box(10.0), None, TOL))
    });
    c.bench_function("converged_critical_time_constant_acceleration", |b| {
        b.iter(|| converged::constant_acceleration(&sys, black_box(0.5), None, TOL).unwrap())
    });
    c.bench_function("converged_safe_rate", |b| {
        b.iter(|| converged::safe_rate(&sys, black_box(1200.0), TOL).unwrap())
    });
    let rates = chart::rate_grid(1.0, 100.0, 100).unwrap();
    c.bench_function("converged_chart_300_rayon", |b| {
        b.iter(|| {
            chart::deployment_chart_with(
                &sys,
                Discretisation::Converged {
                    relative_tolerance: TOL,
                },
                black_box(&rates),
                &[500.0, 1000.0, 2000.0],
                Parallelism::Rayon,
                &|_, _| {},
            )
            .unwrap()
        })
    });
}

criterion_group!(converged_benches, benches);
criterion_main!(converged_benches);
