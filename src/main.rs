//! The `tetherplan` binary: `serve` (the default with no subcommand) runs
//! the HTTP service; the other subcommands answer one request over the JSON
//! contract: each reads a request (file or stdin), prints the JSON answer
//! on stdout, and on bad input prints the error body and exits with status 2.

use std::io::Read;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;
use tetherplan::config::ServeArgs;
use tetherplan::contract::{
    self, Progress, RequestError, dto, ge_charts, ge_critical, run, simulate, transient,
};
use tetherplan::numerics::chart::Parallelism;

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

#[derive(Subcommand)]
enum Command {
    /// Run the HTTP service (the default).
    Serve(ServeArgs),
    /// Run jobs only, from the same job store as `serve` (SQLite on this
    /// host, or `--database-url postgres://…` on any host), until SIGTERM.
    Worker(tetherplan::config::WorkerArgs),
    /// Eigenvalues and stability verdict at one state.
    Stability(InputArg),
    /// Critical time and maximum safe elevation of a deployment profile.
    Critical(InputArg),
    /// Largest safe constant rate for a target elevation.
    SafeRate(InputArg),
    /// Deployment chart: t* and h* against rate, one series per buoyancy
    /// (`model.kind = "geometrically_exact"`: and per stiffness ratio).
    Chart(InputArg),
    /// Transient run (linear string, or `"model": {"kind": "geometrically_exact"}`).
    Simulate(InputArg),
    /// Response against forcing frequency: wind on the linear string, or
    /// `"excitation": "base"` (shaken platform, GE cable).
    FrequencyResponse(InputArg),
    /// Static tether in a steady wind: altitude, blow-down, tensions, shape.
    Equilibrium(InputArg),
    /// Operating envelope over wind speed × tether length.
    Envelope(InputArg),
    /// The fastest safe deployment (or retrieval) schedule, with the haul-down deadline.
    Plan(InputArg),
    /// Uncertainty bands of a deployment chart: 5/50/95 % of h* and t*
    /// per rate under uncertain inputs (seeded Monte Carlo).
    Bands(InputArg),
    /// The tether in time through a gust or turbulence, from rest in the
    /// static equilibrium of `wind.flow` (progress bar in time steps).
    Dynamics(InputArg),
    /// The largest tension over an exposure, Monte Carlo over turbulence
    /// seeds (progress bar in samples).
    DynamicsPeaks(InputArg),
    /// Launch windows by the hour from a forecast (Open-Meteo JSON, METAR,
    /// TAF or CSV): each period judged as the plan judges its wind
    /// (progress bar in plans).
    Windows(InputArg),
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
    use std::io::Write;
    let text = serde_json::to_string_pretty(value).expect("responses serialise");
    let mut out = std::io::stdout().lock();
    if let Err(e) = writeln!(out, "{text}").and_then(|()| out.flush()) {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(0);
        }
        eprintln!("tetherplan: cannot write the answer: {e}");
        std::process::exit(1);
    }
}

fn answer<Req: dto::SystemRequest, Resp: Serialize>(
    arg: &InputArg,
    run: impl FnOnce(&Req) -> Result<Resp, RequestError>,
) -> ExitCode {
    answer_with(arg, contract::parse::<Req>, run)
}

fn answer_with<Req, Resp: Serialize>(
    arg: &InputArg,
    parse: impl FnOnce(&[u8]) -> Result<Req, RequestError>,
    run: impl FnOnce(&Req) -> Result<Resp, RequestError>,
) -> ExitCode {
    let body = match read_input(arg) {
        Ok(b) => b,
        Err(msg) => {
            print_json(&dto::ErrorBody::new("io", None, msg));
            return ExitCode::from(2);
        }
    };
    match contract::json_keys::reject_duplicate_keys(&body)
        .and_then(|()| resolve_system(arg, body))
        .and_then(|body| parse(&body).and_then(|req| run(&req)))
    {
        Ok(resp) => {
            print_json(&resp);
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

fn main() -> ExitCode {
    let cli = Cli::parse();
    let Some(command) = cli.command else {
        return serve(cli.serve);
    };
    match &command {
        Command::Bands(arg) => answer_with(arg, contract::bands::parse_bands, |req| {
            let bar = progress_bar(req.params.uncertainty.samples as u64, "samples");
            let out = contract::bands::bands(req, Parallelism::Rayon, &bar);
            bar.0.finish_and_clear();
            out
        }),
        Command::Dynamics(arg) => answer_with(arg, contract::dynamics::parse_dynamics, |req| {
            let prepared = req.prepare()?;
            let bar = progress_bar(prepared.steps as u64, "time steps");
            let out = contract::dynamics::run::run_prepared(&prepared, &bar)
                .map(|ran| contract::dynamics::run::response(req, &prepared, &ran));
            bar.0.finish_and_clear();
            out
        }),
        Command::DynamicsPeaks(arg) => answer_with(arg, contract::dynamics::parse_peaks, |req| {
            req.prepare()?;
            let bar = progress_bar(req.samples as u64, "samples");
            let out = contract::dynamics::peaks::peaks(req, Parallelism::Rayon, &bar);
            bar.0.finish_and_clear();
            out
        }),
        Command::Windows(arg) => answer_with(arg, contract::windows::parse_windows, |req| {
            let started = std::time::Instant::now();
            let prepared = contract::windows::prepare(req)?;
            let bar = progress_bar(prepared.plan_count() as u64, "plans");
            let out = contract::windows::run::answer(req, &prepared, &bar, started);
            bar.0.finish_and_clear();
            out
        }),
        Command::Serve(args) => serve(args.clone()),
        Command::Worker(args) => worker(args.clone()),
        Command::Stability(arg) => answer_with(
            arg,
            ge_critical::parse_stability,
            ge_critical::stability_any,
        ),
        Command::Critical(arg) => answer_with(arg, ge_critical::parse_critical, |req| {
            ge_critical::critical_any(req, &contract::run::NoProgress)
        }),
        Command::SafeRate(arg) => answer(arg, run::safe_rate),
        Command::Chart(arg) => answer_with(arg, ge_charts::parse_chart, |req| match req {
            ge_charts::AnyChartRequest::LinearString(req) => {
                let bar = progress_bar(run::chart_points(req) as u64, "chart points");
                let out = run::chart(req, Parallelism::Rayon, &bar);
                bar.0.finish_and_clear();
                out.map(ge_charts::AnyChartResponse::LinearString)
            }
            ge_charts::AnyChartRequest::GeometricallyExact(req) => {
                let bar = progress_bar(ge_charts::chart_points(req) as u64, "chart points");
                let out = ge_charts::ge_chart(req, Parallelism::Rayon, &bar);
                bar.0.finish_and_clear();
                out.map(ge_charts::AnyChartResponse::GeometricallyExact)
            }
        }),
        Command::Simulate(arg) => answer_with(arg, simulate::parse_simulate, |req| {
            let bar = progress_bar(0, "steps");
            let out = simulate::simulate_any(req, &bar);
            bar.0.finish_and_clear();
            out
        }),
        Command::Equilibrium(arg) => answer_with(
            arg,
            contract::parse_plain::<contract::equilibrium::dto::EquilibriumRequest>,
            contract::equilibrium::equilibrium,
        ),
        Command::Envelope(arg) => answer_with(
            arg,
            contract::parse_plain::<contract::envelope::dto::EnvelopeRequest>,
            |req| {
                req.validate()?;
                let bar = progress_bar(
                    req.wind_speeds_m_s.as_ref().map_or(1, |g| g.count()) as u64,
                    "wind speeds",
                );
                let out = contract::envelope::envelope(req, Parallelism::Rayon, &bar);
                bar.0.finish_and_clear();
                out
            },
        ),
        Command::Plan(arg) => answer_with(arg, contract::plan::parse_plan, |req| {
            contract::plan::plan(req, &run::NoProgress)
        }),
        Command::FrequencyResponse(arg) => {
            answer_with(arg, ge_charts::parse_frequency_response, |req| {
                let runs = match req {
                    ge_charts::AnyFrequencyResponseRequest::Wind(r) => {
                        transient::frequency_response_runs(r)
                    }
                    ge_charts::AnyFrequencyResponseRequest::Base(r) => {
                        r.frequencies_rad_s.count() + 1
                    }
                };
                let bar = progress_bar(runs as u64, "frequencies");
                let out = ge_charts::frequency_response_any(req, Parallelism::Rayon, &bar);
                bar.0.finish_and_clear();
                out
            })
        }
    }
}
