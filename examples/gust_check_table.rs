//! Is the SPEC §10 gust check safe? (issue 31, item 5.) The hourly maximum
//! winch tension of the §10 tether in von Kármán turbulence, by Monte Carlo
//! over seeds, against the static winch tension at the gust check (the
//! mean flow scaled by `1 + 3 I`).
//!
//! Runs `POST /api/v1/dynamics/peaks` through the library
//! ([`tetherplan::contract::dynamics::peaks::peaks`], the code the API and
//! the workers run) for 6, 10 and 15 m/s at `I` = 0.1 and 0.2 and prints a
//! Markdown table (docs/gust_check.md):
//!
//! ```text
//! cargo run --release --example gust_check_table            # 200 seeds per case
//! GUST_CHECK_SAMPLES=20 cargo run --release --example gust_check_table
//! ```
//!
//! The case: 1000 m of tether, 0.078 kg/m, 5 mm, C_n 1.2, EA 1e7 N, no
//! internal damping; aerostat F = 1000 N, 10 kg, C_D 0.3 on 20 m², no added
//! mass; uniform mean wind, air 1.225 kg/m³; turbulence von Kármán,
//! L_u = 340 m, seeds 1 … n; exposure 3600 s; numerics at their defaults
//! (50 segments, 0.05 s, ρ∞ 0.8).

use std::time::Instant;

use serde_json::json;
use tetherplan::contract::dynamics::parse_peaks;
use tetherplan::contract::dynamics::peaks::peaks;
use tetherplan::contract::run::NoProgress;
use tetherplan::numerics::parallel::Parallelism;

fn main() {
    let samples: usize = std::env::var("GUST_CHECK_SAMPLES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(200);
    let exposure: f64 = std::env::var("GUST_CHECK_EXPOSURE_S")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(3600.0);
    let mut rows = Vec::new();
    let mut factor: f64 = 0.0;
    let mut increment_factor: f64 = 0.0;
    // The calm winch tension of this tether (vertical, at full buoyancy):
    // F − ρA g L, the base the plan's dynamic factor amplifies over.
    let calm = 1000.0 - 0.078 * 9.81 * 1000.0;
    let start = Instant::now();
    for speed in [6.0, 10.0, 15.0] {
        for intensity in [0.1, 0.2] {
            let body = json!({
                "cable": {"mass_per_length_kg_m": 0.078, "diameter_m": 0.005,
                          "normal_drag_coefficient_nondim": 1.2, "axial_stiffness_n": 1.0e7},
                "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0,
                             "drag_coefficient_nondim": 0.3, "reference_area_m2": 20.0},
                "wind": {"flow": {"kind": "uniform", "speed_m_s": speed},
                         "air_density_kg_m3": 1.225,
                         "time_history": {"kind": "turbulence", "model": "von_karman",
                                          "turbulence_intensity_nondim": intensity,
                                          "length_scale_m": 340.0, "seed": 1}},
                "tether_length_m": 1000.0,
                "exposure_s": exposure,
                "samples": samples,
                "percentiles_nondim": [0.5, 0.9, 0.99],
                "confidence_nondim": 0.95,
                "peak_factor_nondim": 3.0
            });
            let req = parse_peaks(body.to_string().as_bytes()).expect("a valid request");
            let t0 = Instant::now();
            let a = peaks(&req, Parallelism::Rayon, &NoProgress).expect("the peaks");
            let secs = t0.elapsed().as_secs_f64();
            let gust = a
                .quasi_static
                .gust_check_winch_tension_n
                .expect("a gust-check equilibrium");
            let mean = a.quasi_static.mean_wind_winch_tension_n.unwrap_or(f64::NAN);
            let p = &a.max_winch_tension.percentiles;
            let iv = |x: Option<f64>| x.map_or("–".to_string(), |v| format!("{v:.0}"));
            let ratio = p[2].value_n / gust;
            factor = factor.max(ratio);
            let increment = (p[2].value_n - calm) / (gust - calm);
            increment_factor = increment_factor.max(increment);
            let above = a
                .probability_above_gust_check
                .as_ref()
                .expect("a gust check");
            let row = format!(
                "| {speed:.0} | {intensity:.1} | {mean:.0} | {gust:.0} | {:.0} | {:.0} | {:.0} [{}, {}] | {:.0} | {ratio:.3} | {increment:.3} | {}/{} = {:.3} [{:.3}, {:.3}] | {} |",
                p[0].value_n,
                p[1].value_n,
                p[2].value_n,
                iv(p[2].low_n),
                iv(p[2].high_n),
                a.max_winch_tension.largest_n,
                above.event_samples,
                a.completed_samples,
                above.probability_nondim,
                above.low_nondim,
                above.high_nondim,
                a.slack_samples,
            );
            eprintln!("{row}   ({secs:.0} s wall)");
            rows.push(row);
        }
    }
    println!(
        "{samples} seeds per case (1 … {samples}), exposure {exposure:.0} s, {:.0} s wall in all.\n",
        start.elapsed().as_secs_f64()
    );
    println!(
        "| U (m/s) | I | mean-wind static (N) | gust check 1+3I (N) | p50 (N) | p90 (N) | p99 (N) [95 % interval] | largest (N) | p99 / gust check | (p99 − calm) / (gust check − calm) | above gust check [Wilson 95 %] | slack samples |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    for r in &rows {
        println!("{r}");
    }
    println!(
        "\nFactor on the gust check's winch tension that covers every case's p99: {factor:.3}"
    );
    println!(
        "Factor on the gust check's increment over the calm winch tension ({calm:.1} N) that covers every case's p99: {increment_factor:.3}"
    );
}
