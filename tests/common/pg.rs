//! A PostgreSQL database of a test's own (created, then dropped), for the
//! tests that need one: `TETHERPLAN_TEST_PG_URL` (default
//! `postgres://postgres:postgres@127.0.0.1:5432/postgres`) names the
//! server. Unreachable, the test is skipped with the reason printed,
//! unless `CI` is set: then it fails.

/// A fresh database, dropped at the end.
pub struct TestDb {
    admin_url: String,
    name: String,
    pub url: String,
}

pub fn admin_url() -> String {
    std::env::var("TETHERPLAN_TEST_PG_URL")
        .unwrap_or_else(|_| "postgres://postgres:postgres@127.0.0.1:5432/postgres".into())
}

impl TestDb {
    /// None (with the reason printed) when PostgreSQL is unreachable and
    /// `CI` is not set.
    pub fn create(test: &str) -> Option<Self> {
        let admin_url = admin_url();
        let mut admin = match postgres::Client::connect(&admin_url, postgres::NoTls) {
            Ok(c) => c,
            Err(e) => {
                if std::env::var_os("CI").is_some() {
                    panic!("PostgreSQL unreachable at {admin_url} with CI set: {e}");
                }
                eprintln!(
                    "SKIPPED {test}: PostgreSQL unreachable at {admin_url} ({e}); \
                     set TETHERPLAN_TEST_PG_URL or start it (.ci/run shows how)"
                );
                return None;
            }
        };
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .unwrap()
            .subsec_nanos();
        let name = format!("tetherplan_test_{}_{}_{nanos}", test, std::process::id());
        admin
            .batch_execute(&format!("CREATE DATABASE {name}"))
            .unwrap();
        let base = admin_url.rsplit_once('/').unwrap().0;
        Some(Self {
            url: format!("{base}/{name}"),
            admin_url,
            name,
        })
    }

    pub fn client(&self) -> postgres::Client {
        postgres::Client::connect(&self.url, postgres::NoTls).unwrap()
    }
}

impl Drop for TestDb {
    fn drop(&mut self) {
        if let Ok(mut admin) = postgres::Client::connect(&self.admin_url, postgres::NoTls) {
            let _ = admin.batch_execute(&format!(
                "DROP DATABASE IF EXISTS {} WITH (FORCE)",
                self.name
            ));
        }
    }
}
