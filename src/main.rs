//! The `tetherplan` binary: `serve` (the default with no subcommand) runs
//! the HTTP service, `worker` runs jobs; the other subcommands, one per
//! analysis kind of the catalogue, answer one request over the JSON
//! contract: each reads a request (file or stdin), prints the JSON answer
//! on stdout (a progress bar on stderr), and on bad input prints the error
//! body and exits with status 2.

use std::io::Read;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, CommandFactory, FromArgMatches, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;
use tetherplan::config::ServeArgs;
use tetherplan::contract::catalogue::{KINDS, Kind};
use tetherplan::contract::{self, Progress, RequestError, dto};

#[derive(Parser)]
#[command(
    name = "tetherplan",
    version,
    about = "Deployment planning for tethered aerostats"
)]
#[command(args_conflicts_with_subcommands = true)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// `serve` flags, also accepted without the subcommand.
    #[command(flatten)]
    serve: ServeArgs,
}

#[derive(clap::Args)]
struct InputArg {
    /// Request JSON file; `-` or absent reads standard input.
    #[arg(long, short)]
    input: Option<PathBuf>,
    /// Job database holding the named systems a request refers to with
    /// `"system": "name"` (the one `serve` uses); without it such a request
    /// is refused.
    #[arg(long)]
    db: Option<PathBuf>,
    /// PostgreSQL job store holding the named systems (replaces `--db`).
    #[arg(long)]
    database_url: Option<String>,
    /// The API token the named systems were stored under (none: stored
    /// without tokens).
    #[arg(long, env = "TETHERPLAN_TOKEN")]
    token: Option<String>,
}

/// The request with its named system merged in (`--db`).
fn resolve_system(arg: &InputArg, body: Vec<u8>) -> Result<Vec<u8>, RequestError> {
    use tetherplan::numerics::params::InvalidInput;
    let mut store: Option<Box<dyn tetherplan::jobs::store::JobBackend>> = None;
    let owner = arg
        .token
        .as_deref()
        .map(tetherplan::api::auth::Tokens::owner_id)
        .unwrap_or_default();
    let resolved = contract::system::resolve::resolve_body::<RequestError>(&body, &mut |name| {
        if store.is_none() {
            if arg.db.is_none() && arg.database_url.is_none() {
                return Err(InvalidInput::new(
                    "system",
                    format!("names the stored system `{name}`: give the job database that holds it with --db"),
                )
                .into());
            }
            let config = tetherplan::config::StoreConfig::new(
                arg.db.clone().unwrap_or_default(),
                arg.database_url.clone(),
            );
            store = Some(config.open().map_err(|e| {
                InvalidInput::new("system", format!("the job database cannot be opened: {e}"))
            })?);
        }
        let s = store.as_ref().expect("opened above");
        let found = s
            .get_system(&owner, name)
            .map_err(|e| InvalidInput::new("system", format!("cannot be read: {e}")))?;
        Ok(found.and_then(|f| serde_json::from_str(&f.body).ok()))
    })?;
    Ok(resolved.unwrap_or(body))
}

/// `serve`, `worker`; the analysis subcommands (one per kind of the
/// catalogue, [`tetherplan::contract::catalogue::KINDS`]) are added to the
/// parser at run time.
#[derive(Subcommand)]
enum Command {
    /// Run the HTTP service (the default).
    Serve(ServeArgs),
    /// Run jobs only, from the same job store as `serve` (SQLite on this
    /// host, or `--database-url postgres://…` on any host), until SIGTERM.
    Worker(tetherplan::config::WorkerArgs),
    /// Fly a flight in the dynamics model through a wind event and write
    /// its telemetry log (the flight's CSV format; `--format json`: the
    /// answer of `POST /api/v1/flights/simulate`). The request: `{"flight":
    /// <a POST /api/v1/flights body>, "wind_event": {...}, "sample_rate_hz",
    /// "hold_s", "numerics"}`.
    SimulateFlight(SimulateArgs),
    /// Replay a recorded telemetry log (the flight's CSV, or NMEA `$--MWV`
    /// lines) against a running server, paced by its time_s.
    Feed(FeedArgs),
}

#[derive(clap::Args)]
struct SimulateArgs {
    /// Request JSON file; `-` or absent reads standard input.
    #[arg(long, short)]
    input: Option<PathBuf>,
    /// Where to write the log (absent: standard output).
    #[arg(long, short)]
    output: Option<PathBuf>,
    /// `csv` (the telemetry log) or `json`.
    #[arg(long, default_value = "csv", value_parser = ["csv", "json"])]
    format: String,
}

#[derive(clap::Args)]
struct FeedArgs {
    /// The flight's id.
    #[arg(long)]
    flight: i64,
    /// The log: `.csv` (a header of the sample's field names) or NMEA
    /// (`.nmea`, or told by its content).
    file: PathBuf,
    /// Sample seconds per wall second; `0` or `max`: as fast as possible.
    #[arg(long, default_value = "1")]
    speed: String,
    /// The server's URL.
    #[arg(long, default_value = "http://127.0.0.1:8080")]
    server: String,
    /// The API token.
    #[arg(long, env = "TETHERPLAN_TOKEN")]
    token: Option<String>,
}

/// A progress bar on standard error for `total` units of `what`.
fn progress_bar(total: u64, what: &str) -> Bar {
    let bar = ProgressBar::new(total);
    bar.set_style(
        ProgressStyle::with_template(&format!(
            "{{spinner}} {what} [{{bar:40}}] {{pos}}/{{len}} ({{eta}})"
        ))
        .expect("valid template")
        .progress_chars("=> "),
    );
    Bar(bar)
}

fn read_input(arg: &InputArg) -> Result<Vec<u8>, String> {
    match &arg.input {
        Some(path) if path.as_os_str() != "-" => {
            std::fs::read(path).map_err(|e| format!("cannot read {}: {e}", path.display()))
        }
        _ => {
            let mut buf = Vec::new();
            std::io::stdin()
                .read_to_end(&mut buf)
                .map_err(|e| format!("cannot read standard input: {e}"))?;
            Ok(buf)
        }
    }
}

/// Prints the JSON answer on stdout. A reader that has gone away (`… | head
/// -1`) is not an error: the process exits quietly with status 0.
fn print_json(value: &impl Serialize) {
    print_text(&serde_json::to_string_pretty(value).expect("responses serialise"));
}

/// Prints `text` and a newline on stdout (see [`print_json`]).
fn print_text(text: &str) {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    if let Err(e) = writeln!(out, "{text}").and_then(|()| out.flush()) {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(0);
        }
        eprintln!("tetherplan: cannot write the answer: {e}");
        std::process::exit(1);
    }
}

/// Answers one request of `kind` read from `arg`: the pretty JSON answer
/// on stdout (status 0), or the error body (status 2 for bad input, 1 for
/// a failure on valid input).
fn answer_kind(kind: &Kind, arg: &InputArg) -> ExitCode {
    let body = match read_input(arg) {
        Ok(b) => b,
        Err(msg) => {
            print_json(&dto::ErrorBody::new("io", None, msg));
            return ExitCode::from(2);
        }
    };
    let bar = progress_bar(0, kind.name);
    let out = contract::json_keys::reject_duplicate_keys(&body)
        .and_then(|()| resolve_system(arg, body))
        .and_then(|body| (kind.run_pretty)(&body, &bar));
    bar.0.finish_and_clear();
    match out {
        Ok(text) => {
            print_text(&text);
            ExitCode::SUCCESS
        }
        Err(e) => {
            print_json(&e.body());
            ExitCode::from(
                if matches!(e, RequestError::Invalid(_) | RequestError::Malformed(_)) {
                    2
                } else {
                    1
                },
            )
        }
    }
}

/// The subcommand of a kind: its name with `-` for `_`.
fn subcommand_name(kind: &Kind) -> &'static str {
    Box::leak(kind.name.replace('_', "-").into_boxed_str())
}

/// A progress bar on standard error.
struct Bar(ProgressBar);

impl Progress for Bar {
    fn report(&self, done: usize, total: usize) {
        self.0.set_length(total as u64);
        self.0.set_position(done as u64);
    }
}

/// Runs the server on a multi-threaded tokio runtime (I/O only: solves
/// run on rayon).
fn serve(args: ServeArgs) -> ExitCode {
    // Before any thread starts: memory comes back after a load (api::memory).
    tetherplan::api::memory::tune_allocator();
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env().unwrap_or_else(|_| "info".into()),
        )
        .with_writer(std::io::stderr)
        // Colour only on a terminal: log files and pipes get plain text.
        .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stderr()))
        .init();
    let runtime = match tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()
    {
        Ok(r) => r,
        Err(e) => {
            eprintln!("cannot start the async runtime: {e}");
            return ExitCode::FAILURE;
        }
    };
    match runtime.block_on(tetherplan::api::serve(args.into())) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            tracing::error!("{e}");
            eprintln!("tetherplan serve: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Runs `tetherplan worker` (logs on standard error).
fn worker(args: tetherplan::config::WorkerArgs) -> ExitCode {
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env().unwrap_or_else(|_| "info".into()),
        )
        .with_writer(std::io::stderr)
        .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stderr()))
        .init();
    match tetherplan::jobs::worker::run(args.into()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            tracing::error!("{e}");
            eprintln!("tetherplan worker: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Prints an error body and returns `code`.
fn fail(body: &dto::ErrorBody, code: u8) -> ExitCode {
    eprintln!(
        "{}",
        serde_json::to_string_pretty(body).expect("errors serialise")
    );
    ExitCode::from(code)
}

/// `tetherplan simulate-flight`.
fn simulate_flight(args: &SimulateArgs) -> ExitCode {
    use tetherplan::contract::flight::simulate::{SimulateFlightRequest, to_csv};
    let input = InputArg {
        input: args.input.clone(),
        db: None,
        database_url: None,
        token: None,
    };
    let body = match read_input(&input) {
        Ok(b) => b,
        Err(msg) => return fail(&dto::ErrorBody::new("io", None, msg), 2),
    };
    let bar = progress_bar(0, "simulate-flight");
    let out = SimulateFlightRequest::parse(&body).and_then(|r| {
        let setup = r.setup(&bar)?;
        setup.run(&bar)
    });
    bar.0.finish_and_clear();
    let out = match out {
        Ok(o) => o,
        Err(e) => {
            let code = if matches!(e, RequestError::Invalid(_) | RequestError::Malformed(_)) {
                2
            } else {
                1
            };
            return fail(&e.body(), code);
        }
    };
    let text = if args.format == "json" {
        serde_json::to_string_pretty(&out).expect("responses serialise")
    } else {
        to_csv(&out.samples)
    };
    match &args.output {
        Some(path) => {
            if let Err(e) = std::fs::write(path, text) {
                let msg = format!("cannot write {}: {e}", path.display());
                return fail(&dto::ErrorBody::new("io", None, msg), 1);
            }
        }
        None => print_text(text.trim_end()),
    }
    eprintln!(
        "simulate-flight: {} samples over {} s ({:?})",
        out.samples.len(),
        out.duration_s,
        out.outcome
    );
    ExitCode::SUCCESS
}

/// `tetherplan feed`.
fn feed(args: &FeedArgs) -> ExitCode {
    use tetherplan::api::flights::feed::{FeedError, Target, feed};
    use tetherplan::contract::flight::feed::{LogError, read_log};
    let speed = match args.speed.trim() {
        "max" | "0" => None,
        s => match s.parse::<f64>() {
            Ok(v) if v.is_finite() && v > 0.0 => Some(v),
            Ok(0.0) => None,
            _ => {
                eprintln!(
                    "tetherplan feed: --speed must be a positive number, 0 or max, got `{s}`"
                );
                return ExitCode::from(2);
            }
        },
    };
    let text = match std::fs::read_to_string(&args.file) {
        Ok(t) => t,
        Err(e) => {
            eprintln!("tetherplan feed: cannot read {}: {e}", args.file.display());
            return ExitCode::from(2);
        }
    };
    let log = match read_log(&args.file, &text) {
        Ok(l) => l,
        Err(LogError::Whole(e)) => {
            eprintln!("tetherplan feed: {}: {e}", args.file.display());
            return ExitCode::from(2);
        }
        Err(LogError::Lines(rejected)) => {
            for r in rejected.iter().take(20) {
                eprintln!(
                    "tetherplan feed: {} line {}: {} {}",
                    args.file.display(),
                    r.line,
                    r.field,
                    r.reason
                );
            }
            eprintln!(
                "tetherplan feed: {} line(s) refused; nothing was sent",
                rejected.len()
            );
            return ExitCode::from(2);
        }
    };
    let target = match Target::new(&args.server, args.token.clone(), args.flight) {
        Ok(t) => t,
        Err(e) => {
            eprintln!("tetherplan feed: {e}");
            return ExitCode::from(2);
        }
    };
    let runtime = match tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
    {
        Ok(r) => r,
        Err(e) => {
            eprintln!("tetherplan feed: cannot start the async runtime: {e}");
            return ExitCode::FAILURE;
        }
    };
    let bar = progress_bar(log.lines.len() as u64, "feed");
    let result = runtime.block_on(feed(&target, &log, speed, |sent| {
        bar.0.set_position(sent as u64)
    }));
    bar.0.finish_and_clear();
    match result {
        Ok(s) => {
            println!(
                "accepted {}, duplicates {}, refused {} ({} batches, {} retries); state {}",
                s.accepted,
                s.duplicates,
                s.refused.len(),
                s.batches,
                s.retries,
                s.state.as_deref().unwrap_or("unknown")
            );
            for r in &s.refused {
                let line = r.line.map_or("?".into(), |l| l.to_string());
                println!("refused line {line}: {} {}", r.field, r.reason);
            }
            ExitCode::SUCCESS
        }
        Err(FeedError::Refused { status, body }) => {
            eprintln!("tetherplan feed: the server refused a batch (HTTP {status}): {body}");
            ExitCode::from(3)
        }
        Err(FeedError::Unreachable(e)) => {
            eprintln!("tetherplan feed: {e}");
            ExitCode::FAILURE
        }
    }
}

fn main() -> ExitCode {
    let kinds: Vec<(&'static str, &'static Kind)> =
        KINDS.iter().map(|k| (subcommand_name(k), k)).collect();
    let mut parser = Cli::command();
    for (name, kind) in &kinds {
        parser = parser.subcommand(InputArg::augment_args(
            clap::Command::new(*name).about(kind.about),
        ));
    }
    let matches = parser.get_matches();
    if let Some((name, sub)) = matches.subcommand()
        && let Some((_, kind)) = kinds.iter().find(|(n, _)| *n == name)
    {
        return match InputArg::from_arg_matches(sub) {
            Ok(arg) => answer_kind(kind, &arg),
            Err(e) => e.exit(),
        };
    }
    let cli = Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    match cli.command {
        None => serve(cli.serve),
        Some(Command::Serve(args)) => serve(args),
        Some(Command::Worker(args)) => worker(args),
        Some(Command::SimulateFlight(args)) => simulate_flight(&args),
        Some(Command::Feed(args)) => feed(&args),
    }
}
