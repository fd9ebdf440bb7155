//! Unit tests of a bands run.

use super::*;
use crate::contract::error::NoProgress;
use serde_json::json;

fn body(extra: Value) -> Vec<u8> {
    let mut v = json!({
        "cable": {"mass_per_length_kg_m": 0.078},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
        "rates_m_s": [5.0, 10.0],
        "uncertainty": {"samples": 200, "seed": 3, "inputs": [
            {"field": "aerostat.net_buoyancy_n", "distribution": "normal", "mean": 1000.0, "std_dev": 50.0}
        ]}
    });
    for (k, x) in extra.as_object().unwrap() {
        v[k] = x.clone();
    }
    serde_json::to_vec(&v).unwrap()
}

fn field_of(b: Vec<u8>) -> String {
    let err = parse_bands(&b)
        .and_then(|r| prepare(&r).map(drop))
        .expect_err("invalid");
    err.body().error.field.unwrap()
}

#[test]
fn a_rate_list_and_a_rate_grid_give_the_same_bands() {
    let run = |rates: Value| {
        let req = parse_bands(&body(json!({"rates_m_s": rates}))).unwrap();
        serde_json::to_string(&bands(&req, Parallelism::Serial, &NoProgress).unwrap()).unwrap()
    };
    let listed = run(json!([5.0, 7.5, 10.0]));
    assert_eq!(listed, run(json!({"min": 5.0, "max": 10.0, "count": 3})));
    assert!(listed.contains("7.5"), "{listed}");
    // errors name the part at fault, as the other grids do
    assert_eq!(
        field_of(body(
            json!({"rates_m_s": {"min": 5.0, "max": 10.0, "count": 1001}})
        )),
        "rates_m_s.count"
    );
    assert_eq!(
        field_of(body(json!({"rates_m_s": vec![5.0; 1001]}))),
        "rates_m_s"
    );
    assert_eq!(
        field_of(body(json!({"rates_m_s": [5.0, 0.0]}))),
        "rates_m_s[1]"
    );
    assert_eq!(
        field_of(body(
            json!({"rates_m_s": {"min": 0.0, "max": 10.0, "count": 3}})
        )),
        "rates_m_s.min"
    );
    assert_eq!(
        field_of(body(
            json!({"rates_m_s": {"min": 5.0, "max": 1.0, "count": 3}})
        )),
        "rates_m_s.max"
    );
}

#[test]
fn errors_name_their_field() {
    assert_eq!(
        field_of(body(json!({"uncertainty": {"inputs": [
            {"field": "aerostat.lift_n", "distribution": "normal", "mean": 1.0, "std_dev": 0.1}]}}))),
        "uncertainty.inputs[0].field"
    );
    assert_eq!(
        field_of(body(json!({"uncertainty": {"inputs": [
            {"field": "model.elements", "distribution": "normal", "mean": 1.0, "std_dev": 0.1}]}}))),
        "uncertainty.inputs[0].field"
    );
    assert_eq!(
        field_of(body(json!({"uncertainty": {"inputs": [
            {"field": "cable.density_kg_m3", "distribution": "normal", "mean": 1.0, "std_dev": 0.1}]}}))),
        "uncertainty.inputs[0].field"
    );
    assert_eq!(
        field_of(body(json!({"uncertainty": {"inputs": [
            {"field": "aerostat.mass_kg", "distribution": "uniform", "low": 9.0, "high": 11.0},
            {"field": "aerostat.mass_kg", "distribution": "uniform", "low": 9.0, "high": 11.0}]}}))),
        "uncertainty.inputs[1].field"
    );
    assert_eq!(
        field_of(body(json!({"uncertainty": {"inputs": [
            {"field": "aerostat.mass_kg", "distribution": "normal", "mean": 10.0}]}}))),
        "uncertainty.inputs[0].std_dev"
    );
    assert_eq!(
        field_of(body(json!({"uncertainty": {"inputs": [
            {"field": "aerostat.mass_kg", "distribution": "normal", "mean": 10.0, "std_dev": 1.0, "skew": 1}]}}))),
        "uncertainty.inputs[0].skew"
    );
    // 2.3 % of a N(10, 5) mass is negative: refused
    assert_eq!(
        field_of(body(json!({"uncertainty": {"inputs": [
            {"field": "aerostat.mass_kg", "distribution": "normal", "mean": 10.0, "std_dev": 5.0}]}}))),
        "uncertainty.inputs[0]"
    );
    assert_eq!(
        field_of(body(json!({"rates_m_s": [5.0, -1.0]}))),
        "rates_m_s[1]"
    );
    assert_eq!(
        field_of(body(
            json!({"rates_m_s": {"min": 1.0, "max": 2.0, "count": 0}})
        )),
        "rates_m_s.count"
    );
    assert_eq!(
        field_of(body(
            json!({"rates_m_s": {"min": 1.0, "max": 2.0, "cnt": 3}})
        )),
        "rates_m_s.cnt"
    );
    assert_eq!(field_of(body(json!({"rates_m_s": "fast"}))), "rates_m_s");
    assert_eq!(
        field_of(body(json!({"target_elevation_m": 0.0}))),
        "target_elevation_m"
    );
    assert_eq!(field_of(body(json!({"wind_m_s": 3.0}))), "wind_m_s");
    assert_eq!(
        field_of(body(
            json!({"aerostat": {"net_buoyancy_n": 1.0, "lift": 2}})
        )),
        "aerostat.lift"
    );
    assert_eq!(
        field_of(body(json!({"uncertainty": {"samples": 0, "inputs": [
            {"field": "aerostat.mass_kg", "distribution": "uniform", "low": 9.0, "high": 11.0}]}}))),
        "uncertainty.samples"
    );
}

/// Rare invalid draws are counted and left out, not silently used.
#[test]
fn out_of_range_draws_are_counted_and_left_out() {
    // P(m < 0) for N(10, 4.2) = Φ(−2.381) ≈ 8.6e-3 (just under the limit)
    let b = body(
        json!({"uncertainty": {"samples": 4000, "seed": 1, "inputs": [
        {"field": "aerostat.mass_kg", "distribution": "normal", "mean": 10.0, "std_dev": 4.2}]}}),
    );
    let resp = bands(&parse_bands(&b).unwrap(), Parallelism::Rayon, &NoProgress).unwrap();
    let rejected = &resp.rejected_samples[0];
    assert_eq!(rejected.field, "aerostat.mass_kg");
    // expected 34.5 ± 5.9
    assert!((12..=60).contains(&rejected.count), "{}", rejected.count);
    assert_eq!(resp.valid_samples + rejected.count, 4000);
}
