//! GE deployment charts (issue 6), Table 7.1 data, 20 elements, default
//! search settings (Δt = 0.02 s, local QEP every 25 steps, bracket
//! re-marched step by step):
//!
//! * one critical time at 12 m/s (t* ≈ 112 s, ≈ 5 600 steps): criterion,
//!   one core; target ≤ 5 s;
//! * one chart of 20 rates (5 … 110 m/s) × 3 stiffness ratios
//!   (1e3, 1e4, 1e5) on rayon (all cores): timed once outside criterion's
//!   loop (a 10-sample criterion run would take minutes); target ≤ 120 s
//!   on 2 cores.

use std::time::Instant;

use criterion::Criterion;
use tetherplan::numerics::ge::chart::{GeChartRequest, GeChartSystem, deployment_chart};
use tetherplan::numerics::ge::critical::{
    CriticalConfig, CriticalProblem, StartState, critical_time,
};
use tetherplan::numerics::parallel::Parallelism;
use tetherplan::numerics::profile::Profile;

fn critical_12(c: &mut Criterion) {
    let model = GeChartSystem::table_7_1().model(1e5).unwrap();
    let problem = CriticalProblem {
        profile: Profile::constant_rate(1.0, 12.0, None).unwrap(),
        net_buoyancy_n: 1000.0,
        perturbation: None,
        aero: None,
        start: StartState::AtRest,
    };
    let config = CriticalConfig::default();
    let mut group = c.benchmark_group("ge_critical");
    group.sample_size(10);
    group.bench_function("table_7_1_12_m_s_20_elements", |b| {
        b.iter(|| {
            let r = critical_time(&model, &problem, &config, &|| false).unwrap();
            assert!(r.time_s().is_some_and(|t| (t - 112.3).abs() < 1.0));
        })
    });
    group.finish();
}

fn chart_once() {
    let rates: Vec<f64> = (0..20).map(|i| 5.0 + 105.0 * i as f64 / 19.0).collect();
    let request = GeChartRequest::table_7_1(rates, vec![1e3, 1e4, 1e5]);
    let start = Instant::now();
    let series = deployment_chart(&request, Parallelism::Rayon, &|_, _| {}, &|| false).unwrap();
    let elapsed = start.elapsed();
    let points: usize = series.iter().map(|s| s.points.len()).sum();
    let steps: usize = series.iter().flat_map(|s| &s.points).map(|p| p.steps).sum();
    println!(
        "ge_chart/table_7_1_20_rates_x_3_stiffness_ratios: {points} points, {steps} steps, {:.2} s on {} rayon threads (one timed run)",
        elapsed.as_secs_f64(),
        rayon::current_num_threads()
    );
}

fn main() {
    faer::set_global_parallelism(faer::Par::Seq);
    let mut c = Criterion::default().configure_from_args();
    critical_12(&mut c);
    chart_once();
    c.final_summary();
}
