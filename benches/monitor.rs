//! The live-flight monitor (issue 33 target: one sample's evaluation ≤
//! 20 µs): a 10 Hz flight with every check on (tension, slack, wind and
//! gust over their 10-minute windows, the payout rate against a 41 × 8
//! ceiling table, the plan trace of 500 points), timed per sample after
//! an hour of history has filled the windows.

use std::sync::Arc;

use criterion::{Criterion, criterion_group, criterion_main};
use tetherplan::numerics::monitor::{
    CeilingTable, FlightModel, Limits, Monitor, PlanTrace, Sample,
};

fn sample(k: u64) -> Sample {
    let t = 0.1 * k as f64;
    let x = k as f64;
    Sample {
        time_s: t,
        tether_length_m: Some(800.0 + 50.0 * (0.001 * x).sin()),
        winch_rate_m_s: Some(2.0 + (0.01 * x).sin()),
        winch_tension_n: Some(5000.0 + 3000.0 * (0.003 * x).sin()),
        wind_speed_m_s: Some(7.0 + 3.0 * (0.05 * x).sin() + (0.7 * x).cos()),
        wind_height_m: Some(10.0),
        aerostat_altitude_m: None,
    }
}

fn bench(c: &mut Criterion) {
    let mut limits = Limits::new(10_000.0);
    limits.allowable_tension_n = Some(10_000.0);
    limits.max_operating_wind_m_s = Some(12.0);
    limits.max_gust_m_s = Some(18.0);
    let lengths: Vec<f64> = (0..=40).map(|k| 50.0 * k as f64).collect();
    let winds: Vec<f64> = (0..8).map(|k| 4.0 * k as f64).collect();
    let table = CeilingTable::tabulate(lengths, winds, |l, w| {
        ((9000.0 - 0.8 * l - 30.0 * w) / 0.1).max(0.0).sqrt()
    })
    .unwrap();
    let times: Vec<f64> = (0..500).map(|k| 2.0 * k as f64).collect();
    let plan_lengths: Vec<f64> = times.iter().map(|t| (t * 1.5).min(1000.0)).collect();
    let model = FlightModel {
        limits,
        plan: PlanTrace::new(times, plan_lengths),
        ceiling: Some(Arc::new(table)),
    };
    let mut m = Monitor::new(model);
    let mut k = 0u64;
    // an hour of 10 Hz history
    while k < 36_000 {
        m.push(&sample(k));
        k += 1;
    }
    c.bench_function("monitor_one_sample_all_checks", |b| {
        b.iter(|| {
            k += 1;
            std::hint::black_box(m.push(std::hint::black_box(&sample(k))))
        })
    });
    c.bench_function("monitor_status_all_checks", |b| {
        b.iter(|| std::hint::black_box(m.status(Some(0.5))))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
