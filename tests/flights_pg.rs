//! Live flights kept in PostgreSQL (issue 33, item 1: "SQLite by default,
//! PostgreSQL for workers"):
//!
//! * the PostgreSQL flight store answers every operation exactly as the
//!   SQLite one does, on the same sequence of operations (duplicates
//!   within a batch and across batches, samples out of order, arrival
//!   numbers, acknowledgements, another owner, ending);
//! * two API processes on one database serve the same flight: the one fed
//!   is killed with SIGKILL, the other answers the same state, alarms and
//!   samples, and goes on from there without storing anything twice.
//!
//! Each test uses a database of its own (`common::pg`); without PostgreSQL
//! they skip, unless `CI` is set.

use serde_json::{Value, json};
use tetherplan::jobs::flights::{FlightStore, NewFlight};
use tetherplan::jobs::flights_sqlite::SqliteFlights;
use tetherplan::jobs::postgres::PgStore;
use tetherplan::numerics::monitor::Sample;

mod common;
use common::flights::{batch, comparable};
use common::http::ServeProcess;
use common::pg::TestDb;

fn sample(t: f64, tension: f64) -> Sample {
    Sample {
        time_s: t,
        tether_length_m: Some(100.0 + t),
        winch_rate_m_s: Some(1.0),
        winch_tension_n: Some(tension),
        wind_speed_m_s: if t > 1.0 { Some(5.5) } else { None },
        wind_height_m: None,
        aerostat_altitude_m: Some(90.0 + t),
    }
}

/// Everything a store answers to one scripted sequence, as text.
fn script(store: &dyn FlightStore) -> Vec<String> {
    let mut out = Vec::new();
    let new = NewFlight {
        name: "morning",
        request: r#"{"a":1}"#,
        plan: r#"{"p":2}"#,
        limits: r#"{"l":3}"#,
        ceiling: r#"{"c":4}"#,
    };
    let a = store.create_flight("owner-a", &new).unwrap().unwrap();
    let b = store.create_flight("owner-b", &new).unwrap().unwrap();
    out.push(format!("ids differ {}", a != b));
    // a batch with a duplicate inside it, then one overlapping it, out of order
    let first: Vec<Sample> = [0.0, 0.1, 0.2, 0.1, 0.3]
        .iter()
        .map(|&t| sample(t, 1000.0 + t))
        .collect();
    let r = store.insert_samples(a, &first, 1_000).unwrap();
    out.push(format!("{r:?}"));
    let second: Vec<Sample> = [0.5, 0.2, 0.4, -0.0, 1.5]
        .iter()
        .map(|&t| sample(t, 2000.0 + t))
        .collect();
    let r = store.insert_samples(a, &second, 2_000).unwrap();
    out.push(format!("{r:?}"));
    let r = store.insert_samples(a, &[], 3_000).unwrap();
    out.push(format!("{r:?}"));
    out.push(format!("{:?}", store.samples_by_time(a).unwrap()));
    out.push(format!("{:?}", store.samples_after(a, 0, 3).unwrap()));
    out.push(format!("{:?}", store.samples_after(a, 4, 100).unwrap()));
    out.push(format!("{:?}", store.samples_by_time(b).unwrap()));
    store.add_acknowledgement(a, 0.3).unwrap();
    store.add_acknowledgement(a, 0.25).unwrap();
    out.push(format!("{:?}", store.acknowledgements(a).unwrap()));
    out.push(format!("{:?}", store.acknowledgements(b).unwrap()));
    let row = store.get_flight(a, "owner-a").unwrap().unwrap();
    out.push(format!(
        "{} {} {} {} {} {} {:?} {:?} {}",
        row.owner,
        row.name,
        row.request,
        row.plan,
        row.limits,
        row.ceiling,
        row.ended_at,
        row.last_arrival_ms,
        row.samples
    ));
    out.push(format!(
        "created_at has ms and Z: {}",
        row.created_at.len() == 24 && row.created_at.ends_with('Z')
    ));
    out.push(format!(
        "owners: {:?} {:?} {:?}",
        store.owner_of(a).unwrap(),
        store.owner_of(b).unwrap(),
        store.owner_of(a + b + 1).unwrap()
    ));
    out.push(format!(
        "other owner: {:?} {}",
        store.get_flight(a, "owner-b").unwrap().map(|r| r.id),
        store.end_flight(a, "owner-b").unwrap()
    ));
    out.push(format!(
        "ended: {}",
        store.end_flight(a, "owner-a").unwrap()
    ));
    let ended = store.get_flight(a, "owner-a").unwrap().unwrap().ended_at;
    out.push(format!("ended_at set: {}", ended.is_some()));
    store.end_flight(a, "owner-a").unwrap();
    out.push(format!(
        "ended_at kept: {}",
        store.get_flight(a, "owner-a").unwrap().unwrap().ended_at == ended
    ));
    let list: Vec<(String, bool)> = store
        .list_flights("owner-a")
        .unwrap()
        .into_iter()
        .map(|e| (e.name, e.ended_at.is_some()))
        .collect();
    out.push(format!("{list:?}"));
    out
}

#[test]
fn the_postgres_flight_store_answers_as_the_sqlite_one() {
    let Some(db) = TestDb::create("flight_store") else {
        return;
    };
    let pg = PgStore::open_for_flights(&db.url).unwrap();
    let sqlite = SqliteFlights::open_in_memory().unwrap();
    let from_pg = script(&pg);
    let from_sqlite = script(&sqlite);
    // the script itself: 4 of 5 stored first (0.1 twice), then 3 of 5
    // (0.2 stored, and -0.0 is the stored 0.0), arrival numbers 1..=7
    assert!(
        from_sqlite[1].contains("accepted: 4, duplicates: 1"),
        "{}",
        from_sqlite[1]
    );
    assert!(from_sqlite[1].contains("last_seq: 4"), "{}", from_sqlite[1]);
    assert!(
        from_sqlite[2].contains("accepted: 3, duplicates: 2"),
        "{}",
        from_sqlite[2]
    );
    assert!(from_sqlite[2].contains("last_seq: 7"), "{}", from_sqlite[2]);
    for (k, (p, s)) in from_pg.iter().zip(&from_sqlite).enumerate() {
        assert_eq!(p, s, "step {k} differs between PostgreSQL and SQLite");
    }
    assert_eq!(from_pg.len(), from_sqlite.len());
    // the schema is at the version that holds the flights
    let version: i32 = db
        .client()
        .query_one("SELECT max(version) FROM schema_version", &[])
        .unwrap()
        .get(0);
    assert_eq!(version, tetherplan::jobs::postgres::SCHEMA_VERSION);
    assert_eq!(version, 5);
}

#[test]
fn a_flight_fed_through_one_api_process_is_served_by_another_after_a_sigkill() {
    let Some(db) = TestDb::create("flight_failover") else {
        return;
    };
    let a = ServeProcess::start(["--database-url", db.url.as_str()]);
    let b = ServeProcess::start(["--database-url", db.url.as_str()]);
    // allowed tension 20 000 / 5 = 4000 N: caution above 3200 N, stop above 4000 N
    let (s, created) = a.send_json(
        "POST",
        "/api/v1/flights",
        &json!({
            "name": "failover",
            "cable": {"mass_per_length_kg_m": 0.078, "breaking_strength_n": 20000.0},
            "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
            "initial_length_m": 1.0,
            "target_elevation_m": 300.0,
            "winch": {"max_rate_m_s": 3.0, "max_acceleration_m_s2": 0.5},
            "lift_reserve_nondim": 0.05,
            "required_safety_factor_nondim": 5.0,
            "limits": {"max_operating_wind_m_s": 12.0, "max_gust_m_s": 18.0,
                       "stale_after_s": 3600.0}
        }),
    );
    assert_eq!(s, 201, "{created}");
    let uri = format!("/api/v1/flights/{}", created["id"]);
    let tele = format!("{uri}/telemetry");
    // a stop (4400 N for 2 s), acknowledged while still past it, then a
    // caution (3500 N) from 12 s on, left raised
    let f = |t: f64| match t {
        t if (2.0..4.0).contains(&t) => 4400.0,
        t if t >= 12.0 => 3500.0,
        _ => 1000.0,
    };
    let mut accepted = 0;
    for k in 0..8 {
        let (s, r) = a.send_json("POST", &tele, &batch(2.0 * k as f64, 20, f));
        assert_eq!(s, 200, "{r}");
        accepted += r["accepted"].as_u64().unwrap();
        if k == 1 {
            let (s, _) = a.send_json("POST", &format!("{uri}/alarms/acknowledge"), &Value::Null);
            assert_eq!(s, 200);
        }
    }
    assert_eq!(accepted, 160);
    let (_, before) = a.send_json("GET", &uri, &Value::Null);
    assert_eq!(before["state"], "caution", "{before}");
    assert_eq!(before["samples_received"], 160);
    let stop = before["alarms"]
        .as_array()
        .unwrap()
        .iter()
        .find(|x| x["level"] == "stop")
        .expect("the stop was raised");
    assert!(stop["acknowledged_at_s"].is_number(), "{stop}");
    drop(a); // SIGKILL
    let (s, after) = b.send_json("GET", &uri, &Value::Null);
    assert_eq!(s, 200, "{after}");
    assert_eq!(comparable(after), comparable(before));
    // the other process goes on: the last batch again stores nothing
    let (s, r) = b.send_json("POST", &tele, &batch(14.0, 20, f));
    assert_eq!(s, 200, "{r}");
    assert_eq!(
        (r["accepted"].as_u64(), r["duplicates"].as_u64()),
        (Some(0), Some(20))
    );
    // and new samples clear the caution after the 5 s dwell below 0.9 × 3200 N
    let (s, r) = b.send_json("POST", &tele, &batch(16.0, 70, |_| 1000.0));
    assert_eq!(s, 200, "{r}");
    assert_eq!(r["accepted"], 70);
    let (_, now) = b.send_json("GET", &uri, &Value::Null);
    assert_eq!(now["state"], "normal", "{now}");
    assert_eq!(now["samples_received"], 230);
    // arrival numbers stayed contiguous across the two processes
    let seqs: Vec<i64> = db
        .client()
        .query(
            "SELECT seq FROM flight_samples WHERE flight_id = $1 ORDER BY seq",
            &[&created["id"].as_i64().unwrap()],
        )
        .unwrap()
        .iter()
        .map(|r| r.get(0))
        .collect();
    assert_eq!(seqs, (1..=230).collect::<Vec<i64>>());
}
