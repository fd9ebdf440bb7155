//! Plan and envelope bands (issue 14, SPEC §8) against closed forms and an
//! independent Monte Carlo written here (xorshift64* + Box–Muller, not the
//! service's SplitMix64 streams and AS241 inverse CDF), for
//! reproducibility at 1 and 2 threads, and a different seed.
//!
//! **Plan.** At a fixed schedule every quantity is linear in the uncertain
//! inputs: the effective roller tension with the sample's full buoyancy at
//! instant k is `F − m a_k − ρA (g + a_k) L_k − ρA v_k²`. With F ~ N(μ, σ)
//! alone, "unstable somewhere" is
//! `F < c = max_k (m a_k + ρA (g + a_k) L_k + ρA v_k²)`, so
//! `P = Φ((c − μ)/σ)`; "over the rating" (largest tension `F − m a_k` above
//! `B/sf`) is `F > min_k (B/sf + m a_k)`, a normal tail.
//! With F and ρA both normal the event is a min over instants of
//! correlated normals: the test's own Monte Carlo evaluates it.
//!
//! **Envelope.** In calm air the tether hangs straight: the largest tension
//! is `F` (at the aerostat), the smallest `F − ρA g L` (at the winch). So
//! "tension exceeded" is `F > B/sf` and "unstable at payout rate v" is
//! `F − ρA (g L + v²) ≤ 0`: with F, ρA and B normal both are normal tails
//! of a linear combination.
//!
//! Tolerance: the estimated probability is within 4 standard errors
//! `√(p(1 − p)/n)` of the closed form (and of the independent Monte Carlo,
//! with both sampling errors combined).

use serde_json::{Value, json};
use tetherplan::contract::bands::{self, EnvelopeBandsResponse, PlanBandsResponse};
use tetherplan::contract::run::NoProgress;
use tetherplan::numerics::parallel::Parallelism;

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
    fn normals(&mut self) -> (f64, f64) {
        let (u1, u2) = (self.uniform(), self.uniform());
        let r = (-2.0 * u1.ln()).sqrt();
        let a = 2.0 * std::f64::consts::PI * u2;
        (r * a.cos(), r * a.sin())
    }
}

/// Φ(x) from erfc by W. J. Cody's rational approximations is overkill here:
/// Abramowitz & Stegun 7.1.26 (absolute error < 1.5e-7) is far below the
/// sampling errors compared against.
fn phi(x: f64) -> f64 {
    let z = x.abs() / std::f64::consts::SQRT_2;
    let t = 1.0 / (1.0 + 0.327_591_1 * z);
    let poly = t
        * (0.254_829_592
            + t * (-0.284_496_736
                + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    let erfc = poly * (-z * z).exp();
    if x >= 0.0 {
        1.0 - 0.5 * erfc
    } else {
        0.5 * erfc
    }
}

fn within(p: f64, truth: f64, n: usize, what: &str) {
    let se = (truth * (1.0 - truth) / n as f64)
        .sqrt()
        .max(1.0 / n as f64);
    assert!(
        (p - truth).abs() <= 4.0 * se,
        "{what}: {p} vs {truth} (4 standard errors = {})",
        4.0 * se
    );
}

// ------------------------------------------------------------------ plan

const G: f64 = 9.81;
const M: f64 = 10.0;

fn plan_body(inputs: Value, samples: usize, seed: u64) -> Value {
    json!({
        "cable": {"mass_per_length_kg_m": 0.078, "breaking_strength_n": 5200.0},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": M},
        "initial_length_m": 1.0,
        "target_elevation_m": 1200.0,
        "winch": {"max_rate_m_s": 40.0, "max_acceleration_m_s2": 2.0},
        "lift_reserve_nondim": 0.05,
        "required_safety_factor_nondim": 5.0,
        "samples": 61,
        "uncertainty": {"samples": samples, "seed": seed, "inputs": inputs}
    })
}

fn plan_run(body: &Value, parallelism: Parallelism) -> PlanBandsResponse {
    let req = bands::parse_plan_bands(&serde_json::to_vec(body).unwrap()).unwrap();
    bands::plan_bands(&req, parallelism, &NoProgress).unwrap()
}

/// `(L, v, a)` of every instant of the nominal schedule.
fn instants(r: &PlanBandsResponse) -> Vec<(f64, f64, f64)> {
    r.plan
        .schedule
        .iter()
        .map(|s| (s.length_m, s.rate_m_s, s.acceleration_m_s2))
        .collect()
}

fn lift_only() -> Value {
    json!([{"field": "aerostat.net_buoyancy_n", "distribution": "normal", "mean": 1000.0, "std_dev": 50.0}])
}

#[test]
fn plan_probabilities_with_uncertain_lift_are_normal_tails() {
    let n = 20_000;
    let r = plan_run(&plan_body(lift_only(), n, 11), Parallelism::Rayon);
    assert!(r.plan.feasible);
    let rho_a = 0.078;
    let ks = instants(&r);
    // unstable: F < c
    let c = ks
        .iter()
        .map(|&(l, v, a)| M * a + rho_a * (G + a) * l + rho_a * v * v)
        .fold(f64::NEG_INFINITY, f64::max);
    let truth = phi((c - 1000.0) / 50.0);
    // at rest at 1200 m: c = ρA g L = 918.2 N, P = Φ(−1.636) ≈ 0.051
    assert!((0.03..0.08).contains(&truth), "{truth}");
    let p = r.probability_unstable.as_ref().unwrap();
    within(p.probability_nondim, truth, n, "P(unstable)");
    assert!(
        p.low_nondim <= truth && truth <= p.high_nondim,
        "{p:?} vs {truth}"
    );
    // over the rating: F − m a_k > 5200/5 somewhere ⇔ F > min_k(1040 + m a_k)
    let c2 = ks
        .iter()
        .map(|&(_, _, a)| 1040.0 + M * a)
        .fold(f64::INFINITY, f64::min);
    let truth = 1.0 - phi((c2 - 1000.0) / 50.0);
    assert!((0.2..0.5).contains(&truth), "{truth}");
    let p = r.probability_over_rating.as_ref().unwrap();
    within(p.probability_nondim, truth, n, "P(over rating)");
    // below the reserve: the plan keeps (1−r)F − … ≥ ε(1−r)F, so any draw
    // below the nominal F by more than the slack fails; at least the
    // unstable ones do
    assert!(
        r.probability_below_reserve.as_ref().unwrap().event_samples
            >= r.probability_unstable.as_ref().unwrap().event_samples
    );
}

#[test]
fn plan_instability_with_two_inputs_matches_an_independent_monte_carlo() {
    let inputs = json!([
        {"field": "aerostat.net_buoyancy_n", "distribution": "normal", "mean": 1000.0, "std_dev": 50.0},
        {"field": "cable.mass_per_length_kg_m", "distribution": "normal", "mean": 0.078, "std_dev": 0.002}
    ]);
    let n = 8000;
    let r = plan_run(&plan_body(inputs, n, 5), Parallelism::Rayon);
    let ks = instants(&r);
    let mut rng = XorShift(0x5eed_1234);
    let m = 40_000;
    let (mut unstable, mut winch_at_end) = (0usize, Vec::with_capacity(m));
    for _ in 0..m {
        let (z1, z2) = rng.normals();
        let (f, rho_a) = (1000.0 + 50.0 * z1, 0.078 + 0.002 * z2);
        let min_t = ks
            .iter()
            .map(|&(l, v, a)| f - M * a - rho_a * (G + a) * l - rho_a * v * v)
            .fold(f64::INFINITY, f64::min);
        if min_t < 0.0 {
            unstable += 1;
        }
        let &(l, _, a) = ks.last().unwrap();
        winch_at_end.push(f - M * a - rho_a * (G + a) * l);
    }
    let mc = unstable as f64 / m as f64;
    let p = r.probability_unstable.as_ref().unwrap().probability_nondim;
    let se = (mc * (1.0 - mc) * (1.0 / n as f64 + 1.0 / m as f64)).sqrt();
    assert!(
        (p - mc).abs() <= 4.0 * se,
        "P(unstable) {p} vs independent Monte Carlo {mc} (4 se = {})",
        4.0 * se
    );
    // the band of the winch tension at the end against the MC percentiles
    winch_at_end.sort_by(f64::total_cmp);
    let band = &r.instants.last().unwrap().winch_tension_n;
    for (q, level) in [(band.p05, 0.05), (band.p50, 0.5), (band.p95, 0.95)] {
        let h = (m - 1) as f64 * level;
        let mc_q = winch_at_end[h as usize];
        // σ of the winch tension ≈ √(50² + (0.002·g·1200)²) ≈ 57 N; the
        // percentile's sampling error at n = 8000 is about 2 N
        assert!((q - mc_q).abs() < 6.0, "p{level}: {q} vs {mc_q}");
    }
    assert!(band.p05_error.unwrap() < 6.0);
}

fn without_timing(r: &PlanBandsResponse) -> String {
    let mut v = serde_json::to_value(r).unwrap();
    v["plan"]["compute_time_s"] = json!(0.0);
    v.to_string()
}

#[test]
fn the_same_seed_is_identical_at_one_and_two_threads() {
    let body = plan_body(
        json!([
            {"field": "aerostat.net_buoyancy_n", "distribution": "lognormal", "mean": 1000.0, "std_dev": 40.0},
            {"field": "aerostat.mass_kg", "distribution": "uniform", "low": 8.0, "high": 12.0},
            {"field": "cable.breaking_strength_n", "distribution": "normal", "mean": 5200.0, "std_dev": 200.0}
        ]),
        600,
        42,
    );
    let at = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| without_timing(&plan_run(&body, Parallelism::Rayon)))
    };
    let one = at(1);
    assert_eq!(one, at(2));
    assert_eq!(one, without_timing(&plan_run(&body, Parallelism::Serial)));
    // another seed: other values, within the sampling error
    let mut other = body.clone();
    other["uncertainty"]["seed"] = json!(43);
    let a = plan_run(&body, Parallelism::Rayon);
    let b = plan_run(&other, Parallelism::Rayon);
    let (pa, pb) = (
        a.probability_over_rating.unwrap(),
        b.probability_over_rating.unwrap(),
    );
    assert_ne!(
        a.peak_tension_n.as_ref().unwrap().p50,
        b.peak_tension_n.as_ref().unwrap().p50
    );
    let se = (pa.standard_error_nondim.powi(2) + pb.standard_error_nondim.powi(2)).sqrt();
    assert!((pa.probability_nondim - pb.probability_nondim).abs() <= 4.0 * se);
}

// -------------------------------------------------------------- envelope

fn envelope_body(samples: usize, seed: u64) -> Value {
    json!({
        "cable": {"mass_per_length_kg_m": 0.1, "diameter_m": 0.006, "breaking_strength_n": 5500.0},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 50.0, "drag_coefficient_nondim": 0.3,
                     "reference_area_m2": 20.0},
        "wind": {"flow": {"kind": "uniform", "speed_m_s": 0.0}},
        "wind_speeds_m_s": {"min": 0.0, "max": 0.0, "count": 1},
        "tether_lengths_m": {"min": 100.0, "max": 1000.0, "count": 3},
        "required_safety_factor_nondim": 5.0,
        "payout_rate_m_s": 20.0,
        "uncertainty": {"samples": samples, "seed": seed, "inputs": [
            {"field": "aerostat.net_buoyancy_n", "distribution": "normal", "mean": 1000.0, "std_dev": 100.0},
            {"field": "cable.mass_per_length_kg_m", "distribution": "normal", "mean": 0.1, "std_dev": 0.005},
            {"field": "cable.breaking_strength_n", "distribution": "normal", "mean": 5500.0, "std_dev": 1000.0}
        ]}
    })
}

fn envelope_run(body: &Value, parallelism: Parallelism) -> EnvelopeBandsResponse {
    let req = bands::parse_envelope_bands(&serde_json::to_vec(body).unwrap()).unwrap();
    bands::envelope_bands(&req, parallelism, &NoProgress).unwrap()
}

#[test]
fn envelope_probabilities_in_calm_air_are_normal_tails() {
    let n = 6000;
    let r = envelope_run(&envelope_body(n, 8), Parallelism::Rayon);
    assert_eq!(r.cells.len(), 3);
    let mut rng = XorShift(77);
    let m = 40_000;
    let draws: Vec<(f64, f64, f64)> = (0..m)
        .map(|_| {
            let (z1, z2) = rng.normals();
            let (z3, _) = rng.normals();
            (1000.0 + 100.0 * z1, 0.1 + 0.005 * z2, 5500.0 + 1000.0 * z3)
        })
        .collect();
    for c in &r.cells {
        let l = c.tether_length_m;
        // tension exceeded: B/5 − F < 0, B/5 − F ~ N(100, √(200² + 100²))
        let truth = phi(-100.0 / (200f64.powi(2) + 100f64.powi(2)).sqrt());
        let p = c.probability_tension_exceeded.as_ref().unwrap();
        within(
            p.probability_nondim,
            truth,
            n,
            &format!("P(tension) at {l} m"),
        );
        // unstable: F − ρA (g L + v²) ≤ 0
        let k = G * l + 400.0;
        let truth = phi(-(1000.0 - 0.1 * k) / (100f64.powi(2) + (0.005 * k).powi(2)).sqrt());
        let p = c.probability_unstable.as_ref().unwrap();
        within(
            p.probability_nondim,
            truth,
            n,
            &format!("P(unstable) at {l} m"),
        );
        // the independent Monte Carlo of the same event
        let mc = draws
            .iter()
            .filter(|&&(f, ra, _)| f - ra * k <= 0.0)
            .count() as f64
            / m as f64;
        let se = (mc * (1.0 - mc) * (1.0 / n as f64 + 1.0 / m as f64))
            .sqrt()
            .max(1e-4);
        assert!(
            (p.probability_nondim - mc).abs() <= 4.0 * se,
            "{l} m: {} vs MC {mc}",
            p.probability_nondim
        );
        // the largest tension is F: its band is that of N(1000, 100)
        assert!(
            (c.max_tension_n.p50 - 1000.0).abs() < 6.0,
            "{:?}",
            c.max_tension_n
        );
        assert!((c.max_tension_n.p95 - (1000.0 + 164.485)).abs() < 12.0);
    }
    // at 1000 m the unstable probability is near one half (Φ(0.19) ≈ 0.57)
    let p = r.cells[2]
        .probability_unstable
        .as_ref()
        .unwrap()
        .probability_nondim;
    assert!((0.5..0.65).contains(&p), "{p}");
}

#[test]
fn envelope_bands_are_identical_at_one_and_two_threads() {
    let mut body = envelope_body(300, 3);
    body["wind"] = json!({"flow": {"kind": "power_law", "coefficient_m_s": 0.0, "exponent_nondim": 0.14, "reference_height_m": 10.0}});
    body["wind_speeds_m_s"] = json!({"min": 0.0, "max": 20.0, "count": 3});
    let at = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| serde_json::to_string(&envelope_run(&body, Parallelism::Rayon)).unwrap())
    };
    assert_eq!(at(1), at(2));
}
