//! The calm-air plan (SPEC §7, issue target ≤ 100 ms; awebox takes about
//! 4 s per solve of its problem): the speed-profile pass alone, and the
//! whole request (pass, bound, constant-rate comparison, FE transient check
//! of the schedule at 50 elements, haul-down deadline).

use criterion::{Criterion, criterion_group, criterion_main};
use serde_json::json;
use tetherplan::contract::plan::{PlanRequest, plan};
use tetherplan::contract::run::NoProgress;
use tetherplan::numerics::params::AerostatSystem;
use tetherplan::numerics::plan::schedule;
use tetherplan::numerics::plan::{PlanProblem, Winch};

fn bench(c: &mut Criterion) {
    let p = PlanProblem::new(
        AerostatSystem::thesis(),
        1200.0,
        Winch::new(40.0, 2.0).unwrap(),
        0.075,
        None,
    )
    .unwrap();
    c.bench_function("plan_pass_thesis_1200m_tight_reserve", |b| {
        b.iter(|| schedule::fastest(std::hint::black_box(&p)))
    });
    let req: PlanRequest = serde_json::from_value(json!({
        "cable": {"mass_per_length_kg_m": 0.078},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "initial_length_m": 1.0,
        "target_elevation_m": 1200.0,
        "winch": {"max_rate_m_s": 40.0, "max_acceleration_m_s2": 2.0},
        "lift_reserve_nondim": 0.05,
        "haul_down": {"forecast": [{"time_s": 0.0, "wind_speed_m_s": 5.0}, {"time_s": 3600.0, "wind_speed_m_s": 15.0}],
                      "max_operating_wind_m_s": 12.0}
    }))
    .unwrap();
    c.bench_function("plan_request_thesis_1200m_calm", |b| {
        b.iter(|| plan(std::hint::black_box(&req), &NoProgress).unwrap())
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
