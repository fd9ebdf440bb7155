//! Raw HTTP/1.1 to a real `tetherplan serve` process, as the full-stack
//! tests speak it: start the server on port 0 and read the address it
//! prints, send one request over a fresh connection (`Connection: close`),
//! and parse the reply (chunked bodies decoded).

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::process::{Child, Command, Stdio};
use std::time::Duration;

use serde_json::Value;

/// Spawns `cmd` (a `serve --addr 127.0.0.1:0` command; stdin closed, stdout
/// piped) and reads the address from its first line.
pub fn spawn_listening(cmd: &mut Command) -> (Child, SocketAddr) {
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .spawn()
        .expect("the server starts");
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let addr = line
        .trim()
        .strip_prefix("tetherplan listening on http://")
        .unwrap_or_else(|| panic!("unexpected first line {line:?}"))
        .parse()
        .unwrap();
    (child, addr)
}

/// A connection to `addr` whose reads time out after `timeout`.
pub fn connect(addr: SocketAddr, timeout: Duration) -> TcpStream {
    let s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(timeout)).unwrap();
    s
}

/// `GET /healthz` over a fresh connection, each step within `timeout`:
/// `Ok` for a 200, otherwise what went wrong and when (for the test's
/// message).
pub fn probe_healthz(addr: SocketAddr, timeout: Duration) -> Result<(), String> {
    let start = std::time::Instant::now();
    let at = |what: String| format!("{what} after {:?}", start.elapsed());
    let mut s = TcpStream::connect_timeout(&addr, timeout)
        .map_err(|e| at(format!("connect failed ({e})")))?;
    s.set_read_timeout(Some(timeout)).unwrap();
    s.set_write_timeout(Some(timeout)).unwrap();
    let req = format!("GET /healthz HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n");
    s.write_all(req.as_bytes())
        .map_err(|e| at(format!("write failed ({e})")))?;
    let mut raw = Vec::new();
    let read = s.read_to_end(&mut raw);
    if raw.starts_with(b"HTTP/1.1 200") {
        return Ok(());
    }
    let first = String::from_utf8_lossy(&raw[..raw.len().min(40)]).into_owned();
    Err(at(format!("reply {first:?} ({read:?})")))
}

/// Sends `method path` with `body` (and `content_type` when given) over
/// `s`, then reads the reply to the end.
pub fn exchange(
    mut s: TcpStream,
    method: &str,
    path: &str,
    host: &str,
    content_type: Option<&str>,
    body: &[u8],
) -> Reply {
    let mut head = format!(
        "{method} {path} HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\nContent-Length: {}\r\n",
        body.len()
    );
    if let Some(ct) = content_type {
        head.push_str(&format!("Content-Type: {ct}\r\n"));
    }
    head.push_str("\r\n");
    s.write_all(head.as_bytes()).unwrap();
    // The server may answer (413) before reading the whole body.
    let _ = s.write_all(body);
    let mut raw = Vec::new();
    s.read_to_end(&mut raw).unwrap();
    Reply::parse(&raw)
}

/// A reply: status, headers (names in lower case) and body text.
pub struct Reply {
    pub status: u16,
    pub headers: Vec<(String, String)>,
    pub body: String,
}

impl Reply {
    /// Parses a whole response (a panic showing it when it is incomplete).
    pub fn parse(raw: &[u8]) -> Self {
        let split = raw
            .windows(4)
            .position(|w| w == b"\r\n\r\n")
            .unwrap_or_else(|| panic!("a complete response: {:?}", String::from_utf8_lossy(raw)));
        let head = String::from_utf8_lossy(&raw[..split]).into_owned();
        let mut lines = head.split("\r\n");
        let status = lines
            .next()
            .unwrap()
            .split(' ')
            .nth(1)
            .unwrap()
            .parse()
            .unwrap();
        let headers: Vec<(String, String)> = lines
            .filter_map(|l| l.split_once(':'))
            .map(|(k, v)| (k.trim().to_ascii_lowercase(), v.trim().to_string()))
            .collect();
        let mut body = raw[split + 4..].to_vec();
        if headers
            .iter()
            .any(|(k, v)| k == "transfer-encoding" && v.contains("chunked"))
        {
            body = dechunk(&body);
        }
        Self {
            status,
            headers,
            body: String::from_utf8_lossy(&body).into_owned(),
        }
    }

    /// The value of header `name` (lower case), if present.
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }

    /// The body as JSON (a panic showing it when it is not JSON).
    pub fn json(&self) -> Value {
        serde_json::from_str(&self.body).unwrap_or_else(|e| panic!("not JSON ({e}): {}", self.body))
    }
}

/// The body of a `Transfer-Encoding: chunked` message, decoded.
pub fn dechunk(mut b: &[u8]) -> Vec<u8> {
    let mut out = vec![];
    loop {
        let eol = b.windows(2).position(|w| w == b"\r\n").unwrap();
        let size =
            usize::from_str_radix(std::str::from_utf8(&b[..eol]).unwrap().trim(), 16).unwrap();
        if size == 0 {
            return out;
        }
        out.extend_from_slice(&b[eol + 2..eol + 2 + size]);
        b = &b[eol + 4 + size..];
    }
}

/// A one-answer HTTP server on a loopback port, for the life of the test
/// process: every request (its head read, its body ignored) gets `status`
/// with `body` as JSON, then the connection closes. Its address.
pub fn serve_fixed(status: u16, body: Vec<u8>) -> SocketAddr {
    let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap();
    std::thread::spawn(move || {
        for stream in listener.incoming() {
            let Ok(mut s) = stream else { continue };
            let mut r = BufReader::new(s.try_clone().unwrap());
            let mut line = String::new();
            while r.read_line(&mut line).is_ok_and(|n| n > 0) && line != "\r\n" {
                line.clear();
            }
            let head = format!(
                "HTTP/1.1 {status} X\r\nContent-Type: application/json\r\nContent-Length: {}\r\nConnection: close\r\n\r\n",
                body.len()
            );
            let _ = s.write_all(head.as_bytes());
            let _ = s.write_all(&body);
        }
    });
    addr
}

/// The recorded Open-Meteo forecast (`tests/forecasts/open_meteo_hourly.json`)
/// served by [`serve_fixed`]; its URL.
pub fn serve_recorded_forecast() -> String {
    let body = std::fs::read(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/forecasts/open_meteo_hourly.json"
    ))
    .unwrap();
    let addr = serve_fixed(200, body);
    format!("http://{addr}/v1/forecast?latitude=52.52&longitude=13.41")
}

/// A `tetherplan serve --addr 127.0.0.1:0` process with `args`, killed
/// (SIGKILL) when dropped: the full-stack flight tests' server. One job
/// thread, warnings logged; the environment's store, token, MQTT and
/// forecast settings are cleared, so only `args` count.
pub struct ServeProcess {
    pub child: Child,
    pub addr: SocketAddr,
}

impl ServeProcess {
    pub fn start<S: AsRef<std::ffi::OsStr>>(args: impl IntoIterator<Item = S>) -> Self {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_tetherplan"));
        cmd.args(["serve", "--addr", "127.0.0.1:0"])
            .args(args)
            .env("RUST_LOG", "warn")
            .env("TETHERPLAN_JOB_THREADS", "1")
            .stderr(Stdio::inherit());
        for var in [
            "TETHERPLAN_API_TOKENS",
            "TETHERPLAN_DATABASE_URL",
            "TETHERPLAN_DB",
            "TETHERPLAN_MQTT_URL",
            "TETHERPLAN_MQTT_TOPIC_PREFIX",
            "TETHERPLAN_FORECAST_URL",
        ] {
            cmd.env_remove(var);
        }
        let (child, addr) = spawn_listening(&mut cmd);
        Self { child, addr }
    }

    /// `method path` with `body` of content type `ct`: the status and the
    /// answer as JSON (`Null` when it is not JSON).
    pub fn send(&self, method: &str, path: &str, ct: &str, body: &[u8]) -> (u16, Value) {
        let s = connect(self.addr, Duration::from_secs(60));
        let r = exchange(s, method, path, &self.addr.to_string(), Some(ct), body);
        (
            r.status,
            serde_json::from_str(&r.body).unwrap_or(Value::Null),
        )
    }

    /// [`Self::send`] with a JSON body (`Null`: none).
    pub fn send_json(&self, method: &str, path: &str, body: &Value) -> (u16, Value) {
        let bytes = if body.is_null() {
            Vec::new()
        } else {
            body.to_string().into_bytes()
        };
        self.send(method, path, "application/json", &bytes)
    }

    /// SIGKILL, and the exit reaped.
    pub fn kill(&mut self) {
        self.child.kill().unwrap();
        self.child.wait().unwrap();
    }
}

impl Drop for ServeProcess {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}
