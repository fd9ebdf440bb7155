//! The MQTT telemetry feed against a real broker (Debian's `mosquitto`,
//! installed by `.ci/run`; without it the test skips, unless `CI` is set):
//! a real `tetherplan serve --mqtt-url …` subscribed to
//! `tetherplan/flights/+/telemetry`, and a publisher at QoS 1.
//!
//! 1. JSON and CSV messages on a flight's topic are stored as the HTTP
//!    telemetry route stores them (200 samples, each once).
//! 2. The broker is restarted without persistence, so it forgets the
//!    server's session and subscription: the server subscribes again by
//!    itself, and what is published afterwards arrives (+200).
//! 3. The server is killed with SIGKILL; what is published while it is
//!    down is kept by the broker for its persistent session and stored
//!    when it comes back (+200): nothing published at QoS 1 is lost, and
//!    nothing is stored twice (the counts are exact).

use std::io::Write;
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use rumqttc::{AsyncClient, MqttOptions, QoS};
use serde_json::{Value, json};

mod common;
use common::http::ServeProcess;

fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}

fn mosquitto_binary() -> Option<PathBuf> {
    ["/usr/sbin/mosquitto", "/usr/bin/mosquitto"]
        .iter()
        .map(PathBuf::from)
        .find(|p| p.exists())
}

/// A mosquitto on `port`, without persistence, killed when dropped.
struct Broker(Child);

impl Broker {
    fn start(bin: &Path, dir: &Path, port: u16) -> Self {
        let conf = dir.join("mosquitto.conf");
        let mut f = std::fs::File::create(&conf).unwrap();
        writeln!(
            f,
            "listener {port} 127.0.0.1\nallow_anonymous true\npersistence false"
        )
        .unwrap();
        let child = Command::new(bin)
            .arg("-c")
            .arg(&conf)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("mosquitto starts");
        let start = Instant::now();
        while std::net::TcpStream::connect(("127.0.0.1", port)).is_err() {
            assert!(
                start.elapsed() < Duration::from_secs(10),
                "mosquitto does not listen"
            );
            std::thread::sleep(Duration::from_millis(50));
        }
        Self(child)
    }
}

impl Drop for Broker {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// A `tetherplan serve` on a database file, fed from the broker.
fn start_server(dir: &Path, port: u16, client_id: &str) -> ServeProcess {
    let url = format!("mqtt://127.0.0.1:{port}");
    ServeProcess::start([
        "--db".as_ref(),
        dir.join("flights.db").as_os_str(),
        "--mqtt-url".as_ref(),
        url.as_ref(),
        "--mqtt-client-id".as_ref(),
        client_id.as_ref(),
    ])
}

/// The samples the flight at `uri` holds.
fn samples(server: &ServeProcess, uri: &str) -> u64 {
    let (s, f) = server.send_json("GET", uri, &Value::Null);
    assert_eq!(s, 200, "{f}");
    f["samples_received"].as_u64().unwrap()
}

/// Ten samples at 10 Hz from second `k`, as a JSON array.
fn json_message(k: usize) -> Vec<u8> {
    Value::Array(
        (0..10)
            .map(|j| {
                json!({"time_s": k as f64 + j as f64 / 10.0, "tether_length_m": 1.0,
                       "winch_rate_m_s": 0.0, "winch_tension_n": 1000.0 + j as f64,
                       "wind_speed_m_s": 5.0})
            })
            .collect(),
    )
    .to_string()
    .into_bytes()
}

/// The same ten samples as CSV.
fn csv_message(k: usize) -> Vec<u8> {
    let mut s = String::from("time_s,tether_length_m,winch_tension_n,wind_speed_m_s\n");
    for j in 0..10 {
        s.push_str(&format!(
            "{},1.0,{},5.0\n",
            k as f64 + j as f64 / 10.0,
            1000.0 + j as f64
        ));
    }
    s.into_bytes()
}

/// Polls until the flight holds `n` samples (and no more, ever).
fn wait_for(server: &ServeProcess, uri: &str, n: u64, within: Duration) {
    let start = Instant::now();
    loop {
        let got = samples(server, uri);
        assert!(
            got <= n,
            "{got} samples stored, more than the {n} published"
        );
        if got == n {
            return;
        }
        assert!(
            start.elapsed() < within,
            "{got} of {n} samples stored after {within:?}"
        );
        std::thread::sleep(Duration::from_millis(100));
    }
}

#[test]
fn mqtt_telemetry_survives_a_broker_restart_and_a_killed_server() {
    let Some(bin) = mosquitto_binary() else {
        if std::env::var_os("CI").is_some() {
            panic!("mosquitto is not installed and CI is set (.ci/run installs it)");
        }
        eprintln!("SKIPPED: mosquitto is not installed (apt-get install mosquitto)");
        return;
    };
    let dir = std::env::temp_dir().join(format!("tetherplan-mqtt-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let port = free_port();
    let client_id = format!("tetherplan-test-{}", std::process::id());
    let mut broker = Broker::start(&bin, &dir, port);
    let mut server = start_server(&dir, port, &client_id);
    let (s, created) = server.send_json(
        "POST",
        "/api/v1/flights",
        &json!({
            "name": "mqtt",
            "cable": {"mass_per_length_kg_m": 0.078, "breaking_strength_n": 20000.0},
            "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
            "initial_length_m": 1.0,
            "target_elevation_m": 300.0,
            "winch": {"max_rate_m_s": 3.0, "max_acceleration_m_s2": 0.5},
            "lift_reserve_nondim": 0.05,
            "required_safety_factor_nondim": 5.0,
            "limits": {"stale_after_s": 3600.0}
        }),
    );
    assert_eq!(s, 201, "{created}");
    let id = created["id"].as_i64().unwrap();
    let uri = format!("/api/v1/flights/{id}");
    let topic = format!("tetherplan/flights/{id}/telemetry");

    let rt = tokio::runtime::Runtime::new().unwrap();
    let mut options = MqttOptions::new(format!("{client_id}-publisher"), "127.0.0.1", port);
    options.set_keep_alive(Duration::from_secs(5));
    let (publisher, mut events) = AsyncClient::new(options, 1000);
    rt.spawn(async move {
        loop {
            if events.poll().await.is_err() {
                tokio::time::sleep(Duration::from_millis(200)).await;
            }
        }
    });
    let publish = |payload: Vec<u8>| {
        rt.block_on(publisher.publish(&topic, QoS::AtLeastOnce, false, payload))
            .unwrap();
    };
    // Sends second 0 until it is stored: the server's subscription is live
    // (a repeat stores nothing: the same time_s).
    let until_subscribed = |server: &ServeProcess, k: usize, stored: u64| {
        let start = Instant::now();
        while samples(server, &uri) < stored + 10 {
            assert!(
                start.elapsed() < Duration::from_secs(30),
                "the server never subscribed"
            );
            publish(json_message(k));
            std::thread::sleep(Duration::from_millis(300));
        }
    };

    // 1. JSON and CSV messages
    until_subscribed(&server, 0, 0);
    for k in 1..20 {
        let payload = if k % 2 == 0 {
            csv_message(k)
        } else {
            json_message(k)
        };
        publish(payload);
    }
    wait_for(&server, &uri, 200, Duration::from_secs(30));
    let (_, f) = server.send_json("GET", &uri, &Value::Null);
    assert_eq!(f["last_sample_time_s"], 19.9, "{f}");

    // 2. the broker restarts and forgets the subscription
    drop(broker);
    broker = Broker::start(&bin, &dir, port);
    until_subscribed(&server, 20, 200);
    for k in 21..40 {
        publish(json_message(k));
    }
    wait_for(&server, &uri, 400, Duration::from_secs(30));

    // 3. the server is killed; the broker keeps its session's messages
    server.kill();
    for k in 40..60 {
        publish(json_message(k));
    }
    // the broker has them all (the publisher's QoS 1 acknowledgements)
    std::thread::sleep(Duration::from_millis(500));
    server = start_server(&dir, port, &client_id);
    wait_for(&server, &uri, 600, Duration::from_secs(30));
    let (_, f) = server.send_json("GET", &uri, &Value::Null);
    assert_eq!(f["last_sample_time_s"], 59.9, "{f}");
    assert_eq!(f["state"], "normal", "{f}");
    drop(broker);
}
