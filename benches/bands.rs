//! Uncertainty bands (issue 14): 1000 samples × a 100-rate chart
//! (1–100 m/s), converged points (model.elements omitted), two normal
//! inputs (lift, mass per length), on rayon over all cores. Target ≤ 3 s on
//! 2 cores. Timed runs outside criterion's loop (median of 3 reported),
//! plus a short criterion group for a 100-sample ensemble.

use std::time::Instant;

use criterion::Criterion;
use serde_json::json;
use tetherplan::contract::bands::{self, BandsRequest};
use tetherplan::contract::run::NoProgress;
use tetherplan::numerics::parallel::Parallelism;

fn request(samples: usize, count: usize) -> BandsRequest {
    request_with(samples, count, 1e-4)
}

fn request_with(samples: usize, count: usize, tolerance: f64) -> BandsRequest {
    let body = json!({
        "numerics": {"relative_tolerance": tolerance},
        "cable": {"mass_per_length_kg_m": 0.078},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "rates_m_s": {"min": 1.0, "max": 100.0, "count": count},
        "target_elevation_m": 1200.0,
        "uncertainty": {"samples": samples, "seed": 1, "inputs": [
            {"field": "aerostat.net_buoyancy_n", "distribution": "normal", "mean": 1000.0, "std_dev": 50.0},
            {"field": "cable.mass_per_length_kg_m", "distribution": "normal", "mean": 0.078, "std_dev": 0.002}
        ]}
    });
    bands::parse_bands(&serde_json::to_vec(&body).unwrap()).unwrap()
}

fn timed_runs() {
    timed_runs_at(1e-4);
    // the sampling error of a percentile (~0.3 % here) dwarfs 1e-3
    timed_runs_at(1e-3);
}

fn timed_runs_at(tolerance: f64) {
    let req = request_with(1000, 100, tolerance);
    let mut times: Vec<f64> = (0..3)
        .map(|_| {
            let start = Instant::now();
            let resp = bands::bands(&req, Parallelism::Rayon, &NoProgress).unwrap();
            assert_eq!(resp.points.len(), 100);
            assert!(resp.converged);
            start.elapsed().as_secs_f64()
        })
        .collect();
    times.sort_by(f64::total_cmp);
    println!(
        "bands/1000_samples_x_100_rates_converged (relative tolerance {tolerance:e}): median {:.3} s (runs {:?}) on {} rayon threads",
        times[1],
        times.iter().map(|t| format!("{t:.3}")).collect::<Vec<_>>(),
        rayon::current_num_threads()
    );
}

/// Plan bands (the nominal plan once, 1000 samples over its schedule) and
/// envelope bands (200 samples × the 42-cell example envelope), median of 3.
fn plan_and_envelope_runs() {
    let median = |f: &dyn Fn()| {
        let mut t: Vec<f64> = (0..3)
            .map(|_| {
                let start = Instant::now();
                f();
                start.elapsed().as_secs_f64()
            })
            .collect();
        t.sort_by(f64::total_cmp);
        t[1]
    };
    let example = |schema: utoipa::openapi::RefOr<utoipa::openapi::schema::Schema>| {
        serde_json::to_value(&schema).unwrap()["example"].clone()
    };
    use utoipa::PartialSchema;
    let plan = bands::parse_plan_bands(
        &serde_json::to_vec(&example(bands::PlanBandsRequest::schema())).unwrap(),
    )
    .unwrap();
    let t = median(&|| {
        bands::plan_bands(&plan, Parallelism::Rayon, &NoProgress).unwrap();
    });
    println!("bands/plan_bands_example (1000 samples, 101 schedule samples): median {t:.3} s");
    let env = bands::parse_envelope_bands(
        &serde_json::to_vec(&example(bands::EnvelopeBandsRequest::schema())).unwrap(),
    )
    .unwrap();
    let t = median(&|| {
        bands::envelope_bands(&env, Parallelism::Rayon, &NoProgress).unwrap();
    });
    println!("bands/envelope_bands_example (200 samples × 42 cells): median {t:.3} s");
}

fn small(c: &mut Criterion) {
    let req = request(100, 100);
    let mut group = c.benchmark_group("bands");
    group.sample_size(10);
    group.bench_function("100_samples_x_100_rates_converged", |b| {
        b.iter(|| bands::bands(&req, Parallelism::Rayon, &NoProgress).unwrap())
    });
    group.finish();
}

fn main() {
    faer::set_global_parallelism(faer::Par::Seq);
    let mut c = Criterion::default().configure_from_args();
    small(&mut c);
    timed_runs();
    plan_and_envelope_runs();
    c.final_summary();
}
