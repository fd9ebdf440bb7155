//! Settings of `tetherplan serve`: bind address, database, static files and
//! the limits that keep the server responsive. Each is a flag with an
//! environment fallback (`TETHERPLAN_*`), so the same binary runs from a
//! shell, a test harness or a container.

use std::net::SocketAddr;
use std::path::PathBuf;
use std::time::Duration;

pub use crate::jobs::store::StoreConfig;
pub use crate::jobs::worker::WorkerConfig;
pub use crate::limits::{ConnectionLimits, Limits};

/// `tetherplan serve` flags.
#[derive(Clone, Debug, clap::Args)]
pub struct ServeArgs {
    /// Address to listen on (`host:port`; port 0 picks a free one).
    #[arg(long, env = "TETHERPLAN_ADDR", default_value = "127.0.0.1:8080")]
    pub addr: SocketAddr,
    /// SQLite database of batch jobs (created if missing; WAL mode).
    #[arg(long, env = "TETHERPLAN_DB", default_value = "./tetherplan.db")]
    pub db: PathBuf,
    /// PostgreSQL job store shared by API and worker processes
    /// (`postgres://user:password@host:5432/db`); replaces `--db`.
    #[arg(long, env = "TETHERPLAN_DATABASE_URL", hide_env_values = true)]
    pub database_url: Option<String>,
    /// Directory served at `GET /` instead of the chart page built into the binary.
    #[arg(long, env = "TETHERPLAN_STATIC_DIR")]
    pub static_dir: Option<PathBuf>,
    /// Largest request body (bytes); larger bodies get 413.
    #[arg(long, env = "TETHERPLAN_MAX_BODY_BYTES", default_value_t = Limits::default().max_body_bytes)]
    pub max_body_bytes: usize,
    /// Synchronous solves running or waiting at once; beyond: 503 with Retry-After.
    #[arg(long, env = "TETHERPLAN_MAX_IN_FLIGHT", default_value_t = Limits::default().max_in_flight)]
    pub max_in_flight: usize,
    /// Seconds a synchronous request waits for its answer; beyond: 504.
    #[arg(long, env = "TETHERPLAN_SOLVE_TIMEOUT_S", default_value_t = Limits::default().solve_timeout.as_secs_f64())]
    pub solve_timeout_s: f64,
    /// Jobs queued or running at once; beyond: 429 with Retry-After.
    #[arg(long, env = "TETHERPLAN_MAX_PENDING_JOBS", default_value_t = Limits::default().max_pending_jobs)]
    pub max_pending_jobs: usize,
    /// Threads of the job pool (default: one per core; 0: this process runs
    /// no jobs, leaving them to `tetherplan worker` processes).
    #[arg(long, env = "TETHERPLAN_JOB_THREADS")]
    pub job_threads: Option<usize>,
    /// Host names requests may address besides loopback and the bind
    /// address (comma-separated; `*`: any). Others get 421.
    #[arg(long, env = "TETHERPLAN_ALLOWED_HOSTS")]
    pub allowed_hosts: Option<String>,
    /// Connections open at once (clamped below the file limit); past it the
    /// oldest connection is closed.
    #[arg(long, env = "TETHERPLAN_MAX_CONNECTIONS", default_value_t = ConnectionLimits::default().max_connections)]
    pub max_connections: usize,
    /// Seconds a client has to send a request head (also the keep-alive idle time).
    #[arg(long, env = "TETHERPLAN_HEADER_TIMEOUT_S", default_value_t = ConnectionLimits::default().header_timeout.as_secs_f64())]
    pub header_timeout_s: f64,
    /// Seconds allowed between two pieces of a request body.
    #[arg(long, env = "TETHERPLAN_BODY_TIMEOUT_S", default_value_t = ConnectionLimits::default().body_timeout.as_secs_f64())]
    pub body_timeout_s: f64,
    /// Seconds a whole request body may take to arrive (however it trickles).
    #[arg(long, env = "TETHERPLAN_BODY_DEADLINE_S", default_value_t = ConnectionLimits::default().body_deadline.as_secs_f64())]
    pub body_deadline_s: f64,
    /// Seconds a whole answer may take to be written (a client that does not read is dropped).
    #[arg(long, env = "TETHERPLAN_WRITE_DEADLINE_S", default_value_t = ConnectionLimits::default().write_deadline.as_secs_f64())]
    pub write_deadline_s: f64,
    /// Request-body bytes held at once over all connections; past it new
    /// bodies are refused (503) until earlier requests finish.
    #[arg(long, env = "TETHERPLAN_BODY_BUDGET_BYTES", default_value_t = ConnectionLimits::default().body_budget_bytes)]
    pub body_budget_bytes: usize,
    #[command(flatten)]
    pub jobs: JobArgs,
    #[command(flatten)]
    pub mqtt: MqttArgs,
    #[command(flatten)]
    pub forecast: ForecastArgs,
}

/// Where `GET /api/v1/forecast` fetches today's forecast (off by default:
/// the server may have no network).
#[derive(Clone, Debug, Default, clap::Args)]
pub struct ForecastArgs {
    /// URL of a forecast to fetch on request (`http://` or `https://`), e.g.
    /// an Open-Meteo hourly forecast for the site:
    /// `https://api.open-meteo.com/v1/forecast?latitude=…&longitude=…&hourly=wind_speed_10m,wind_speed_80m,wind_speed_120m,wind_speed_180m,wind_gusts_10m&wind_speed_unit=ms`.
    #[arg(long, env = "TETHERPLAN_FORECAST_URL")]
    pub forecast_url: Option<String>,
    /// The format of what that URL answers: `open_meteo`, `metar`, `taf` or `csv`.
    #[arg(long, env = "TETHERPLAN_FORECAST_FORMAT", default_value = "open_meteo")]
    pub forecast_format: String,
}

/// The MQTT telemetry feed (`tetherplan serve`; off without `--mqtt-url`).
#[derive(Clone, Debug, clap::Args)]
pub struct MqttArgs {
    /// MQTT broker to take flight telemetry from (`mqtt://host:1883`); the
    /// server subscribes to `<prefix>/+/telemetry` at QoS 1 in a persistent
    /// session, `+` a flight's id. Off by default.
    #[arg(long, env = "TETHERPLAN_MQTT_URL")]
    pub mqtt_url: Option<String>,
    /// Topic prefix of the telemetry topics.
    #[arg(
        long,
        env = "TETHERPLAN_MQTT_TOPIC_PREFIX",
        default_value = "tetherplan/flights"
    )]
    pub mqtt_topic_prefix: String,
    /// MQTT client id: the broker keeps this session's subscription and
    /// unacknowledged messages while the server is away; give every
    /// server process its own.
    #[arg(
        long,
        env = "TETHERPLAN_MQTT_CLIENT_ID",
        default_value = "tetherplan-server"
    )]
    pub mqtt_client_id: String,
}

/// The forecast source, when configured.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ForecastSource {
    pub url: String,
    pub format: crate::contract::windows::dto::ForecastFormat,
}

impl ForecastArgs {
    /// The source, `None` without a URL; an unusable URL or format is an
    /// error in plain words.
    pub fn settings(&self) -> Result<Option<ForecastSource>, String> {
        let Some(url) = self
            .forecast_url
            .as_deref()
            .map(str::trim)
            .filter(|u| !u.is_empty())
        else {
            return Ok(None);
        };
        if !(url.starts_with("http://") || url.starts_with("https://")) {
            return Err(format!(
                "--forecast-url `{url}`: must start with http:// or https://"
            ));
        }
        let format = serde_json::from_value(serde_json::Value::String(
            self.forecast_format.trim().to_string(),
        ))
        .map_err(|_| {
            format!(
                "--forecast-format `{}`: must be open_meteo, metar, taf or csv",
                self.forecast_format
            )
        })?;
        Ok(Some(ForecastSource {
            url: url.to_string(),
            format,
        }))
    }
}

/// The MQTT feed's settings, when on.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MqttSettings {
    pub host: String,
    pub port: u16,
    pub topic_prefix: String,
    pub client_id: String,
}

impl MqttArgs {
    /// The settings, `None` without a URL; an unusable URL or prefix is an
    /// error in plain words.
    pub fn settings(&self) -> Result<Option<MqttSettings>, String> {
        let Some(url) = self.mqtt_url.as_deref().filter(|u| !u.trim().is_empty()) else {
            return Ok(None);
        };
        let rest = url.trim().strip_prefix("mqtt://").ok_or_else(|| {
            format!("--mqtt-url `{url}`: must start with mqtt:// (TLS brokers are not supported)")
        })?;
        let rest = rest.trim_end_matches('/');
        let (host, port) = match rest.rsplit_once(':') {
            Some((h, p)) => (
                h,
                p.parse::<u16>()
                    .map_err(|_| format!("--mqtt-url `{url}`: the port `{p}` is not a number"))?,
            ),
            None => (rest, 1883),
        };
        if host.is_empty() || host.contains('/') || host.contains('@') {
            return Err(format!(
                "--mqtt-url `{url}`: give mqtt://host[:port], without credentials or a path"
            ));
        }
        let prefix = self.mqtt_topic_prefix.trim_matches('/');
        if prefix.is_empty() || prefix.contains(['+', '#']) {
            return Err(format!(
                "--mqtt-topic-prefix `{}`: must be a topic without wildcards (+, #)",
                self.mqtt_topic_prefix
            ));
        }
        if self.mqtt_client_id.is_empty() || self.mqtt_client_id.len() > 64 {
            return Err("--mqtt-client-id: 1 to 64 characters".into());
        }
        Ok(Some(MqttSettings {
            host: host.to_string(),
            port,
            topic_prefix: prefix.to_string(),
            client_id: self.mqtt_client_id.clone(),
        }))
    }
}

/// Job limits, leases and API tokens (`tetherplan serve`).
#[derive(Clone, Debug, clap::Args)]
pub struct JobArgs {
    /// Comma-separated bearer tokens; when set, every `/api` route needs
    /// `Authorization: Bearer <token>` and a job is visible to its own token only.
    #[arg(long, env = "TETHERPLAN_API_TOKENS", hide_env_values = true)]
    pub api_tokens: Option<String>,
    /// Jobs queued or running at once per token; beyond: 429.
    #[arg(long, env = "TETHERPLAN_TOKEN_MAX_PENDING_JOBS", default_value_t = Limits::default().max_pending_jobs_per_token)]
    pub token_max_pending_jobs: usize,
    /// Seconds a job claim lasts without a heartbeat; a dead process's job is
    /// taken over by another after this.
    #[arg(long, env = "TETHERPLAN_JOB_LEASE_S", default_value_t = Limits::default().job_lease.as_secs_f64())]
    pub job_lease_s: f64,
    /// Starts of one job (process died each time) before it is failed.
    #[arg(long, env = "TETHERPLAN_JOB_MAX_ATTEMPTS", default_value_t = Limits::default().max_job_attempts)]
    pub job_max_attempts: u32,
    /// Longest run of one job, seconds; beyond it the job fails.
    #[arg(long, env = "TETHERPLAN_JOB_MAX_RUN_S", default_value_t = Limits::default().max_job_run_time.as_secs_f64())]
    pub job_max_run_s: f64,
    /// Largest estimated answer of one job (bytes of JSON); larger: 422.
    #[arg(long, env = "TETHERPLAN_JOB_MAX_RESULT_BYTES", default_value_t = Limits::default().max_job_result_bytes)]
    pub job_max_result_bytes: u64,
    /// Seconds a finished job (and its answer) is kept; then it is deleted.
    #[arg(long, env = "TETHERPLAN_JOB_RETENTION_S", default_value_t = Limits::default().job_retention.as_secs_f64())]
    pub job_retention_s: f64,
    /// Bytes one token's jobs (requests, answers, estimated answers of
    /// pending jobs) and named systems may keep in the store; beyond: 429.
    #[arg(long, env = "TETHERPLAN_TOKEN_MAX_STORED_BYTES", default_value_t = Limits::default().max_stored_bytes_per_token)]
    pub token_max_stored_bytes: u64,
}

/// `tetherplan worker` flags: the job store and the job limits.
#[derive(Clone, Debug, clap::Args)]
pub struct WorkerArgs {
    /// SQLite database of batch jobs (shared with `serve` on this host).
    #[arg(long, env = "TETHERPLAN_DB", default_value = "./tetherplan.db")]
    pub db: PathBuf,
    /// PostgreSQL job store (`postgres://…`); replaces `--db`.
    #[arg(long, env = "TETHERPLAN_DATABASE_URL", hide_env_values = true)]
    pub database_url: Option<String>,
    /// Threads of the job pool (default and 0: one per core).
    #[arg(long, env = "TETHERPLAN_JOB_THREADS")]
    pub job_threads: Option<usize>,
    #[command(flatten)]
    pub jobs: JobArgs,
}

fn cores() -> usize {
    std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(2)
}

impl JobArgs {
    /// The limits these flags set (the others at their defaults).
    pub fn limits(&self) -> Limits {
        Limits {
            max_pending_jobs_per_token: self.token_max_pending_jobs,
            job_lease: Duration::from_secs_f64(self.job_lease_s.clamp(0.1, 86_400.0)),
            max_job_attempts: self.job_max_attempts.max(1),
            max_job_run_time: Duration::from_secs_f64(self.job_max_run_s.clamp(0.01, 1e7)),
            max_job_result_bytes: self.job_max_result_bytes,
            job_retention: Duration::from_secs_f64(self.job_retention_s.clamp(0.0, 1e10)),
            max_stored_bytes_per_token: self.token_max_stored_bytes,
            ..Limits::default()
        }
    }
}

impl From<WorkerArgs> for WorkerConfig {
    fn from(a: WorkerArgs) -> Self {
        Self {
            store: StoreConfig::new(a.db, a.database_url),
            job_threads: a.job_threads.filter(|&n| n > 0).unwrap_or_else(cores),
            limits: a.jobs.limits(),
        }
    }
}

/// Everything `serve` needs.
#[derive(Clone, Debug)]
pub struct Config {
    pub addr: SocketAddr,
    pub db: PathBuf,
    /// The job store (SQLite at `db` unless a PostgreSQL URL is given).
    pub store: StoreConfig,
    /// `None`: the page built into the binary.
    pub static_dir: Option<PathBuf>,
    /// Threads of the job pool; 0: no job worker in this process.
    pub job_threads: usize,
    pub limits: Limits,
    pub connections: ConnectionLimits,
    pub allowed_hosts: Option<String>,
    /// API tokens (empty: no authentication).
    pub api_tokens: Vec<String>,
    /// The MQTT telemetry feed, as given (checked when the server starts).
    pub mqtt: MqttArgs,
    /// The forecast source, as given (checked when the server starts).
    pub forecast: ForecastArgs,
}

impl From<ServeArgs> for Config {
    fn from(a: ServeArgs) -> Self {
        let job_threads = a.job_threads.unwrap_or_else(cores);
        Self {
            addr: a.addr,
            store: StoreConfig::new(a.db.clone(), a.database_url),
            db: a.db,
            static_dir: a.static_dir,
            job_threads,
            api_tokens: parse_tokens(a.jobs.api_tokens.as_deref()),
            limits: Limits {
                max_body_bytes: a.max_body_bytes,
                max_in_flight: a.max_in_flight,
                solve_timeout: Duration::from_secs_f64(a.solve_timeout_s.clamp(0.001, 86_400.0)),
                max_pending_jobs: a.max_pending_jobs,
                max_pending_jobs_per_token: a.jobs.token_max_pending_jobs,
                job_lease: Duration::from_secs_f64(a.jobs.job_lease_s.clamp(0.1, 86_400.0)),
                max_job_attempts: a.jobs.job_max_attempts.max(1),
                max_job_run_time: Duration::from_secs_f64(a.jobs.job_max_run_s.clamp(0.01, 1e7)),
                max_job_result_bytes: a.jobs.job_max_result_bytes,
                job_retention: Duration::from_secs_f64(a.jobs.job_retention_s.clamp(0.0, 1e10)),
                max_stored_bytes_per_token: a.jobs.token_max_stored_bytes,
                ..Limits::default()
            },
            connections: ConnectionLimits {
                header_timeout: Duration::from_secs_f64(a.header_timeout_s.clamp(0.1, 3600.0)),
                body_timeout: Duration::from_secs_f64(a.body_timeout_s.clamp(0.1, 3600.0)),
                max_connections: a.max_connections.max(1),
                body_deadline: Duration::from_secs_f64(a.body_deadline_s.clamp(0.1, 86_400.0)),
                write_deadline: Duration::from_secs_f64(a.write_deadline_s.clamp(0.1, 86_400.0)),
                max_body_bytes: a.max_body_bytes,
                body_budget_bytes: a.body_budget_bytes.max(a.max_body_bytes),
                ..ConnectionLimits::default()
            },
            allowed_hosts: a.allowed_hosts,
            mqtt: a.mqtt,
            forecast: a.forecast,
        }
    }
}

/// Tokens from `TETHERPLAN_API_TOKENS`: comma-separated, blanks trimmed,
/// empty entries ignored.
pub fn parse_tokens(s: Option<&str>) -> Vec<String> {
    s.unwrap_or("")
        .split(',')
        .map(str::trim)
        .filter(|t| !t.is_empty())
        .map(str::to_string)
        .collect()
}
