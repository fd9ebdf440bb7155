//! `POST /api/v1/windows` (SPEC §12, issue 32): each forecast period is
//! judged exactly as `/plan` judges the wind the answer echoes; the
//! Open-Meteo file of `tests/forecasts/` (its documented format), a uniform
//! hour and the knot conversion, METAR and TAF winds, ensembles (all equal:
//! the single answer, split 3:1: 0.75), and bad input refused naming its
//! field and key or line.

use axum::http::StatusCode;
use serde_json::{Value, json};
use tetherplan::config::Limits;

mod common;

/// The route's answer; a forecast of more distinct winds than the
/// synchronous budget pays for (a plan each, issue 34's prices) is refused
/// `too_large` at once and answered as a `windows` job, as the page does.
async fn post(uri: &str, body: &Value) -> (StatusCode, Value) {
    let (app, queue) = common::app_with(1, Limits::default());
    let (status, answer) = common::post(&app, uri, body).await;
    if !(uri == "/api/v1/windows" && answer["error"]["code"] == "too_large") {
        return (status, answer);
    }
    assert_eq!(answer["error"]["field"], "forecast.data", "{answer}");
    let (status, sub) = common::post(
        &app,
        "/api/v1/jobs",
        &json!({"kind": "windows", "request": body}),
    )
    .await;
    assert_eq!(status, StatusCode::ACCEPTED, "{sub}");
    let ran = tetherplan::jobs::try_execute_next(&queue).unwrap().unwrap();
    assert_eq!(ran.status, tetherplan::jobs::store::JobStatus::Done);
    let job = common::get(&app, &format!("/api/v1/jobs/{}", sub["id"])).await;
    (StatusCode::OK, job["result"].clone())
}

/// The system of the plan's documented example, flying at 300 m.
fn system() -> Value {
    json!({
        "cable": {"mass_per_length_kg_m": 0.078, "diameter_m": 0.006, "breaking_strength_n": 20000.0},
        "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0, "drag_coefficient_nondim": 0.3,
                     "reference_area_m2": 20.0},
        "winch": {"max_rate_m_s": 10.0, "max_acceleration_m_s2": 1.0},
        "target_elevation_m": 300.0
    })
}

fn windows_request(format: &str, data: Value) -> Value {
    let mut b = system();
    b["operation_s"] = json!(3600.0);
    b["forecast"] = json!({"format": format, "data": data});
    b
}

fn open_meteo_file() -> Value {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/forecasts/open_meteo_hourly.json"
    ))
    .unwrap();
    serde_json::from_str(&text).unwrap()
}

/// `/plan` for the system in `wind`.
async fn plan_in(wind: &Value) -> Value {
    let mut b = system();
    b["wind"] = wind.clone();
    let (s, r) = post("/api/v1/plan", &b).await;
    assert_eq!(s, StatusCode::OK, "{r}");
    r
}

/// The hour's answer is `/plan`'s for `wind`, to the bit.
async fn assert_hour_is_plan(h: &Value, wind: &Value) {
    let p = plan_in(wind).await;
    let verdict = if p["go"] == true { "go" } else { "no-go" };
    assert_eq!(h["verdict"], verdict, "{}: {}", h["time"], h["reason"]);
    assert_eq!(h["reason"], p["reason"], "{}", h["time"]);
    assert_eq!(
        h["max_altitude_m"], p["wind"]["reachable_altitude_m"],
        "{}",
        h["time"]
    );
    assert_eq!(
        h["peak_tension_n"], p["limits"]["peak_tension_n"],
        "{}",
        h["time"]
    );
    assert_eq!(
        h["safety_factor_nondim"], p["limits"]["min_safety_factor_nondim"],
        "{}",
        h["time"]
    );
    assert_eq!(h["deployment_s"], p["duration_s"], "{}", h["time"]);
}

#[tokio::test]
async fn open_meteo_hours_are_the_plan_of_their_echoed_wind() {
    let (s, r) = post(
        "/api/v1/windows",
        &windows_request("open_meteo", open_meteo_file()),
    )
    .await;
    assert_eq!(s, StatusCode::OK, "{r}");
    let hours = r["hours"].as_array().unwrap();
    assert_eq!(hours.len(), 24);
    assert_eq!(hours[0]["time"], "2026-12-03T00:00");
    assert_eq!(hours[0]["end"], "2026-12-03T01:00");
    assert_eq!(r["roughness_length_m"], 0.03);
    for h in hours {
        assert_hour_is_plan(h, &h["wind"]).await;
    }
    // Four heights: a power law from 10 m; the calm hour 02:00: uniform 0,
    // its 2 km/h gust left out (and said so).
    assert_eq!(hours[5]["wind"]["flow"]["kind"], "power_law");
    assert_eq!(hours[5]["wind"]["flow"]["reference_height_m"], 10.0);
    assert_eq!(
        hours[2]["wind"]["flow"],
        json!({"kind": "uniform", "speed_m_s": 0.0})
    );
    assert!(hours[2]["wind"].get("gust").is_none());
    assert!(
        r["notes"].to_string().contains("2026-12-03T02:00"),
        "{}",
        r["notes"]
    );
    let verdicts: Vec<&str> = hours
        .iter()
        .map(|h| h["verdict"].as_str().unwrap())
        .collect();
    assert!(
        verdicts.contains(&"go") && verdicts.contains(&"no-go"),
        "{verdicts:?}"
    );
    // The windows are the runs of in-limit hours long enough for the
    // deployment, an hour aloft and the haul-down.
    let ws = r["windows"].as_array().unwrap();
    assert!(!ws.is_empty());
    for w in ws {
        let inside: Vec<&Value> = hours
            .iter()
            .filter(|h| {
                h["time"].as_str().unwrap() >= w["start"].as_str().unwrap()
                    && h["time"].as_str().unwrap() < w["end"].as_str().unwrap()
            })
            .collect();
        assert!(
            inside
                .iter()
                .all(|h| h["in_window_limits"] == true && h["verdict"] == "go")
        );
        let need = inside
            .iter()
            .map(|h| h["deployment_s"].as_f64().unwrap() + h["haul_down_s"].as_f64().unwrap())
            .fold(0.0, f64::max)
            + 3600.0;
        assert_eq!(w["required_s"].as_f64().unwrap(), need);
        assert_eq!(
            w["duration_s"].as_f64().unwrap(),
            3600.0 * inside.len() as f64
        );
        assert!(w["duration_s"].as_f64().unwrap() >= need);
    }
}

/// Open-Meteo writes `null` where it has no value (past the horizon of a
/// height or a model). An hour whose upper heights are null is fitted
/// through the heights it has; an hour whose gust is null is judged in the
/// mean wind only, and the answer says so; an hour with no speed at all is
/// left out, and said so.
#[tokio::test]
async fn open_meteo_nulls_fit_what_remains_and_say_what_is_missing() {
    let mut f = open_meteo_file();
    for k in ["wind_speed_80m", "wind_speed_120m", "wind_speed_180m"] {
        f["hourly"][k][20] = Value::Null;
    }
    f["hourly"]["wind_gusts_10m"][21] = Value::Null;
    f["hourly"]["wind_gusts_10m"][22] = Value::Null;
    for k in [
        "wind_speed_10m",
        "wind_speed_80m",
        "wind_speed_120m",
        "wind_speed_180m",
    ] {
        f["hourly"][k][23] = Value::Null;
    }
    let (s, r) = post("/api/v1/windows", &windows_request("open_meteo", f)).await;
    assert_eq!(s, StatusCode::OK, "{r}");
    let hours = r["hours"].as_array().unwrap();
    assert_eq!(hours.len(), 23, "the hour without any speed is left out");
    // 20:00 from its 10 m speed alone: the log law of the roughness.
    assert_eq!(hours[20]["wind"]["flow"]["kind"], "log_law");
    assert_eq!(hours[20]["wind"]["flow"]["reference_height_m"], 10.0);
    assert!(hours[21]["wind"].get("gust").is_none());
    assert!(hours[22]["wind"].get("gust").is_none());
    assert!(hours[19]["wind"].get("gust").is_some());
    for h in &hours[20..23] {
        assert_hour_is_plan(h, &h["wind"]).await;
    }
    let notes = r["notes"].to_string();
    assert!(
        notes.contains("control: 2 hour(s) with no gust (null) judged in the mean wind only"),
        "{notes}"
    );
    assert!(
        notes.contains("control: 1 hour(s) with no wind speed at any height left out"),
        "{notes}"
    );
}

/// A CSV whose times carry an offset gets its ends and windows back in
/// that offset (an end of `…T01:00` after a start of `…T00:00+01:00` read
/// as if the period ended where it began).
#[tokio::test]
async fn csv_times_with_an_offset_are_answered_in_that_offset() {
    let csv = "time,height_m,speed_m_s,gust_m_s\n\
               2026-12-03T00:00+01:00,10,3,5\n\
               2026-12-03T01:00+01:00,10,3,5\n";
    let (s, r) = post("/api/v1/windows", &windows_request("csv", json!(csv))).await;
    assert_eq!(s, StatusCode::OK, "{r}");
    let hours = r["hours"].as_array().unwrap();
    assert_eq!(hours[0]["time"], "2026-12-03T00:00+01:00");
    assert_eq!(hours[0]["end"], "2026-12-03T01:00+01:00");
    assert_eq!(hours[1]["end"], "2026-12-03T02:00+01:00");
    assert_eq!(hours[1]["lead_time_s"], 3600.0);
    let w = &r["windows"][0];
    assert_eq!(w["start"], "2026-12-03T00:00+01:00", "{r}");
    assert_eq!(w["end"], "2026-12-03T02:00+01:00");
    assert!(
        w["latest_launch"].as_str().unwrap().ends_with("+01:00"),
        "{w}"
    );
}

/// What the fit changes is said: a gust below the mean (taken as the
/// mean) and a profile whose fitted exponent leaves [0, 2] (speeds falling
/// with height: the exponent brought to 0).
#[tokio::test]
async fn a_low_gust_and_a_clamped_exponent_are_noted() {
    let csv = "time,height_m,speed_m_s,gust_m_s\n\
               2026-12-03T00:00,10,6,3\n\
               2026-12-03T01:00,10,6,\n\
               2026-12-03T01:00,80,3,\n";
    let (s, r) = post("/api/v1/windows", &windows_request("csv", json!(csv))).await;
    assert_eq!(s, StatusCode::OK, "{r}");
    let h = &r["hours"][0];
    // the gust taken as the mean: its speed at the reference height is the mean's
    let (g, u) = (
        h["wind"]["gust"]["gust_m_s"].as_f64().unwrap(),
        h["wind"]["flow"]["speed_m_s"].as_f64().unwrap(),
    );
    assert!((g - u).abs() <= 1e-12 * u, "{h}");
    assert_eq!(r["hours"][1]["wind"]["flow"]["exponent_nondim"], 0.0);
    let notes = r["notes"].to_string();
    assert!(
        notes.contains("a gust below the mean wind at its height is taken as the mean (gust ratio 1): control 2026-12-03T00:00"),
        "{notes}"
    );
    assert!(
        notes.contains("exponent outside [0, 2], brought to its nearer end (the speeds refitted): control 2026-12-03T01:00"),
        "{notes}"
    );
}

/// The plan's `haul_down.source` takes the windows' formats: a TAF read at
/// the target altitude is the `haul_down.forecast` of its groups' winds by
/// the log law of 0.03 m (computed here), a group without `G` having the
/// mean as its gust. A source without any gust cannot serve a gust limit,
/// and one with gusts needs it: both refused, naming the field.
#[tokio::test]
async fn the_plans_haul_down_source_is_its_forecast_read_at_the_target() {
    let taf = "TAF EGLL 051100Z 0512/0618 24010KT 9999 BECMG 0515/0517 27020G32KT \
               TEMPO 0520/0602 30030G45KT";
    let kn = 1852.0 / 3600.0;
    let at_300 = |u10_kn: f64| u10_kn * kn * (300.0f64 / 0.03).ln() / (10.0f64 / 0.03).ln();
    let limits = json!({"max_operating_wind_m_s": 14.0, "max_gust_m_s": 24.0});
    let mut by_source = system();
    by_source["haul_down"] = limits.clone();
    by_source["haul_down"]["source"] = json!({"format": "taf", "data": taf});
    let mut by_points = system();
    by_points["haul_down"] = limits.clone();
    by_points["haul_down"]["forecast"] = json!([
        {"time_s": 0.0, "wind_speed_m_s": at_300(10.0), "gust_m_s": at_300(10.0)},
        {"time_s": 10800.0, "wind_speed_m_s": at_300(20.0), "gust_m_s": at_300(32.0)},
        {"time_s": 28800.0, "wind_speed_m_s": at_300(30.0), "gust_m_s": at_300(45.0)},
    ]);
    let (s, a) = post("/api/v1/plan", &by_source).await;
    assert_eq!(s, StatusCode::OK, "{a}");
    let (s, b) = post("/api/v1/plan", &by_points).await;
    assert_eq!(s, StatusCode::OK, "{b}");
    let (ha, hb) = (&a["haul_down"], &b["haul_down"]);
    for k in [
        "wind_exceeds_limit_at_s",
        "gust_exceeds_limit_at_s",
        "latest_start_s",
        "retrieval_duration_s",
    ] {
        let (x, y) = (ha[k].as_f64().unwrap(), hb[k].as_f64().unwrap());
        assert!((x - y).abs() <= 1e-9 * y.abs().max(1.0), "{k}: {x} vs {y}");
    }
    assert_eq!(ha["exceeded_by"], hb["exceeded_by"]);
    assert_eq!(a["go"], b["go"]);
    // the mean passes 14 m/s on the way to the BECMG's 20 kt (18 m/s aloft)
    let t = ha["wind_exceeds_limit_at_s"].as_f64().unwrap();
    assert!(t > 0.0 && t < 10800.0, "{t}");

    let mut no_gusts = system();
    no_gusts["haul_down"] = limits.clone();
    no_gusts["haul_down"]["source"] = json!({"format": "csv",
        "data": "time,height_m,speed_m_s\n2026-12-03T00:00,10,3\n2026-12-03T01:00,10,8\n"});
    let (f, m) = refused_by("/api/v1/plan", &no_gusts).await;
    assert_eq!(f, "haul_down.source.data", "{m}");
    assert!(m.contains("gives no gust"), "{m}");
    let mut no_limit = system();
    no_limit["haul_down"] = json!({"max_operating_wind_m_s": 14.0,
        "source": {"format": "taf", "data": taf}});
    assert_eq!(
        refused_by("/api/v1/plan", &no_limit).await.0,
        "haul_down.max_gust_m_s"
    );
}

/// A text with several reports (a METAR history, a TAF and its
/// amendment) is judged by its latest report alone, and says so: read as
/// one, the later groups overwrote the earlier ones (the first TAF's
/// validity with the amendment's wind).
#[tokio::test]
async fn of_several_reports_the_latest_is_judged() {
    let older = "METAR EDDB 031150Z 27025KT 9999 FEW030 08/02 Q1012";
    let newer = "METAR EDDB 031220Z 27005KT 9999 FEW030 08/02 Q1012";
    let taf = "TAF EDDB 031100Z 0312/0412 24010KT 9999 SCT030";
    let amd = "TAF AMD EDDB 031300Z 0313/0412 30025KT 9999 SCT030";
    for (format, text, alone, at) in [
        ("metar", format!("{newer}\n{older}"), newer, "031220Z"),
        ("metar", format!("{older} {newer}"), newer, "031220Z"),
        ("taf", format!("{taf}\n{amd}"), amd, "031300Z"),
    ] {
        let (s, both) = post("/api/v1/windows", &windows_request(format, json!(text))).await;
        assert_eq!(s, StatusCode::OK, "{both}");
        let (s, one) = post("/api/v1/windows", &windows_request(format, json!(alone))).await;
        assert_eq!(s, StatusCode::OK, "{one}");
        assert_eq!(both["hours"], one["hours"], "{text}");
        assert_eq!(both["windows"], one["windows"], "{text}");
        let note = both["notes"][0].as_str().unwrap();
        let what = format.to_uppercase();
        assert_eq!(
            note,
            format!("2 {what} reports given: the latest, of {at}, is judged, the others left out")
        );
    }
    // A report among them that cannot be read is named by its place.
    let (f, m) = refused(&windows_request(
        "metar",
        json!(format!("{older}\nMETAR EDDB 031220Z /////KT 9999")),
    ))
    .await;
    assert_eq!(f, "forecast.data");
    assert!(m.contains("METAR 2 of 2"), "{m}");
}

#[tokio::test]
async fn a_uniform_hour_in_knots_is_the_plan_for_that_speed() {
    // 15 kn at 10 and 80 m: a uniform flow of exactly 15 × 1852/3600 m/s.
    let data = json!({
        "hourly_units": {"time": "iso8601", "wind_speed_10m": "kn", "wind_speed_80m": "kn"},
        "hourly": {"time": ["2026-12-03T09:00", "2026-12-03T10:00"],
                   "wind_speed_10m": [15.0, 0.0], "wind_speed_80m": [15.0, 0.0]}
    });
    let (s, r) = post("/api/v1/windows", &windows_request("open_meteo", data)).await;
    assert_eq!(s, StatusCode::OK, "{r}");
    let u = 15.0 * 1852.0 / 3600.0;
    let h = &r["hours"][0];
    assert_eq!(
        h["wind"]["flow"],
        json!({"kind": "uniform", "speed_m_s": u})
    );
    assert_eq!(h["wind_at_target_m_s"], u);
    assert_hour_is_plan(h, &json!({"flow": {"kind": "uniform", "speed_m_s": u}})).await;
    // The calm hour is the plan in calm (zero-speed) air.
    assert_hour_is_plan(
        &r["hours"][1],
        &json!({"flow": {"kind": "uniform", "speed_m_s": 0.0}}),
    )
    .await;
}

#[tokio::test]
async fn metar_winds_gusts_variable_calm_and_mps() {
    // v kn = v·1852/3600 m/s, as the definition reads.
    let kn = |v: f64| v * 1852.0 / 3600.0;
    for (report, flow, gust) in [
        (
            "METAR EDDB 031250Z 27015G25KT 9999 FEW030 08/02 Q1012",
            json!({"kind": "log_law", "speed_m_s": kn(15.0), "reference_height_m": 10.0, "roughness_length_m": 0.03}),
            Some(kn(25.0)),
        ),
        (
            "METAR EDDB 031250Z VRB03KT CAVOK 08/02 Q1012",
            json!({"kind": "log_law", "speed_m_s": kn(3.0), "reference_height_m": 10.0, "roughness_length_m": 0.03}),
            None,
        ),
        (
            "METAR EDDB 031250Z 00000KT CAVOK 08/02 Q1012",
            json!({"kind": "uniform", "speed_m_s": 0.0}),
            None,
        ),
        (
            "METAR UUEE 031230Z 03005MPS 9999 BKN020 M02/M05 Q1020",
            json!({"kind": "log_law", "speed_m_s": 5.0, "reference_height_m": 10.0, "roughness_length_m": 0.03}),
            None,
        ),
    ] {
        let (s, r) = post("/api/v1/windows", &windows_request("metar", json!(report))).await;
        assert_eq!(s, StatusCode::OK, "{report}: {r}");
        let h = &r["hours"][0];
        assert_eq!(r["hours"].as_array().unwrap().len(), 1);
        assert_eq!(h["time"], report.split(' ').nth(2).unwrap(), "{report}");
        assert_eq!(h["group"], "metar");
        assert_eq!(h["wind"]["flow"], flow, "{report}");
        match gust {
            Some(g) => {
                let got = h["wind"]["gust"]["gust_m_s"].as_f64().unwrap();
                assert!((got - g).abs() <= 1e-12 * g, "{report}: {got} vs {g}");
            }
            None => assert!(h["wind"].get("gust").is_none(), "{report}"),
        }
        assert_hour_is_plan(h, &h["wind"]).await;
    }
}

#[tokio::test]
async fn taf_gives_one_period_per_change_group() {
    let taf = "TAF EDDB 031100Z 0312/0412 24010KT 9999 SCT030 \
               BECMG 0315/0317 27020G30KT \
               TEMPO 0318/0322 30030G45KT TSRA";
    let (s, r) = post("/api/v1/windows", &windows_request("taf", json!(taf))).await;
    assert_eq!(s, StatusCode::OK, "{r}");
    let hours = r["hours"].as_array().unwrap();
    let seen: Vec<(&str, &str, &str, f64)> = hours
        .iter()
        .map(|h| {
            (
                h["group"].as_str().unwrap(),
                h["time"].as_str().unwrap(),
                h["end"].as_str().unwrap(),
                h["lead_time_s"].as_f64().unwrap(),
            )
        })
        .collect();
    assert_eq!(
        seen,
        vec![
            ("base", "031200Z", "041200Z", 3600.0),
            ("becmg", "031500Z", "041200Z", 4.0 * 3600.0),
            ("tempo", "031800Z", "032200Z", 7.0 * 3600.0),
        ]
    );
    assert_eq!(
        hours[1]["wind"]["flow"]["speed_m_s"],
        20.0 * 1852.0 / 3600.0
    );
    assert_eq!(
        hours[2]["wind"]["flow"]["speed_m_s"],
        30.0 * 1852.0 / 3600.0
    );
    for h in hours {
        assert_hour_is_plan(h, &h["wind"]).await;
    }
    // A no-go TEMPO cuts the windows of the periods it overlaps.
    if hours[2]["in_window_limits"] == false {
        for w in r["windows"].as_array().unwrap() {
            let (a, b) = (w["start"].as_str().unwrap(), w["end"].as_str().unwrap());
            assert!(b <= "031800Z" || a >= "032200Z", "{w}");
        }
    }
}

/// The Open-Meteo file as an ensemble: the control and `members` copies
/// suffixed `_member01`, …, the copies changed by `edit(member, key, values)`.
fn ensemble(members: usize, edit: impl Fn(usize, &str, &mut Vec<Value>)) -> Value {
    let mut d = open_meteo_file();
    let hourly = d["hourly"].as_object().unwrap().clone();
    let units = d["hourly_units"].as_object().unwrap().clone();
    for m in 1..=members {
        for (k, v) in &hourly {
            if k == "time" {
                continue;
            }
            let key = format!("{k}_member{m:02}");
            let mut values = v.as_array().unwrap().clone();
            edit(m, k, &mut values);
            d["hourly"][&key] = Value::Array(values);
            d["hourly_units"][&key] = units[k].clone();
        }
    }
    d
}

#[tokio::test]
async fn an_ensemble_of_equal_members_is_the_single_forecast() {
    let mut req = windows_request("open_meteo", open_meteo_file());
    req["haul_down"] = json!({"max_operating_wind_m_s": 12.0, "max_gust_m_s": 20.0});
    let (s, single) = post("/api/v1/windows", &req).await;
    assert_eq!(s, StatusCode::OK, "{single}");
    req["forecast"]["data"] = ensemble(3, |_, _, _| {});
    let (s, r) = post("/api/v1/windows", &req).await;
    assert_eq!(s, StatusCode::OK, "{r}");
    assert_eq!(r["members"], 4);
    assert_eq!(r["plans_computed"], single["plans_computed"]);
    for (h, one) in r["hours"]
        .as_array()
        .unwrap()
        .iter()
        .zip(single["hours"].as_array().unwrap())
    {
        for k in [
            "time",
            "wind",
            "verdict",
            "reason",
            "max_altitude_m",
            "peak_tension_n",
            "in_window_limits",
        ] {
            assert_eq!(h[k], one[k], "{k} at {}", h["time"]);
        }
        let p = if h["verdict"] == "go" { 1.0 } else { 0.0 };
        assert_eq!(h["probability_go"], p);
        for k in [
            "max_altitude_p10_m",
            "max_altitude_p50_m",
            "max_altitude_p90_m",
        ] {
            assert_eq!(h[k], h["max_altitude_m"], "{k}");
        }
        assert!(one.get("probability_go").is_none());
    }
    let ws = r["windows"].as_array().unwrap();
    assert_eq!(ws.len(), single["windows"].as_array().unwrap().len());
    for (w, one) in ws.iter().zip(single["windows"].as_array().unwrap()) {
        assert_eq!((&w["start"], &w["end"]), (&one["start"], &one["end"]));
        assert_eq!(w["probability"], 1.0);
    }
}

#[tokio::test]
async fn members_split_three_to_one_give_three_quarters() {
    // Member 3 has a gale at 08:00 (index 8) at every height; the rest are the control.
    let data = ensemble(3, |m, k, v| {
        if m == 3 && k.starts_with("wind_speed_") {
            v[8] = json!(140.0);
        }
        if m == 3 && k.starts_with("wind_gusts_") {
            v[8] = json!(190.0);
        }
    });
    let (s, r) = post("/api/v1/windows", &windows_request("open_meteo", data)).await;
    assert_eq!(s, StatusCode::OK, "{r}");
    let h = &r["hours"][8];
    assert_eq!(h["verdict"], "go", "{}", h["reason"]);
    assert_eq!(h["probability_go"], 0.75);
    let (lo, hi) = (
        h["probability_go_low"].as_f64().unwrap(),
        h["probability_go_high"].as_f64().unwrap(),
    );
    assert!(
        lo < 0.75 && hi > 0.75 && lo >= 0.0 && hi <= 1.0,
        "{lo} {hi}"
    );
    // The stormy member's altitude is the lowest: the 10 % point is below the median.
    assert!(h["max_altitude_p10_m"].as_f64().unwrap() < h["max_altitude_p50_m"].as_f64().unwrap());
}

#[tokio::test]
async fn haul_down_limits_make_windy_hours_no_go_and_say_so() {
    let mut req = windows_request("open_meteo", open_meteo_file());
    req["haul_down"] = json!({"max_operating_wind_m_s": 12.0});
    let (s, r) = post("/api/v1/windows", &req).await;
    assert_eq!(s, StatusCode::OK, "{r}");
    let mut seen = false;
    for h in r["hours"].as_array().unwrap() {
        let u = h["wind_at_target_m_s"].as_f64().unwrap();
        if u > 12.0 {
            seen = true;
            assert_eq!(h["verdict"], "no-go", "{}", h["time"]);
            // A plan that flies says the haul-down binds; one that cannot fly says why.
            if h["deployment_s"].is_number() {
                assert!(
                    h["reason"].as_str().unwrap().contains("haul-down"),
                    "{}",
                    h["reason"]
                );
            }
        }
        // Within a window only with α × the limit.
        if h["in_window_limits"] == true {
            assert!(u <= h["limit_factor_nondim"].as_f64().unwrap() * 12.0);
        }
    }
    assert!(seen);
    assert_eq!(r["lead_time_factor"]["per_hour_nondim"], 0.01);
    // α at 12 h is 0.88.
    assert!((r["hours"][12]["limit_factor_nondim"].as_f64().unwrap() - 0.88).abs() < 1e-12);
}

async fn refused(body: &Value) -> (String, String) {
    refused_by("/api/v1/windows", body).await
}

/// `uri`'s 422 for `body`: its field and message.
async fn refused_by(uri: &str, body: &Value) -> (String, String) {
    let (s, r) = post(uri, body).await;
    assert_eq!(s, StatusCode::UNPROCESSABLE_ENTITY, "{r}");
    (
        r["error"]["field"].as_str().unwrap_or_default().to_string(),
        r["error"]["message"]
            .as_str()
            .unwrap_or_default()
            .to_string(),
    )
}

#[tokio::test]
async fn bad_forecasts_are_refused_naming_field_and_key_or_line() {
    let om = |hourly: Value, units: Value| json!({"hourly": hourly, "hourly_units": units});
    let t = json!(["2026-12-03T00:00", "2026-12-03T01:00", "2026-12-03T02:00"]);
    let cases: Vec<(&str, Value, &str, &str)> = vec![
        (
            "open_meteo",
            json!("not an object"),
            "forecast.data",
            "JSON object",
        ),
        (
            "open_meteo",
            json!({"latitude": 1.0}),
            "forecast.data.hourly",
            "required",
        ),
        (
            "open_meteo",
            om(
                json!({"time": t, "wind_speed_10m": [1, 2, 3]}),
                json!({"wind_speed_10m": "furlong/fortnight"}),
            ),
            "forecast.data.hourly_units.wind_speed_10m",
            "unknown unit",
        ),
        (
            "open_meteo",
            om(
                json!({"time": t, "temperature_2m": [1, 2, 3]}),
                json!({"temperature_2m": "°C"}),
            ),
            "forecast.data.hourly",
            "no wind",
        ),
        (
            "open_meteo",
            om(
                json!({"time": ["2026-12-03T00:00", "2026-12-03T02:00", "2026-12-03T01:00"], "wind_speed_10m": [1, 2, 3]}),
                json!({"wind_speed_10m": "m/s"}),
            ),
            "forecast.data.hourly.time[2]",
            "increase",
        ),
        (
            "open_meteo",
            om(
                json!({"time": t, "wind_speed_10m": [1, "x", 3]}),
                json!({"wind_speed_10m": "m/s"}),
            ),
            "forecast.data.hourly.wind_speed_10m[1]",
            "number",
        ),
        (
            "open_meteo",
            om(
                json!({"time": t, "wind_speed_10m": [1, 2]}),
                json!({"wind_speed_10m": "m/s"}),
            ),
            "forecast.data.hourly.wind_speed_10m",
            "2 values for 3 times",
        ),
        (
            "open_meteo",
            om(
                json!({"time": t, "wind_speed_10m": [null, null, null]}),
                json!({"wind_speed_10m": "m/s"}),
            ),
            "forecast.data",
            "no wind",
        ),
        (
            "csv",
            json!("when,where\n"),
            "forecast.data line 1",
            "header",
        ),
        (
            "csv",
            json!("time,height_m,speed_m_s,gust_m_s\n2026-12-03T00:00,10,abc,\n"),
            "forecast.data line 2",
            "speed_m_s `abc` is not a number",
        ),
        (
            "csv",
            json!(
                "time,height_m,speed_m_s,gust_m_s\n2026-12-03T01:00,10,3,\n\n2026-12-03T00:00,10,4,\n"
            ),
            "forecast.data line 4",
            "time order",
        ),
        (
            "csv",
            json!("time,height_m,speed_m_s,gust_m_s\n"),
            "forecast.data",
            "no wind",
        ),
        ("csv", json!({"rows": []}), "forecast.data", "JSON string"),
        ("metar", json!("HELLO"), "forecast.data", "METAR"),
        (
            "metar",
            json!("METAR EDDB 031250Z CAVOK 08/02 Q1012"),
            "forecast.data",
            "no wind",
        ),
        (
            "taf",
            json!("TAF EDDB 031100Z 0312/0412 9999 SCT030"),
            "forecast.data",
            "no wind",
        ),
        // An FM group whose wind cannot be read (a speed of three digits
        // and a two-digit gust field run together) would leave its hours
        // unjudged: refused, naming the group.
        (
            "taf",
            json!("TAF EDDB 031100Z 0312/0412 24010KT 9999 FM031500 99999KT 9999 BKN010"),
            "forecast.data",
            "TAF group 2 (fm, from 031500Z) has no wind group",
        ),
    ];
    for (format, data, field, words) in cases {
        let (f, m) = refused(&windows_request(format, data.clone())).await;
        assert_eq!(f, field, "{format} {data}: {m}");
        assert!(m.contains(words), "{format} {data}: {m}");
    }
    // The request's own fields.
    let mut b = windows_request(
        "csv",
        json!("time,height_m,speed_m_s\n2026-12-03T00:00,10,3\n"),
    );
    b["forecast"]["format"] = json!("grib");
    assert_eq!(refused(&b).await.0, "forecast.format");
    let mut b = windows_request(
        "csv",
        json!("time,height_m,speed_m_s\n2026-12-03T00:00,10,3\n"),
    );
    b["operation_s"] = json!(-1.0);
    assert_eq!(refused(&b).await.0, "operation_s");
    let mut b = windows_request(
        "csv",
        json!("time,height_m,speed_m_s\n2026-12-03T00:00,10,3\n"),
    );
    b["wind"] = json!({"flow": {"kind": "uniform", "speed_m_s": 3.0}});
    assert_eq!(refused(&b).await.0, "wind.flow");
    // A wind the plan refuses names the period.
    let (f, m) = refused(&windows_request(
        "csv",
        json!("time,height_m,speed_m_s\n2026-12-03T00:00,10,3\n2026-12-03T01:00,10,400\n"),
    ))
    .await;
    assert!(f.starts_with("wind.flow"), "{f}: {m}");
    assert!(m.contains("2026-12-03T01:00"), "{m}");
}

#[tokio::test]
async fn the_documented_example_succeeds_as_is() {
    let doc: Value = serde_json::from_str(&tetherplan::api::openapi::openapi_json()).unwrap();
    let body = doc["components"]["schemas"]["WindowsRequest"]["example"].clone();
    let (s, r) = post("/api/v1/windows", &body).await;
    assert_eq!(s, StatusCode::OK, "{r}");
    let hours = r["hours"].as_array().unwrap();
    assert_eq!(hours.len(), 4);
    assert_eq!(hours[3]["verdict"], "no-go", "{}", hours[3]["reason"]);
    assert_eq!(r["windows"][0]["start"], "2026-12-03T08:00");
}
