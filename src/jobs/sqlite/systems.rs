//! The named systems of the SQLite store (`systems`, keyed by owner and
//! name; SPEC §9), counted with the owner's jobs against the store quota.
//! [`super::JobStore`]'s `JobBackend` methods of the same names call these.

use rusqlite::{OptionalExtension, TransactionBehavior, params};

use super::rows::{JobStore, NOW, OLDEST_FINISHED, STORED_BYTES};
use crate::jobs::admission;
use crate::jobs::backend::{PutSystem, StoreError, StoredSystem};

pub(super) fn put_system(
    store: &JobStore,
    owner: &str,
    name: &str,
    body: &str,
    max_per_owner: usize,
    max_stored_bytes: u64,
) -> Result<PutSystem, StoreError> {
    let mut conn = store.conn();
    let tx = conn.transaction_with_behavior(TransactionBehavior::Immediate)?;
    let jobs_owner = (!owner.is_empty()).then_some(owner);
    let stored: i64 = tx.query_row(STORED_BYTES, [jobs_owner], |r| r.get(0))?;
    let replaced: i64 = tx.query_row(
        "SELECT ifnull(sum(octet_length(body)), 0) FROM systems WHERE owner = ?1 AND name = ?2",
        params![owner, name],
        |r| r.get(0),
    )?;
    if let Some(full) =
        admission::check_system_store(stored, replaced, body.len(), max_stored_bytes, || {
            Ok(tx.query_row(OLDEST_FINISHED, [jobs_owner], |r| r.get(0))?)
        })?
    {
        return Ok(full);
    }
    let updated = tx.execute(
        &format!("UPDATE systems SET body = ?3, updated_at = {NOW} WHERE owner = ?1 AND name = ?2"),
        params![owner, name, body],
    )?;
    let out = if updated == 1 {
        PutSystem::Updated
    } else {
        let n: i64 = tx.query_row(
            "SELECT count(*) FROM systems WHERE owner = ?1",
            params![owner],
            |r| r.get(0),
        )?;
        if n as usize >= max_per_owner {
            return Ok(PutSystem::Full { max: max_per_owner });
        }
        tx.execute(
            "INSERT INTO systems (owner, name, body) VALUES (?1, ?2, ?3)",
            params![owner, name, body],
        )?;
        PutSystem::Created
    };
    tx.commit()?;
    Ok(out)
}

pub(super) fn get_system(
    store: &JobStore,
    owner: &str,
    name: &str,
) -> Result<Option<StoredSystem>, StoreError> {
    Ok(store
        .conn()
        .query_row(
            "SELECT name, body, created_at, updated_at FROM systems WHERE owner = ?1 AND name = ?2",
            params![owner, name],
            |r| {
                Ok(StoredSystem {
                    name: r.get(0)?,
                    body: r.get(1)?,
                    created_at: r.get(2)?,
                    updated_at: r.get(3)?,
                })
            },
        )
        .optional()?)
}

pub(super) fn delete_system(store: &JobStore, owner: &str, name: &str) -> Result<bool, StoreError> {
    let n = store.conn().execute(
        "DELETE FROM systems WHERE owner = ?1 AND name = ?2",
        params![owner, name],
    )?;
    Ok(n == 1)
}

pub(super) fn list_systems(store: &JobStore, owner: &str) -> Result<Vec<StoredSystem>, StoreError> {
    let conn = store.conn();
    let mut stmt = conn.prepare(
        "SELECT name, created_at, updated_at FROM systems WHERE owner = ?1 ORDER BY name",
    )?;
    let rows = stmt.query_map(params![owner], |r| {
        Ok(StoredSystem {
            name: r.get(0)?,
            body: String::new(),
            created_at: r.get(1)?,
            updated_at: r.get(2)?,
        })
    })?;
    Ok(rows.collect::<Result<Vec<_>, _>>()?)
}
