//! Which job store a process opens ([`StoreConfig`]: the embedded SQLite
//! file or a PostgreSQL database), and the store's old paths
//! (`jobs::store::…`): the trait and its row types ([`super::backend`]),
//! the lease, the SQLite store. The trait itself names no implementation.

use std::path::PathBuf;

pub use super::backend::*;
pub use super::lease::{Lease, WorkerId};
pub use super::sqlite::JobStore;

/// The job store a process opens: SQLite at a path, or PostgreSQL.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum StoreConfig {
    Sqlite(PathBuf),
    Postgres(String),
}

impl StoreConfig {
    pub fn new(db: PathBuf, database_url: Option<String>) -> Self {
        match database_url.filter(|u| !u.trim().is_empty()) {
            Some(url) => Self::Postgres(url),
            None => Self::Sqlite(db),
        }
    }

    /// Where the jobs are, for logs (no password).
    pub fn describe(&self) -> String {
        match self {
            Self::Sqlite(p) => format!("sqlite:{}", p.display()),
            Self::Postgres(u) => super::postgres::redact(u),
        }
    }

    /// Opens (and migrates) the store.
    pub fn open(&self) -> Result<Box<dyn JobBackend>, StoreError> {
        Ok(match self {
            Self::Sqlite(p) => Box::new(JobStore::open(p)?),
            Self::Postgres(u) => Box::new(super::postgres::PgStore::open(u)?),
        })
    }
}
