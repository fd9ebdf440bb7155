//! A simulated flight fed to a real server (issue 33): `tetherplan
//! simulate-flight` flies a deployment (50 m to 150 m in a steady 6 m/s,
//! then a 90 s hold) in the dynamics model, with and without a `1 − cos`
//! gust of +8 m/s over 20 s at t = 80 s; `tetherplan feed --speed max`
//! replays each log against a `tetherplan serve` process.
//!
//! The tension caution is put halfway between the calm flight's largest
//! tension (the deceleration at the end of the payout included) and the
//! gusty flight's (both read from the logs): the gusty flight must raise
//! the caution when the log says (1 s dwell after the first sample past
//! it) and clear it 5 s into the first run below 0.9 of it, both found
//! here by scanning the log; the calm flight raises nothing. The report's
//! peaks must equal the extremes computed here from the log (exactly: the
//! same numbers), its alarms the flight's; its CSV and HTML carry the same
//! figures. A repeated feed stores nothing twice; a bad file is refused
//! before anything is sent, naming its line.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

use serde_json::{Value, json};

mod common;
use common::http::{connect, exchange, spawn_listening};

const BIN: &str = env!("CARGO_BIN_EXE_tetherplan");

fn flight(limits: Value) -> Value {
    json!({
        "name": "simulated",
        "cable": {"preset": "dyneema", "diameter_m": 0.006},
        "aerostat": {"net_buoyancy_n": 2000.0, "mass_kg": 100.0, "drag_coefficient_nondim": 0.5,
                     "reference_area_m2": 40.0},
        "initial_length_m": 50.0,
        "target_elevation_m": 150.0,
        "winch": {"max_rate_m_s": 2.0, "max_acceleration_m_s2": 0.5},
        "wind": {"flow": {"kind": "uniform", "speed_m_s": 6.0}},
        "limits": limits
    })
}

fn base_limits() -> Value {
    json!({"max_operating_wind_m_s": 15.0, "max_gust_m_s": 40.0, "stale_after_s": 3600.0})
}

/// Runs `simulate-flight`; the log's path and its rows.
fn simulate(dir: &Path, name: &str, gust: bool) -> (PathBuf, Vec<[f64; 7]>) {
    let mut req = json!({
        "flight": flight(base_limits()),
        "sample_rate_hz": 10.0,
        "hold_s": 90.0,
        "numerics": {"segments": 20, "time_step_s": 0.05, "spectral_radius_nondim": 0.8}
    });
    if gust {
        req["wind_event"] = json!({"kind": "one_minus_cosine", "start_time_s": 80.0,
                                   "duration_s": 20.0, "amplitude_m_s": 8.0});
    }
    let input = dir.join(format!("{name}.json"));
    let output = dir.join(format!("{name}.csv"));
    std::fs::write(&input, req.to_string()).unwrap();
    let out = Command::new(BIN)
        .args(["simulate-flight", "--input"])
        .arg(&input)
        .arg("--output")
        .arg(&output)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&output).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "time_s,tether_length_m,winch_rate_m_s,winch_tension_n,wind_speed_m_s,wind_height_m,aerostat_altitude_m"
    );
    let rows: Vec<[f64; 7]> = lines
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|c| c.parse().unwrap()).collect();
            v.try_into().unwrap()
        })
        .collect();
    (output, rows)
}

struct Server {
    child: std::process::Child,
    addr: std::net::SocketAddr,
}

impl Server {
    fn start(dir: &Path) -> Self {
        let (child, addr) = spawn_listening(
            Command::new(BIN)
                .args(["serve", "--addr", "127.0.0.1:0"])
                .arg("--db")
                .arg(dir.join("flights.db"))
                .env("RUST_LOG", "warn")
                .env("TETHERPLAN_JOB_THREADS", "1")
                .env_remove("TETHERPLAN_API_TOKENS")
                .env_remove("TETHERPLAN_DATABASE_URL")
                .stderr(Stdio::inherit()),
        );
        Self { child, addr }
    }

    fn send(&self, method: &str, path: &str, ct: Option<&str>, body: &[u8]) -> (u16, String) {
        let s = connect(self.addr, Duration::from_secs(120));
        let r = exchange(s, method, path, &self.addr.to_string(), ct, body);
        (r.status, r.body)
    }

    fn get_as(&self, path: &str, accept: &str) -> (u16, String) {
        use std::io::{Read, Write};
        let mut s = connect(self.addr, Duration::from_secs(60));
        write!(
            s,
            "GET {path} HTTP/1.1\r\nHost: {}\r\nAccept: {accept}\r\nConnection: close\r\n\r\n",
            self.addr
        )
        .unwrap();
        let mut raw = Vec::new();
        s.read_to_end(&mut raw).unwrap();
        let r = common::http::Reply::parse(&raw);
        (r.status, r.body)
    }

    fn post_as(&self, path: &str, accept: &str, body: &[u8]) -> (u16, String) {
        use std::io::{Read, Write};
        let mut s = connect(self.addr, Duration::from_secs(120));
        write!(
            s,
            "POST {path} HTTP/1.1\r\nHost: {}\r\nAccept: {accept}\r\nContent-Type: application/json\r\n\
             Content-Length: {}\r\nConnection: close\r\n\r\n",
            self.addr,
            body.len()
        )
        .unwrap();
        s.write_all(body).unwrap();
        let mut raw = Vec::new();
        s.read_to_end(&mut raw).unwrap();
        let r = common::http::Reply::parse(&raw);
        (r.status, r.body)
    }

    fn create(&self, limits: Value) -> i64 {
        let (s, body) = self.send(
            "POST",
            "/api/v1/flights",
            Some("application/json"),
            flight(limits).to_string().as_bytes(),
        );
        assert_eq!(s, 201, "{body}");
        serde_json::from_str::<Value>(&body).unwrap()["id"]
            .as_i64()
            .unwrap()
    }

    fn flight(&self, id: i64) -> Value {
        let (s, body) = self.send("GET", &format!("/api/v1/flights/{id}"), None, b"");
        assert_eq!(s, 200, "{body}");
        serde_json::from_str(&body).unwrap()
    }

    fn feed(&self, id: i64, file: &Path) -> std::process::Output {
        Command::new(BIN)
            .args(["feed", "--flight", &id.to_string(), "--speed", "max"])
            .arg("--server")
            .arg(format!("http://{}", self.addr))
            .arg(file)
            .env_remove("TETHERPLAN_TOKEN")
            .output()
            .unwrap()
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// `(value, first time)` of the largest (`larger`) or smallest column `c`.
fn extreme(rows: &[[f64; 7]], c: usize, larger: bool) -> (f64, f64) {
    let mut best = (rows[0][c], rows[0][0]);
    for r in rows {
        if (larger && r[c] > best.0) || (!larger && r[c] < best.0) {
            best = (r[c], r[0]);
        }
    }
    best
}

/// The monitor's wind figures after every sample, computed directly
/// (O(n²)): the mean of the last 600 s and the largest 3 s mean of the
/// last 600 s; their largest values and first times.
fn wind_peaks(rows: &[[f64; 7]]) -> ((f64, f64), (f64, f64)) {
    let mean_over = |t: f64, span: f64| {
        let w: Vec<f64> = rows
            .iter()
            .filter(|r| r[0] > t - span && r[0] <= t)
            .map(|r| r[4])
            .collect();
        w.iter().sum::<f64>() / w.len() as f64
    };
    let shorts: Vec<f64> = rows.iter().map(|r| mean_over(r[0], 3.0)).collect();
    let (mut mean_best, mut gust_best) = ((f64::MIN, 0.0), (f64::MIN, 0.0));
    for (i, r) in rows.iter().enumerate() {
        let t = r[0];
        let mean = mean_over(t, 600.0);
        let gust = rows
            .iter()
            .zip(&shorts)
            .take(i + 1)
            .filter(|(q, _)| q[0] > t - 600.0)
            .map(|(_, s)| *s)
            .fold(f64::MIN, f64::max);
        if mean > mean_best.0 {
            mean_best = (mean, t);
        }
        if gust > gust_best.0 {
            gust_best = (gust, t);
        }
    }
    (mean_best, gust_best)
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * b.abs().max(1.0)
}

#[test]
fn a_simulated_gust_fed_to_a_server_raises_and_clears_the_caution_and_the_report_has_its_peaks() {
    let dir = std::env::temp_dir().join(format!("tetherplan-flight-feed-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let (calm_log, calm) = simulate(&dir, "calm", false);
    let (gust_log, gusty) = simulate(&dir, "gust", true);
    assert_eq!(calm.len(), gusty.len());
    let calm_max = extreme(&calm, 3, true).0;
    let peak = extreme(&gusty, 3, true).0;
    assert!(
        peak > calm_max + 150.0,
        "the gust loads the tether past anything the calm flight saw: {calm_max} → {peak} N"
    );
    let caution = calm_max + 0.5 * (peak - calm_max);

    // the expected raise and clear, scanned from the log
    let first = gusty.iter().position(|r| r[3] > caution).unwrap();
    let t_exceed = gusty[first][0];
    let raise = gusty[first..]
        .iter()
        .take_while(|r| r[3] > caution)
        .find(|r| r[0] - t_exceed >= 1.0 - 1e-6)
        .expect("above the threshold for a second")[0];
    let raised_at = gusty.iter().position(|r| r[0] == raise).unwrap();
    let mut run_start: Option<f64> = None;
    let mut clear = None;
    for r in &gusty[raised_at + 1..] {
        if r[3] < 0.9 * caution {
            let start = *run_start.get_or_insert(r[0]);
            if r[0] - start >= 5.0 - 1e-6 {
                clear = Some(r[0]);
                break;
            }
        } else {
            run_start = None;
        }
    }
    let clear = clear.expect("back below 0.9 of the threshold for 5 s");

    let server = Server::start(&dir);
    // the allowed tension is the cable's breaking strength / 5
    let probe = server.create(base_limits());
    let allowed = server.flight(probe)["limits"]["allowable_tension_n"]
        .as_f64()
        .unwrap();
    let mut limits = base_limits();
    limits["tension_caution_fraction_nondim"] = json!(caution / allowed);

    // (a) the gusty flight: one tension caution, raised and cleared
    let id = server.create(limits.clone());
    let out = server.feed(id, &gust_log);
    let summary = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(
        out.status.success(),
        "{summary}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        summary.starts_with(&format!(
            "accepted {}, duplicates 0, refused 0",
            gusty.len()
        )),
        "{summary}"
    );
    let f = server.flight(id);
    assert_eq!(f["samples_received"], gusty.len());
    let alarms = f["alarms"].as_array().unwrap();
    assert_eq!(alarms.len(), 1, "{f}");
    let a = &alarms[0];
    assert_eq!(
        (a["check"].as_str(), a["level"].as_str()),
        (Some("tension"), Some("caution"))
    );
    assert!(
        close(a["raised_at_s"].as_f64().unwrap(), raise, 1e-12),
        "{a} vs {raise}"
    );
    assert!(
        close(a["cleared_at_s"].as_f64().unwrap(), clear, 1e-12),
        "{a} vs {clear}"
    );
    eprintln!(
        "calm max {calm_max:.1} N, gust peak {peak:.1} N, caution {caution:.1} N; raised {raise} s, cleared {clear} s"
    );

    // the same flight without the gust raises nothing
    let quiet = server.create(limits.clone());
    let out = server.feed(quiet, &calm_log);
    assert!(out.status.success());
    let q = server.flight(quiet);
    assert_eq!(q["alarms"], json!([]), "{q}");
    assert_eq!(q["samples_received"], calm.len());

    // (b) the report's peaks are the log's extremes
    let (s, body) = server.send("GET", &format!("/api/v1/flights/{id}/report"), None, b"");
    assert_eq!(s, 200, "{body}");
    let r: Value = serde_json::from_str(&body).unwrap();
    let (mean, gust) = wind_peaks(&gusty);
    let expected = [
        ("max_winch_tension_n", extreme(&gusty, 3, true)),
        ("min_winch_tension_n", extreme(&gusty, 3, false)),
        ("max_payout_rate_m_s", extreme(&gusty, 2, true)),
        ("min_aerostat_altitude_m", extreme(&gusty, 6, false)),
        ("max_wind_mean_m_s", mean),
        ("max_gust_m_s", gust),
    ];
    for (name, (v, t)) in expected {
        let p = &r["peaks"][name];
        // the tension, rate and altitude are the log's numbers; the wind
        // figures are sums, compensated in the monitor, plain here
        let tol = if name.contains("wind") || name.contains("gust") {
            1e-12
        } else {
            0.0
        };
        assert!(
            close(p["value"].as_f64().unwrap(), v, tol),
            "{name}: {p} vs {v}"
        );
        assert_eq!(p["time_s"].as_f64().unwrap(), t, "{name}: {p}");
    }
    assert_eq!(r["alarms"], f["alarms"]);
    assert_eq!(r["samples_received"], gusty.len());
    let t_last = gusty[gusty.len() - 1][0];
    assert_eq!(r["duration_s"].as_f64().unwrap(), t_last - gusty[0][0]);
    let track = r["track"].as_array().unwrap();
    assert!(track.len() > 100 && track.len() <= 1000);
    // the planned length at the end is the committed schedule's last
    let planned_end = track[track.len() - 1]["planned_length_m"].as_f64().unwrap();
    let measured_end = gusty[gusty.len() - 1][1];
    assert!(
        (planned_end - measured_end).abs() < 0.05 * planned_end,
        "{planned_end} vs {measured_end}"
    );

    // the CSV and HTML answers carry the same figures
    let (s, csv) = server.get_as(&format!("/api/v1/flights/{id}/report"), "text/csv");
    assert_eq!(s, 200, "{csv}");
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "record,name,value,unit,time_s,planned_value,cleared_at_s,acknowledged_at_s"
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    for (name, _) in expected {
        let row = rows
            .iter()
            .find(|c| c[0] == "peak" && c[1] == name)
            .unwrap_or_else(|| panic!("no {name} in {csv}"));
        let p = &r["peaks"][name];
        assert_eq!(row[2].parse::<f64>().unwrap(), p["value"].as_f64().unwrap());
        assert_eq!(
            row[4].parse::<f64>().unwrap(),
            p["time_s"].as_f64().unwrap()
        );
    }
    let alarm = rows.iter().find(|c| c[0] == "alarm").unwrap();
    assert_eq!(alarm[1], "tension/caution");
    assert_eq!(
        alarm[4].parse::<f64>().unwrap(),
        a["raised_at_s"].as_f64().unwrap()
    );
    assert_eq!(
        alarm[6].parse::<f64>().unwrap(),
        a["cleared_at_s"].as_f64().unwrap()
    );
    let samples_row = rows.iter().find(|c| c[1] == "samples_received").unwrap();
    assert_eq!(samples_row[2].parse::<usize>().unwrap(), gusty.len());

    let (s, html) = server.get_as(&format!("/api/v1/flights/{id}/report"), "text/html");
    assert_eq!(s, 200);
    assert!(html.starts_with("<!DOCTYPE html>"));
    // self-contained: no script, no external resource
    assert!(!html.contains("<script") && !html.contains("src=") && !html.contains("href="));
    for (name, _) in expected {
        let v = r["peaks"][name]["value"].as_f64().unwrap();
        assert!(
            html.contains(&format!(">{v}<")),
            "{name} {v} not in the page"
        );
    }
    assert!(html.contains(&format!(">{}<", a["raised_at_s"].as_f64().unwrap())));
    assert!(html.contains(&format!(">{}<", a["cleared_at_s"].as_f64().unwrap())));
    assert!(html.contains(&format!(">{}<", gusty.len())));

    // (c) a repeated feed stores nothing twice
    let out = server.feed(id, &gust_log);
    let summary = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(out.status.success(), "{summary}");
    assert!(
        summary.starts_with(&format!(
            "accepted 0, duplicates {}, refused 0",
            gusty.len()
        )),
        "{summary}"
    );
    assert_eq!(server.flight(id)["samples_received"], gusty.len());
    assert_eq!(server.flight(id)["alarms"], f["alarms"]);

    // a bad file is refused before anything is sent, naming its line
    let text = std::fs::read_to_string(&gust_log).unwrap();
    let mut bad: Vec<String> = text.lines().map(String::from).collect();
    bad[7] = bad[7].replacen(',', ",x", 1);
    let bad_path = dir.join("bad.csv");
    std::fs::write(&bad_path, bad.join("\n")).unwrap();
    let fresh = server.create(limits);
    let out = server.feed(fresh, &bad_path);
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("line 8: tether_length_m"), "{err}");
    assert_eq!(server.flight(fresh)["samples_received"], 0);
    // an unknown flight: the server's 404, a non-zero exit
    let out = server.feed(999_999, &gust_log);
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(3), "{err}");
    assert!(
        err.contains("HTTP 404") && err.contains("no flight"),
        "{err}"
    );

    // the API answers the CLI's log byte for byte (Accept: text/csv), and
    // names this request's fields
    let req = std::fs::read(dir.join("gust.json")).unwrap();
    let (s, csv) = server.post_as("/api/v1/flights/simulate", "text/csv", &req);
    assert_eq!(s, 200, "{csv}");
    assert_eq!(csv, std::fs::read_to_string(&gust_log).unwrap());
    let mut too_fast: Value = serde_json::from_slice(&req).unwrap();
    too_fast["sample_rate_hz"] = json!(100.0);
    let (s, e) = server.post_as(
        "/api/v1/flights/simulate",
        "application/json",
        too_fast.to_string().as_bytes(),
    );
    assert_eq!(s, 422, "{e}");
    assert_eq!(
        serde_json::from_str::<Value>(&e).unwrap()["error"]["field"],
        "sample_rate_hz"
    );
    let mut no_ea: Value = serde_json::from_slice(&req).unwrap();
    no_ea["flight"]["cable"] = json!({"mass_per_length_kg_m": 0.02, "diameter_m": 0.006});
    let (s, e) = server.post_as(
        "/api/v1/flights/simulate",
        "application/json",
        no_ea.to_string().as_bytes(),
    );
    assert_eq!(s, 422, "{e}");
    assert_eq!(
        serde_json::from_str::<Value>(&e).unwrap()["error"]["field"],
        "flight.cable.axial_stiffness_n"
    );
    drop(server);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The log's batches: NMEA told by content, lines with and without a
/// time, batches of at most a second of sample time, and the server's
/// batch lines mapped back to the file's.
#[test]
fn a_log_is_cut_into_batches_that_know_their_file_lines() {
    use tetherplan::contract::flight::feed::{LogError, read_log};
    use tetherplan::contract::flight::telemetry::Format;
    let nmea = "\n0.0,$WIMWV,270.0,R,8.0,N,A*2E\n0.5,$WIMWV,270.0,R,8.0,N,A*2E\n1.2,$WIMWV,270.0,R,8.0,N,A*2E\n$WIMWV,270.0,R,8.0,N,A*2E\n";
    let log = read_log(Path::new("wind.log"), nmea).unwrap();
    assert_eq!(log.format, Format::Nmea);
    assert_eq!(
        log.lines
            .iter()
            .map(|l| (l.line, l.time_s))
            .collect::<Vec<_>>(),
        vec![(2, Some(0.0)), (3, Some(0.5)), (4, Some(1.2)), (5, None)]
    );
    let b = log.batches(100, Some(1.0));
    assert_eq!(b.len(), 2);
    assert_eq!((b[0].lines.clone(), b[0].due_s), (vec![2, 3], Some(0.5)));
    assert_eq!((b[1].lines.clone(), b[1].due_s), (vec![4, 5], Some(1.2)));
    assert_eq!(b[1].file_line(Format::Nmea, 2), Some(5));

    let csv = "time_s,tether_length_m\n0,1\n0.1,1.1\n0.2,1.2\n";
    let log = read_log(Path::new("x.txt"), csv).unwrap();
    assert_eq!(log.format, Format::Csv);
    let b = log.batches(2, None);
    assert_eq!(b.len(), 2);
    assert_eq!(b[1].body, "time_s,tether_length_m\n0.2,1.2\n");
    // the server's line 2 of the second body (its header is line 1) is the file's line 4
    assert_eq!(b[1].file_line(Format::Csv, 2), Some(4));

    match read_log(Path::new("x.csv"), "time_s,tether_length_m\n0,1\n0.1,-3\n") {
        Err(LogError::Lines(r)) => {
            assert_eq!(
                (r.len(), r[0].line, r[0].field.as_str()),
                (1, 3, "tether_length_m")
            )
        }
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        read_log(Path::new("x.csv"), "time_s,speed\n0,1\n"),
        Err(LogError::Whole(_))
    ));
}
