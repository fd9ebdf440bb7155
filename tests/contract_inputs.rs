//! Bad input gets an error naming the field; physical outcomes are answers.

use tetherplan::contract::dto::{ChartRequest, CriticalRequest, SafeRateRequest, StabilityRequest};
use tetherplan::contract::run::{self, NoProgress};
use tetherplan::contract::{RequestError, parse};
use tetherplan::numerics::parallel::Parallelism;

const SYSTEM: &str = r#""cable": {"mass_per_length_kg_m": 0.078},
    "aerostat": {"net_buoyancy_n": 1000, "mass_kg": 10},
    "initial_length_m": 1,
    "model": {"kind": "linear_string", "elements": 50}"#;

fn with(extra: &str) -> String {
    format!("{{{SYSTEM}, {extra}}}")
}

fn field_of(e: RequestError) -> String {
    match e {
        RequestError::Invalid(i) => i.field,
        RequestError::Malformed(_) => "body".into(),
        other => panic!("expected invalid input, got {other:?}"),
    }
}

fn critical_error(body: &str) -> String {
    field_of(
        parse::<CriticalRequest>(body.as_bytes())
            .and_then(|r| run::critical(&r))
            .unwrap_err(),
    )
}

#[test]
fn the_issue_example_answers_with_real_numbers() {
    let req: CriticalRequest =
        parse(with(r#""profile": {"kind": "constant_rate", "rate_m_s": 10}"#).as_bytes()).unwrap();
    let resp = run::critical(&req).unwrap();
    assert!((resp.max_elevation_m.unwrap() - 1310.0).abs() < 1.0);
    assert!((resp.closed_form_elevation_m.unwrap() - 1296.688).abs() < 1e-3);
    assert!((resp.critical_time_s.unwrap() - 130.9).abs() < 0.1);
    assert_eq!(resp.onset, "during");

    let req: SafeRateRequest = parse(with(r#""target_elevation_m": 1200"#).as_bytes()).unwrap();
    let resp = run::safe_rate(&req).unwrap();
    assert!(
        (resp.max_rate_m_s.unwrap() - 34.49).abs() < 0.01,
        "{:?}",
        resp.max_rate_m_s
    );

    let req: StabilityRequest = parse(
        with(r#""state": {"length_m": 500, "rate_m_s": 10, "acceleration_m_s2": 0}, "modes": 3"#)
            .as_bytes(),
    )
    .unwrap();
    let resp = run::stability(&req).unwrap();
    assert!(resp.stable);
    assert_eq!(resp.eigenvalues.len(), 3);
    assert!(
        resp.eigenvalues
            .windows(2)
            .all(|w| w[0].im_1_s <= w[1].im_1_s)
    );
    assert!(
        resp.max_real_1_s < 0.0,
        "lengthening damps: {}",
        resp.max_real_1_s
    );

    let req: ChartRequest = parse(
        with(r#""rates_m_s": {"min": 5, "max": 50, "count": 10}, "net_buoyancies_n": [500, 1000, 2000]"#).as_bytes(),
    )
    .unwrap();
    let resp = run::chart(&req, Parallelism::Rayon, &NoProgress).unwrap();
    assert_eq!(resp.series.len(), 3);
    assert_eq!(resp.series[1].points.len(), 10);
    assert_eq!(resp.series[1].points[1].rate_m_s, 10.0);
    assert!((resp.series[1].points[1].max_elevation_m - 1310.0).abs() < 1.0);
}

#[test]
fn density_and_area_give_the_same_answer() {
    let a: CriticalRequest =
        parse(with(r#""profile": {"kind": "constant_rate", "rate_m_s": 10}"#).as_bytes()).unwrap();
    let b: CriticalRequest = parse(
        with(r#""profile": {"kind": "constant_rate", "rate_m_s": 10}"#)
            .replace(
                r#""mass_per_length_kg_m": 0.078"#,
                r#""density_kg_m3": 7800, "area_m2": 1e-5"#,
            )
            .as_bytes(),
    )
    .unwrap();
    let (a, b) = (run::critical(&a).unwrap(), run::critical(&b).unwrap());
    assert!((a.max_elevation_m.unwrap() - b.max_elevation_m.unwrap()).abs() < 1e-9);
}

#[test]
fn bad_inputs_name_the_field() {
    let profile = r#""profile": {"kind": "constant_rate", "rate_m_s": 10}"#;
    let cases: Vec<(String, &str)> = vec![
        // NaN is not JSON; neither is an out-of-range number
        (with(profile).replace("0.078", "NaN"), "body"),
        (with(profile).replace("0.078", "1e999"), "body"),
        (
            with(profile).replace("0.078", "0"),
            "cable.mass_per_length_kg_m",
        ),
        (
            with(profile).replace("0.078", "-0.078"),
            "cable.mass_per_length_kg_m",
        ),
        (
            with(profile).replace("0.078", "\"heavy\""),
            "cable.mass_per_length_kg_m",
        ),
        (
            with(profile).replace(r#""net_buoyancy_n": 1000"#, r#""net_buoyancy_n": -1000"#),
            "aerostat.net_buoyancy_n",
        ),
        (
            with(profile).replace(r#""net_buoyancy_n": 1000, "#, ""),
            "aerostat.net_buoyancy_n",
        ),
        (
            with(profile).replace(r#""elements": 50"#, r#""elements": 0"#),
            "model.elements",
        ),
        (
            with(profile).replace(r#""elements": 50"#, r#""elements": 1000000"#),
            "model.elements",
        ),
        (
            with(profile).replace(r#""elements": 50"#, r#""elements": -5"#),
            "model.elements",
        ),
        (
            with(profile).replace(r#""linear_string""#, r#""wobbly""#),
            "model.kind",
        ),
        (
            with(profile).replace(r#""initial_length_m": 1"#, r#""initial_length_m": -1"#),
            "initial_length_m",
        ),
        (
            with(r#""profile": {"kind": "constant_rate"}"#),
            "profile.rate_m_s",
        ),
        (
            with(r#""profile": {"kind": "constant_rate", "rate_m_s": 10, "target_length_m": 0.5}"#),
            "profile.target_length_m",
        ),
        (
            with(r#""profile": {"kind": "constant_acceleration", "acceleration_m_s2": 0}"#),
            "profile.acceleration_m_s2",
        ),
        (SYSTEM.to_string(), "body"),
        ("[]".to_string(), "body"),
    ];
    for (body, field) in cases {
        assert_eq!(critical_error(&body), field, "body: {body}");
    }
}

#[test]
fn huge_charts_and_bad_grids_are_refused() {
    let chart = |grid: &str, buoyancies: &str| {
        let body = with(&format!(
            r#""rates_m_s": {grid}, "net_buoyancies_n": {buoyancies}"#
        ));
        field_of(
            parse::<ChartRequest>(body.as_bytes())
                .and_then(|r| run::chart(&r, Parallelism::Serial, &NoProgress))
                .unwrap_err(),
        )
    };
    assert_eq!(
        chart(r#"{"min": 1, "max": 100, "count": 1000000000}"#, "[1000]"),
        "rates_m_s.count"
    );
    assert_eq!(
        chart(
            r#"{"min": 1, "max": 100, "count": 400000}"#,
            "[1000, 2000, 3000]"
        ),
        "rates_m_s.count"
    );
    assert_eq!(
        chart(r#"{"min": 1, "max": 100, "count": 0}"#, "[1000]"),
        "rates_m_s.count"
    );
    assert_eq!(
        chart(r#"{"min": -1, "max": 100, "count": 10}"#, "[1000]"),
        "rates_m_s.min"
    );
    assert_eq!(
        chart(r#"{"min": 10, "max": 1, "count": 10}"#, "[1000]"),
        "rates_m_s.max"
    );
    assert_eq!(
        chart(r#"{"min": 1, "max": 10, "count": 10}"#, "[1000, -5]"),
        "net_buoyancies_n[1]"
    );
}

#[test]
fn physical_outcomes_are_answers_not_errors() {
    // above the wave speed: unstable at t = 0
    let req: CriticalRequest =
        parse(with(r#""profile": {"kind": "constant_rate", "rate_m_s": 150}"#).as_bytes()).unwrap();
    let resp = run::critical(&req).unwrap();
    assert_eq!(resp.critical_time_s, Some(0.0));
    assert_eq!(resp.onset, "immediate");
    assert!(
        resp.explanation.contains("wave speed"),
        "{}",
        resp.explanation
    );
    // shortening: unstable at once
    let req: CriticalRequest =
        parse(with(r#""profile": {"kind": "constant_rate", "rate_m_s": -1}"#).as_bytes()).unwrap();
    let resp = run::critical(&req).unwrap();
    assert_eq!(resp.critical_time_s, Some(0.0));
    assert!(resp.explanation.contains("shortening"));
    // above the static lift limit F/(ρA g) = 1306.9 m: no safe rate, with the reason
    let req: SafeRateRequest = parse(with(r#""target_elevation_m": 1500"#).as_bytes()).unwrap();
    let resp = run::safe_rate(&req).unwrap();
    assert_eq!(resp.max_rate_m_s, None);
    assert!(resp.reason.unwrap().contains("static lift limit"));
}

#[test]
fn confirmation_probes_agree_when_asked() {
    let req: CriticalRequest = parse(
        with(r#""profile": {"kind": "constant_rate", "rate_m_s": 10}, "confirm_with_qep": true"#)
            .as_bytes(),
    )
    .unwrap();
    let resp = run::critical(&req).unwrap();
    assert_eq!(resp.qep_probes.len(), 4);
    assert!(resp.confirmed_by_qep);
    let after = resp.qep_probes.last().unwrap();
    assert!(!after.stable && after.max_real_1_s > 0.0);
}
