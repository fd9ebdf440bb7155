//! Uncertainty bands (issue 14, SPEC §8) against an independent Monte
//! Carlo of the closed form, for reproducibility across thread counts and
//! seeds, and against the deterministic chart.
//!
//! The continuum critical elevation of constant-rate lengthening is
//! `h* = (F/ρA − v²)/g` (SPEC §1); the converged chart lands on it to about
//! 1e-4 (relative tolerance, safe side). So the percentiles of the banded
//! chart must match the percentiles of that formula over the same input
//! distributions, computed here with a different generator (xorshift64*)
//! and a different normal transform (Box–Muller), within 1 % (the issue's
//! tolerance) and within the stated sampling errors.

use serde_json::{Value, json};
use tetherplan::contract::bands::{self, BandsRequest, BandsResponse};
use tetherplan::contract::dto::ChartRequest;
use tetherplan::contract::run::{self, NoProgress};
use tetherplan::numerics::parallel::Parallelism;

const G: f64 = 9.81;

fn request(extra: Value) -> BandsRequest {
    let mut v = json!({
        "cable": {"mass_per_length_kg_m": 0.078},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "initial_length_m": 1.0,
        "rates_m_s": [5.0, 10.0, 20.0, 30.0],
        "uncertainty": {"samples": 4000, "seed": 2026, "inputs": [
            {"field": "aerostat.net_buoyancy_n", "distribution": "normal", "mean": 1000.0, "std_dev": 50.0},
            {"field": "cable.mass_per_length_kg_m", "distribution": "normal", "mean": 0.078, "std_dev": 0.002}
        ]}
    });
    for (k, x) in extra.as_object().unwrap() {
        v[k] = x.clone();
    }
    bands::parse_bands(&serde_json::to_vec(&v).unwrap()).unwrap()
}

fn run(req: &BandsRequest) -> BandsResponse {
    bands::bands(req, Parallelism::Rayon, &NoProgress).unwrap()
}

/// xorshift64* (Vigna 2016): the test's own generator.
struct XorShift(u64);

impl XorShift {
    fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    /// A pair of independent standard normals (Box–Muller).
    fn normals(&mut self) -> (f64, f64) {
        let (u1, u2) = (self.uniform(), self.uniform());
        let r = (-2.0 * u1.ln()).sqrt();
        let a = 2.0 * std::f64::consts::PI * u2;
        (r * a.cos(), r * a.sin())
    }
}

/// Percentile by linear interpolation of sorted values.
fn percentile(sorted: &[f64], p: f64) -> f64 {
    let h = (sorted.len() - 1) as f64 * p;
    let i = h.floor() as usize;
    sorted[i] + (h - i as f64) * (sorted[(i + 1).min(sorted.len() - 1)] - sorted[i])
}

/// `(F/ρA − v²)/g` for `n` draws of F ~ N(1000, 50), ρA ~ N(0.078, 0.002).
fn closed_form_ensemble(rate: f64, n: usize, seed: u64) -> Vec<f64> {
    let mut rng = XorShift(seed);
    let mut hs: Vec<f64> = (0..n)
        .map(|_| {
            let (z1, z2) = rng.normals();
            let f = 1000.0 + 50.0 * z1;
            let rho_a = 0.078 + 0.002 * z2;
            (f / rho_a - rate * rate) / G
        })
        .collect();
    hs.sort_by(f64::total_cmp);
    hs
}

/// Issue 14: the 5/50/95 % points of h* within 1 % of an independent
/// Monte Carlo of the closed form (200 000 draws), and within the bands'
/// stated 95 % sampling error plus the reference's own (≈ 0.1 m) and the
/// convergence tolerance (1e-4).
#[test]
fn percentiles_of_h_star_match_an_independent_monte_carlo() {
    let resp = run(&request(json!({})));
    assert_eq!(resp.valid_samples, 4000);
    assert!(resp.rejected_samples.is_empty());
    for point in &resp.points {
        let reference = closed_form_ensemble(point.rate_m_s, 200_000, 0x5EED_1234);
        let b = &point.max_elevation_m;
        for (p, got, err) in [
            (0.05, b.p05, b.p05_error.unwrap()),
            (0.50, b.p50, b.p50_error.unwrap()),
            (0.95, b.p95, b.p95_error.unwrap()),
        ] {
            let want = percentile(&reference, p);
            let rel = (got / want - 1.0).abs();
            println!(
                "rate {:>4} m/s p{:02.0}: bands {got:.2} ± {err:.2} m, independent MC {want:.2} m, difference {:.3} %",
                point.rate_m_s,
                100.0 * p,
                100.0 * rel
            );
            assert!(rel < 0.01, "rate {} p {p}: {got} vs {want}", point.rate_m_s);
            assert!(
                (got - want).abs() <= err + 1.0 + 2e-4 * want,
                "rate {} p {p}: {got} vs {want}, stated error {err}",
                point.rate_m_s
            );
        }
        // the stated error is a sampling error of the right size:
        // asymptotically 1.96·√(p(1−p)/n)/f(ξ_p) ≈ 0.064 σ_h at p = 5 %, n = 4000
        let sd = b.std_dev;
        assert!(b.p05_error.unwrap() < 0.15 * sd && b.p05_error.unwrap() > 0.03 * sd);
    }
}

/// The probability that 1200 m is unsafe at 20 m/s (h* < 1200 m) against
/// the independent Monte Carlo, within four combined standard errors.
#[test]
fn probability_unsafe_matches_an_independent_monte_carlo() {
    let resp = run(&request(json!({"target_elevation_m": 1200.0})));
    for point in &resp.points {
        let reference = closed_form_ensemble(point.rate_m_s, 200_000, 77);
        let p_ref = reference.iter().filter(|&&h| h < 1200.0).count() as f64 / 200_000.0;
        let p = point.probability_unsafe.as_ref().unwrap();
        let se = (p.standard_error_nondim.powi(2) + p_ref * (1.0 - p_ref) / 200_000.0).sqrt();
        println!(
            "rate {} m/s: P(h* < 1200 m) = {:.4} ± {:.4} (Wilson {:.4}–{:.4}), independent {p_ref:.4}",
            point.rate_m_s,
            p.probability_nondim,
            p.standard_error_nondim,
            p.low_nondim,
            p.high_nondim
        );
        assert!(
            (p.probability_nondim - p_ref).abs() <= 4.0 * se + 1e-3,
            "rate {}: {} vs {p_ref}",
            point.rate_m_s,
            p.probability_nondim
        );
        assert!(p.low_nondim <= p.probability_nondim && p.probability_nondim <= p.high_nondim);
    }
    // the probability rises with the rate (h* falls)
    let ps: Vec<f64> = resp
        .points
        .iter()
        .map(|p| p.probability_unsafe.as_ref().unwrap().probability_nondim)
        .collect();
    assert!(ps.windows(2).all(|w| w[0] <= w[1]), "{ps:?}");
}

/// The same seed gives identical JSON at 1 and 2 rayon threads (and
/// serially); a different seed gives different values that agree within
/// the stated sampling errors.
#[test]
fn same_seed_same_json_at_any_thread_count_other_seed_within_error() {
    let req = request(
        json!({"uncertainty": {"samples": 1000, "seed": 11, "inputs": [
            {"field": "aerostat.net_buoyancy_n", "distribution": "normal", "mean": 1000.0, "std_dev": 50.0},
            {"field": "cable.mass_per_length_kg_m", "distribution": "normal", "mean": 0.078, "std_dev": 0.002}
        ]}}),
    );
    let texts: Vec<String> = [1, 2]
        .into_iter()
        .map(|threads| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| serde_json::to_string(&run(&req)).unwrap())
        })
        .collect();
    assert_eq!(texts[0], texts[1]);
    let serial = bands::bands(&req, Parallelism::Serial, &NoProgress).unwrap();
    assert_eq!(texts[0], serde_json::to_string(&serial).unwrap());

    let mut other = req.clone();
    other.params.uncertainty.seed = 12;
    let (a, b) = (run(&req), run(&other));
    assert_eq!(b.seed, 12);
    let mut differ = 0;
    for (pa, pb) in a.points.iter().zip(&b.points) {
        for (x, y) in [
            (&pa.max_elevation_m, &pb.max_elevation_m),
            (&pa.critical_time_s, &pb.critical_time_s),
        ] {
            for (va, ea, vb, eb) in [
                (x.p05, x.p05_error, y.p05, y.p05_error),
                (x.p50, x.p50_error, y.p50, y.p50_error),
                (x.p95, x.p95_error, y.p95, y.p95_error),
            ] {
                if va != vb {
                    differ += 1;
                }
                let (ea, eb) = (ea.unwrap(), eb.unwrap());
                assert!((va - vb).abs() <= ea + eb, "{va} ± {ea} vs {vb} ± {eb}");
            }
        }
    }
    assert_eq!(differ, 4 * 2 * 3, "every percentile moves with the seed");
}

/// A zero-width distribution reproduces the deterministic chart bit for
/// bit: every percentile equals the chart's point, with zero error.
#[test]
fn zero_width_distributions_reproduce_the_chart_exactly() {
    let grid = json!({"min": 5.0, "max": 30.0, "count": 6});
    let req = request(json!({
        "rates_m_s": grid,
        "uncertainty": {"samples": 100, "seed": 5, "inputs": [
            {"field": "aerostat.net_buoyancy_n", "distribution": "normal", "mean": 1000.0, "std_dev": 0.0},
            {"field": "cable.mass_per_length_kg_m", "distribution": "lognormal", "mean": 0.078, "std_dev": 0.0},
            {"field": "aerostat.mass_kg", "distribution": "uniform", "low": 10.0, "high": 10.0}
        ]}
    }));
    let resp = run(&req);
    let chart_body = json!({
        "cable": {"mass_per_length_kg_m": 0.078},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "initial_length_m": 1.0,
        "rates_m_s": grid,
    });
    let chart_req: ChartRequest =
        tetherplan::contract::parse(&serde_json::to_vec(&chart_body).unwrap()).unwrap();
    let chart = run::chart(&chart_req, Parallelism::Rayon, &NoProgress).unwrap();
    let points = &chart.series[0].points;
    assert_eq!(points.len(), resp.points.len());
    for (c, b) in points.iter().zip(&resp.points) {
        assert_eq!(c.rate_m_s.to_bits(), b.rate_m_s.to_bits());
        for (band, want) in [
            (&b.max_elevation_m, c.max_elevation_m),
            (&b.critical_time_s, c.critical_time_s),
        ] {
            for v in [band.p05, band.p50, band.p95, band.mean] {
                assert_eq!(v.to_bits(), want.to_bits(), "{v} vs {want}");
            }
            assert_eq!(band.std_dev, 0.0);
            for e in [band.p05_error, band.p50_error, band.p95_error] {
                assert_eq!(e, Some(0.0));
            }
        }
        assert_eq!(
            b.nominal_max_elevation_m.to_bits(),
            c.max_elevation_m.to_bits()
        );
    }
}

/// Rates above some samples' wave speed (√(F/ρA) ≈ 113 m/s) make those
/// samples unstable at once: counted, with h* = L0 and t* = 0, and the
/// 95 % point of a rate far above every wave speed is L0.
#[test]
fn rates_near_the_wave_speed_count_immediate_samples() {
    let resp = run(&request(json!({"rates_m_s": [113.0, 200.0],
        "uncertainty": {"samples": 500, "seed": 1, "inputs": [
            {"field": "aerostat.net_buoyancy_n", "distribution": "normal", "mean": 1000.0, "std_dev": 50.0}]}})));
    let near = &resp.points[0];
    assert!(
        near.immediate_samples > 100 && near.immediate_samples < 400,
        "{}",
        near.immediate_samples
    );
    assert_eq!(near.max_elevation_m.p05, 1.0);
    let far = &resp.points[1];
    assert_eq!(far.immediate_samples, 500);
    assert_eq!(far.max_elevation_m.p95, 1.0);
    assert_eq!(far.critical_time_s.p95, 0.0);
}
