//! The named systems of the PostgreSQL store (`systems`, keyed by owner
//! and name; SPEC §9), counted with the owner's jobs against the store
//! quota under the insert lock. [`super::PgStore`]'s `JobBackend` methods
//! of the same names call these.

use super::rows::{INSERT_LOCK, NOW, OLDEST_FINISHED, PgStore, STORED_BYTES};
use crate::jobs::admission;
use crate::jobs::backend::{PutSystem, StoreError, StoredSystem};

pub(super) fn put_system(
    store: &PgStore,
    owner: &str,
    name: &str,
    body: &str,
    max_per_owner: usize,
    max_stored_bytes: u64,
) -> Result<PutSystem, StoreError> {
    store.with(|c| {
        let mut tx = c.transaction()?;
        // Counted and written under the insert lock (the quota holds across processes).
        tx.execute("SELECT pg_advisory_xact_lock($1)", &[&INSERT_LOCK])?;
        let jobs_owner = (!owner.is_empty()).then_some(owner);
        let stored: i64 = tx.query_one(STORED_BYTES, &[&jobs_owner])?.get(0);
        let replaced: i64 = tx
            .query_one(
                "SELECT coalesce(sum(octet_length(body)), 0)::BIGINT FROM systems
                     WHERE owner = $1 AND name = $2",
                &[&owner, &name],
            )?
            .get(0);
        if let Some(full) =
            admission::check_system_store(stored, replaced, body.len(), max_stored_bytes, || {
                Ok(tx.query_one(OLDEST_FINISHED, &[&jobs_owner])?.get(0))
            })?
        {
            return Ok(full);
        }
        let updated = tx.execute(
            &format!(
                "UPDATE systems SET body = $3, updated_at = {NOW} WHERE owner = $1 AND name = $2"
            ),
            &[&owner, &name, &body],
        )?;
        let out = if updated == 1 {
            PutSystem::Updated
        } else {
            let n: i64 = tx
                .query_one("SELECT count(*) FROM systems WHERE owner = $1", &[&owner])?
                .get(0);
            if n as usize >= max_per_owner {
                return Ok(PutSystem::Full { max: max_per_owner });
            }
            tx.execute(
                "INSERT INTO systems (owner, name, body) VALUES ($1, $2, $3)",
                &[&owner, &name, &body],
            )?;
            PutSystem::Created
        };
        tx.commit()?;
        Ok(out)
    })
}

pub(super) fn get_system(
    store: &PgStore,
    owner: &str,
    name: &str,
) -> Result<Option<StoredSystem>, StoreError> {
    store.with(|c| {
        Ok(c.query_opt(
            "SELECT name, body, created_at, updated_at FROM systems WHERE owner = $1 AND name = $2",
            &[&owner, &name],
        )?
        .map(|r| StoredSystem {
            name: r.get(0),
            body: r.get(1),
            created_at: r.get(2),
            updated_at: r.get(3),
        }))
    })
}

pub(super) fn delete_system(store: &PgStore, owner: &str, name: &str) -> Result<bool, StoreError> {
    store.with(|c| {
        let n = c.execute(
            "DELETE FROM systems WHERE owner = $1 AND name = $2",
            &[&owner, &name],
        )?;
        Ok(n == 1)
    })
}

pub(super) fn list_systems(store: &PgStore, owner: &str) -> Result<Vec<StoredSystem>, StoreError> {
    store.with(|c| {
        Ok(c.query(
            "SELECT name, created_at, updated_at FROM systems WHERE owner = $1 ORDER BY name",
            &[&owner],
        )?
        .iter()
        .map(|r| StoredSystem {
            name: r.get(0),
            body: String::new(),
            created_at: r.get(1),
            updated_at: r.get(2),
        })
        .collect())
    })
}
