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
    }
}
