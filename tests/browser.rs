//! Browser tests of the page. Each starts `tetherplan serve` on a free
//! loopback port with a fresh database and the repository's `static/`, then
//! runs a script under `tests/browser/` (playwright-core driving Debian's
//! Chromium) against it; screenshots go to `tests/artifacts/`.
//!
//! * `chart_page.mjs` submits the default chart form, checks the plotted
//!   curves, an error rendered next to its field and the console.
//! * `plan_page.mjs` types the issue-20 scenario into the system card and the
//!   plan (inputs named by their request paths): 1000 m in a uniform 6 m/s
//!   wind is NO-GO naming the wind, 900 m is GO with the tether length
//!   shown; an edit turns `#verdict` stale at once with Print disabled, a
//!   negative buoyancy turns it to `error` beside its field; a shared URL
//!   plans at once with the same verdict; the card's values reach the
//!   envelope's request; the verdict is above the fold at 1440×900, 390×844
//!   and in print.
//! * `transient_page.mjs` runs the default transient (thesis Fig 4.5) and
//!   checks the resonance in the plotted envelope, runs a small frequency
//!   response directly and a larger one as a job, checks API errors next to
//!   their fields, the phone layout and the console.
//! * `envelope_page.mjs` enters a system in the card and runs the
//!   operating-envelope panel's default grid with it, checks
//!   the feasible region's outline, the region labels, CSV/PNG export with
//!   the inputs, a job with progress, and screenshots the page at 1280×800
//!   and 390×844.
//! * `dynamics_page.mjs` opens a shared URL with a 1 − cos gust case: the
//!   panel runs at once; the peak winch tension shown is the API's, the
//!   tension and altitude plots are drawn, the shape animation advances and
//!   pauses; the peak distribution of 6 seeds is drawn with the gust check;
//!   an invalid gust duration shows the API's error beside its field.
//! * `windows_page.mjs` drops the Open-Meteo file of `tests/forecasts/` on the
//!   launch-windows panel: the day's timeline; a NO-GO hour turns the plan NO-GO.
//! * `docs_page.mjs` runs every POST operation's "Try it out" in `/docs`
//!   with the document's example (each must answer 2xx) under the CSP.
//! * `windows_fetch_page.mjs` runs on a server given `--forecast-url` (the
//!   recorded Open-Meteo file served by a thread here): "Fetch today's
//!   forecast" fills the file's JSON and shows its day.
//! * `live_page.mjs` starts a flight from the page and replays a log by
//!   posting telemetry itself: the stoplight reads normal, caution, stop (the
//!   flight's own thresholds), stays stop until Acknowledge, unavailable
//!   after 2 s of silence; each sample held once; the re-plan; units in
//!   knots and feet by exact factors kept in the URL; phone and print.
//! * `live_token_page.mjs` runs the live panel on a server with API tokens
//!   (`TETHERPLAN_API_TOKENS`): the page asks for the token once, the events
//!   are read with fetch (EventSource cannot send it), a dropped stream
//!   reconnects with Last-Event-ID without a sample twice.
//! * `panels_page.mjs` checks the page's panels as units: each panel's
//!   system-card declaration gets exactly the paths it lists from the card's
//!   reader; the frequency-response panel sweeps with `transient.js` absent;
//!   the panels' script tags in reverse order still plan GO.
//!
//! The two run one after the other (a lock), not side by side on 2 cores.
//!
//! Needs `/usr/bin/chromium` (or `$CHROMIUM`), `node`, and
//! `npm ci --prefix tests/browser`. When one is missing the test fails if
//! `CI` is set, and otherwise prints `skipped: …` and passes.

use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

mod common;

/// The server process, killed when the test ends (also on panic).
struct Server {
    child: Child,
    dir: PathBuf,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// What the test needs and does not find, if anything.
fn missing_prerequisite(chromium: &Path) -> Option<String> {
    if !chromium.exists() {
        return Some(format!(
            "{} not found (apt-get install -y chromium, or set CHROMIUM)",
            chromium.display()
        ));
    }
    if Command::new("node")
        .arg("--version")
        .output()
        .map(|o| !o.status.success())
        .unwrap_or(true)
    {
        return Some("node not found on PATH".into());
    }
    if !repo()
        .join("tests/browser/node_modules/playwright-core")
        .is_dir()
    {
        return Some("tests/browser/node_modules missing (npm ci --prefix tests/browser)".into());
    }
    None
}

fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .expect("a free loopback port")
        .port()
}

/// True once `GET /healthz` answers 200.
fn healthy(port: u16) -> bool {
    let Ok(mut stream) =
        TcpStream::connect_timeout(&([127, 0, 0, 1], port).into(), Duration::from_millis(200))
    else {
        return false;
    };
    let _ = stream.set_read_timeout(Some(Duration::from_secs(2)));
    let request =
        format!("GET /healthz HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nConnection: close\r\n\r\n");
    if stream.write_all(request.as_bytes()).is_err() {
        return false;
    }
    let mut response = String::new();
    let _ = stream.read_to_string(&mut response);
    response.starts_with("HTTP/1.1 200")
}

fn start_server(label: &str, envs: &[(&str, &str)]) -> (Server, String) {
    let stamp = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_nanos())
        .unwrap_or(0);
    let dir = std::env::temp_dir().join(format!(
        "tetherplan-browser-{label}-{}-{stamp}",
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).expect("temporary directory");
    let log = std::fs::File::create(dir.join("server.log")).expect("server log file");
    let port = free_port();
    let child = Command::new(env!("CARGO_BIN_EXE_tetherplan"))
        .arg("serve")
        .args(["--addr", &format!("127.0.0.1:{port}")])
        .arg("--db")
        .arg(dir.join("jobs.db"))
        .arg("--static-dir")
        .arg(repo().join("static"))
        .envs(envs.iter().copied())
        .stdout(log.try_clone().expect("log handle"))
        .stderr(log)
        .spawn()
        .expect("start tetherplan serve");
    let mut server = Server { child, dir };
    let deadline = Instant::now() + Duration::from_secs(30);
    while !healthy(port) {
        if let Ok(Some(status)) = server.child.try_wait() {
            panic!(
                "tetherplan serve exited with {status}:\n{}",
                server_log(&server)
            );
        }
        assert!(
            Instant::now() < deadline,
            "server not healthy after 30 s:\n{}",
            server_log(&server)
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    (server, format!("http://127.0.0.1:{port}/"))
}

fn server_log(server: &Server) -> String {
    std::fs::read_to_string(server.dir.join("server.log")).unwrap_or_default()
}

/// Serialises the browser tests.
static ONE_BROWSER_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Runs `tests/browser/<script>` against a fresh server; skips (or, with
/// `CI` set, fails) when a prerequisite is missing.
fn run_page_script(script: &str) {
    run_page_script_with(script, &[]);
}

/// The same with environment variables for the server and the script.
fn run_page_script_with(script: &str, envs: &[(&str, &str)]) {
    let _turn = ONE_BROWSER_AT_A_TIME
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    let chromium = std::env::var_os("CHROMIUM")
        .map(PathBuf::from)
        .unwrap_or_else(|| "/usr/bin/chromium".into());
    if let Some(what) = missing_prerequisite(&chromium) {
        if std::env::var_os("CI").is_some() {
            panic!("browser test {script} cannot run in CI: {what}");
        }
        // Straight to stderr: libtest would swallow println! of a passing test.
        let _ = writeln!(
            std::io::stderr(),
            "skipped: browser test {script}: {what} (set CI to make this a failure)"
        );
        return;
    }
    let (server, url) = start_server(script.trim_end_matches(".mjs"), envs);
    let status = Command::new("node")
        .arg(repo().join("tests/browser").join(script))
        .arg(&url)
        .env("CHROMIUM", &chromium)
        .envs(envs.iter().copied())
        .stdin(Stdio::null())
        .status()
        .expect("run node");
    assert!(
        status.success(),
        "browser checks of {script} failed ({status}); screenshots in tests/artifacts/; server log:\n{}",
        server_log(&server)
    );
}

#[test]
fn chart_page_in_headless_chromium() {
    run_page_script("chart_page.mjs");
}

#[test]
fn transient_page_in_headless_chromium() {
    run_page_script("transient_page.mjs");
}

#[test]
fn docs_try_it_out_in_headless_chromium() {
    run_page_script("docs_page.mjs");
}

#[test]
fn plan_page_in_headless_chromium() {
    run_page_script("plan_page.mjs");
}

#[test]
fn bands_page_in_headless_chromium() {
    run_page_script("bands_page.mjs");
}

#[test]
fn envelope_page_in_headless_chromium() {
    run_page_script("envelope_page.mjs");
}

#[test]
fn dynamics_page_in_headless_chromium() {
    run_page_script("dynamics_page.mjs");
}

#[test]
fn windows_page_in_headless_chromium() {
    run_page_script("windows_page.mjs");
}

#[test]
fn panels_page_in_headless_chromium() {
    run_page_script("panels_page.mjs");
}

#[test]
fn windows_fetched_forecast_in_headless_chromium() {
    let source = common::http::serve_recorded_forecast();
    run_page_script_with(
        "windows_fetch_page.mjs",
        &[("TETHERPLAN_FORECAST_URL", source.as_str())],
    );
}

#[test]
fn live_page_in_headless_chromium() {
    run_page_script("live_page.mjs");
}

#[test]
fn live_page_with_api_tokens_in_headless_chromium() {
    run_page_script_with(
        "live_token_page.mjs",
        &[("TETHERPLAN_API_TOKENS", "browser-test-token")],
    );
}
