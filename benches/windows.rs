//! Launch windows from a forecast (issue 32, target ≤ 1 s on 2 cores): a
//! 48-hour Open-Meteo ensemble of 51 members (the control and
//! `_member01`…`_member50`), 2 448 hourly plans, each member's winds at
//! 10/80/120/180 m spread by a seeded factor and not rounded, so no two
//! members share a wind (the worst case); the same ensemble rounded to
//! 0.1 km/h as Open-Meteo sends it, whose members share winds (1 364
//! distinct); and the control alone (48 plans); the §9 system of the
//! windows example at 300 m.
//!
//! Medians on the 2-core machine (2026-12-05): control 1.11 s; 2 448
//! distinct winds 13.4 s (each member beyond the control judged by
//! `plan_verdict`: 285–480 shootings, 11–21 ms of one core for a GO
//! verdict; with full plans it took about 56 s); rounded 7.45 s. The
//! target is not met: a verdict needs the loads along the whole path (four
//! sparse sequences of about 100 shootings on the plan's 4 000-segment
//! grid), and 2 448 of them at about 10 ms of one core is 12 s on two.

use criterion::{Criterion, criterion_group, criterion_main};
use serde_json::{Value, json};
use tetherplan::contract::run::NoProgress;
use tetherplan::contract::windows::{WindowsRequest, windows};

/// A reproducible factor in [0.7, 1.3) for (member, hour).
fn spread(member: u64, hour: u64) -> f64 {
    let mut z =
        member.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ hour.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    0.7 + 0.6 * (z >> 11) as f64 / (1u64 << 53) as f64
}

/// `rounded`: to 0.1 km/h, as Open-Meteo sends its speeds.
fn forecast(members: u64, rounded: bool) -> Value {
    let r = |v: f64| {
        if rounded {
            (v * 10.0).round() / 10.0
        } else {
            v
        }
    };
    let hours = 48;
    let mut hourly = serde_json::Map::new();
    let mut units = serde_json::Map::new();
    units.insert("time".into(), json!("iso8601"));
    hourly.insert(
        "time".into(),
        json!(
            (0..hours)
                .map(|h| format!("2026-12-{:02}T{:02}:00", 3 + h / 24, h % 24))
                .collect::<Vec<_>>()
        ),
    );
    for m in 0..members {
        let suffix = if m == 0 {
            String::new()
        } else {
            format!("_member{m:02}")
        };
        let base = |h: u64| 8.0 + 30.0 * (std::f64::consts::PI * h as f64 / 24.0).sin().powi(2);
        for (z, a) in [(10.0, 0.0), (80.0, 0.16), (120.0, 0.15), (180.0, 0.14)] {
            let key = format!("wind_speed_{z}m{suffix}");
            let v: Vec<f64> = (0..hours)
                .map(|h| r(base(h) * spread(m, h) * (z / 10.0f64).powf(a)))
                .collect();
            hourly.insert(key.clone(), json!(v));
            units.insert(key, json!("km/h"));
        }
        let key = format!("wind_gusts_10m{suffix}");
        let v: Vec<f64> = (0..hours)
            .map(|h| r(base(h) * spread(m, h) * 1.6))
            .collect();
        hourly.insert(key.clone(), json!(v));
        units.insert(key, json!("km/h"));
    }
    json!({"latitude": 52.52, "longitude": 13.42, "utc_offset_seconds": 0, "timezone": "GMT",
           "hourly_units": units, "hourly": hourly})
}

fn request(members: u64, rounded: bool) -> WindowsRequest {
    serde_json::from_value(json!({
        "cable": {"mass_per_length_kg_m": 0.078, "diameter_m": 0.006, "breaking_strength_n": 20000.0},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0, "drag_coefficient_nondim": 0.3,
                     "reference_area_m2": 20.0},
        "winch": {"max_rate_m_s": 10.0, "max_acceleration_m_s2": 1.0},
        "target_elevation_m": 300.0,
        "operation_s": 3600.0,
        "haul_down": {"max_operating_wind_m_s": 12.0, "max_gust_m_s": 20.0},
        "forecast": {"format": "open_meteo", "data": forecast(members, rounded)}
    }))
    .unwrap()
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("windows");
    g.sample_size(10);
    let one = request(1, false);
    let r = windows(&one, &NoProgress).unwrap();
    assert_eq!(r.hours.len(), 48);
    g.bench_function("open_meteo_48h_control_48_plans", |b| {
        b.iter(|| windows(std::hint::black_box(&one), &NoProgress).unwrap())
    });
    let ens = request(51, false);
    let r = windows(&ens, &NoProgress).unwrap();
    assert_eq!(r.members, 51);
    assert_eq!(r.plans_computed, 2448);
    g.bench_function("open_meteo_48h_51_members_2448_plans", |b| {
        b.iter(|| windows(std::hint::black_box(&ens), &NoProgress).unwrap())
    });
    let sent = request(51, true);
    let r = windows(&sent, &NoProgress).unwrap();
    assert_eq!(r.plans_computed, 1364);
    g.bench_function("open_meteo_48h_51_members_rounded_1364_plans", |b| {
        b.iter(|| windows(std::hint::black_box(&sent), &NoProgress).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
