//! Speed of the converged linear-string answers (issue 10 targets in
//! brackets), thesis data, default tolerance 1e-4: constant-rate critical
//! time [≤ 50 µs]; chart of 100 rates × 3 buoyancies = 300 points on rayon
//! [≤ 10 ms on 2 cores]; constant-acceleration critical time with its QEP
//! confirmation [≤ 5 ms]; safe rate to 1200 m. Also the dense QEP
//! spectrum on graded meshes of a few refinement levels: the
//! constant-acceleration answer spends most of its time in its four QEP
//! probes (faer's real Schur), the rest in tridiagonal inertia counts.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use tetherplan::numerics::parallel::Parallelism;
use tetherplan::numerics::params::AerostatSystem;
use tetherplan::numerics::string::StringModel;
use tetherplan::numerics::string::chart::{self, Discretisation};
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
    let state = sys.to_nondim(tetherplan::numerics::params::Kinematics {
        length_m: 1100.0,
        rate_m_s: 30.0,
        acceleration_m_s2: 0.5,
    });
    for level in [0, 4, 7, 10] {
        let model = StringModel::with_operators(sys, converged::graded_operators(level));
        c.bench_function(
            &format!(
                "qep_spectrum_graded_level_{level}_{}_elements",
                model.elements()
            ),
            |b| b.iter(|| model.spectrum(black_box(state)).unwrap()),
        );
    }
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
