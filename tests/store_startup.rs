//! A job store that cannot start (issue 34, item 3): `tetherplan serve` and
//! `tetherplan worker` on a PostgreSQL database that holds a table they did
//! not make, whose migration fails half way, with a wrong password, or with
//! nothing listening. Each must exit with status 1 (not a panic's 101), say
//! why in plain words (not "db error"), never log a migration as done, and
//! leave the database as it found it (the migration is one transaction).
//!
//! Each test uses a database of its own (created, then dropped). Without a
//! reachable PostgreSQL (`TETHERPLAN_TEST_PG_URL`, default
//! `postgres://postgres:postgres@127.0.0.1:5432/postgres`) the tests print
//! why and pass, unless `CI` is set: then they fail.

use std::io::Read;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

mod common;
use common::pg::{TestDb, admin_url};

/// Every table and index of the public schema of `db`, sorted.
fn relations(db: &TestDb) -> Vec<String> {
    let mut c = db.client();
    c.query(
        "SELECT relname::TEXT FROM pg_class c JOIN pg_namespace n ON n.oid = c.relnamespace
         WHERE n.nspname = 'public' AND c.relkind IN ('r', 'i', 'S') ORDER BY 1",
        &[],
    )
    .unwrap()
    .iter()
    .map(|r| r.get(0))
    .collect()
}

/// Runs `tetherplan <args> --database-url url` to its end (at most 60 s):
/// exit code and standard error.
fn run_to_end(subcommand: &str, url: &str) -> (Option<i32>, String) {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_tetherplan"));
    cmd.arg(subcommand);
    if subcommand == "serve" {
        cmd.args(["--addr", "127.0.0.1:0"]);
    }
    let mut child = cmd
        .args(["--database-url", url])
        .env("RUST_LOG", "info")
        .env("TETHERPLAN_JOB_THREADS", "1")
        .env_remove("TETHERPLAN_DB")
        .env_remove("RUST_BACKTRACE")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if start.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("tetherplan {subcommand} did not stop within 60 s on a store it cannot open");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    (status.code(), err)
}

fn assert_plain_failure(what: &str, code: Option<i32>, err: &str, expected: &[&str]) {
    assert_eq!(
        code,
        Some(1),
        "{what}: exit status 1 expected, stderr:\n{err}"
    );
    assert!(!err.contains("panicked"), "{what}: a panic:\n{err}");
    assert!(
        !err.contains("db error"),
        "{what}: \"db error\" says nothing:\n{err}"
    );
    assert!(
        !err.contains("migrated"),
        "{what}: a migration logged as done:\n{err}"
    );
    for e in expected {
        assert!(err.contains(e), "{what}: {e:?} not in stderr:\n{err}");
    }
}

/// A table `systems` the server did not make: both commands refuse to start,
/// naming the table, and the database keeps exactly that one table.
#[test]
fn a_table_it_did_not_make_stops_the_start_and_changes_nothing() {
    let Some(db) = TestDb::create("foreign_table") else {
        return;
    };
    db.client()
        .batch_execute("CREATE TABLE systems (x INTEGER)")
        .unwrap();
    let before = relations(&db);
    assert_eq!(before, ["systems"]);
    for sub in ["serve", "worker"] {
        let (code, err) = run_to_end(sub, &db.url);
        assert_plain_failure(
            sub,
            code,
            &err,
            &[
                "a table `systems` that tetherplan did not make",
                "nothing was changed",
            ],
        );
        assert_eq!(relations(&db), before, "{sub} left the database changed");
    }
}

/// A migration that fails half way (an index name taken by someone else's
/// index, created after the table `jobs` in the same version): rolled back
/// whole, `jobs` is not left behind, and the message names the version.
#[test]
fn a_failed_migration_is_rolled_back_whole() {
    let Some(db) = TestDb::create("failed_migration") else {
        return;
    };
    db.client()
        .batch_execute("CREATE TABLE other (x INTEGER); CREATE INDEX jobs_by_owner ON other (x)")
        .unwrap();
    let before = relations(&db);
    let (code, err) = run_to_end("serve", &db.url);
    assert_plain_failure(
        "serve",
        code,
        &err,
        &[
            "migration of the job database to schema version 1 failed",
            "jobs_by_owner",
            "nothing was changed",
        ],
    );
    assert_eq!(relations(&db), before);
    // An empty database then migrates, and the log says so after the commit.
    db.client().batch_execute("DROP TABLE other").unwrap();
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_tetherplan"));
    let mut child = cmd
        .args(["serve", "--addr", "127.0.0.1:0", "--database-url", &db.url])
        .env("RUST_LOG", "info")
        .env("TETHERPLAN_JOB_THREADS", "0")
        .env_remove("TETHERPLAN_DB")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut line = [0u8; 64];
    let n = child.stdout.as_mut().unwrap().read(&mut line).unwrap();
    assert!(String::from_utf8_lossy(&line[..n]).starts_with("tetherplan listening"));
    child.kill().unwrap();
    child.wait().unwrap();
    let version: i32 = db
        .client()
        .query_one("SELECT max(version) FROM schema_version", &[])
        .unwrap()
        .get(0);
    assert_eq!(version, tetherplan::jobs::postgres::SCHEMA_VERSION);
}

/// A wrong password says authentication failed, with the server's reason;
/// the password itself is never printed.
#[test]
fn a_wrong_password_says_authentication_failed() {
    let admin = admin_url();
    if postgres::Client::connect(&admin, postgres::NoTls).is_err() {
        assert!(std::env::var_os("CI").is_none(), "PostgreSQL unreachable");
        eprintln!("SKIPPED: PostgreSQL unreachable at {admin}");
        return;
    }
    let (scheme_user, host_db) = admin.split_once('@').unwrap();
    let user = scheme_user.rsplit_once(':').unwrap().0;
    let url = format!("{user}:not-the-password-x9@{host_db}");
    let (code, err) = run_to_end("serve", &url);
    assert_plain_failure(
        "serve",
        code,
        &err,
        &[
            "authentication failed",
            "password authentication failed for user",
        ],
    );
    assert!(
        !err.contains("not-the-password-x9"),
        "the password shown:\n{err}"
    );
}

/// Nothing listening: "connection refused", and where.
#[test]
fn nothing_listening_says_connection_refused() {
    // A port nothing listens on: bound, then closed.
    let port = {
        let l = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        l.local_addr().unwrap().port()
    };
    let url = format!("postgres://postgres:pw@127.0.0.1:{port}/postgres");
    for sub in ["serve", "worker"] {
        let (code, err) = run_to_end(sub, &url);
        assert_plain_failure(
            sub,
            code,
            &err,
            &["connection refused", &format!("127.0.0.1:{port}")],
        );
    }
}
