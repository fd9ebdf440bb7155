//! Who runs a job: worker identities and leases.
//!
//! A worker claims a job under a lease: its [`WorkerId`], an expiry
//! (renewed by a heartbeat while the job runs) and an epoch that grows at
//! every claim. Progress, result and failure writes are fenced: they name
//! the lease and change nothing unless the row is still `running` under
//! that owner and epoch. A process that lost its lease (expired and taken
//! over, or the job cancelled) therefore cannot write, and two processes on
//! one database never both run a job to completion.
//!
//! A worker id is `host/pid/nonce`. At start-up a store takes over at once
//! the jobs of workers on the same host whose process is gone (or whose pid
//! is its own, as after a container restart), so one restarted process
//! re-runs its interrupted job without waiting for the lease to expire.

use std::hash::{BuildHasher, Hasher};
use std::time::{Duration, SystemTime, UNIX_EPOCH};

/// The identity of one job-running process (one store instance).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct WorkerId {
    id: String,
    host: String,
    pid: u32,
}

impl WorkerId {
    /// A fresh identity for this process: `host/pid/nonce`.
    pub fn this_process() -> Self {
        let host = hostname();
        let pid = std::process::id();
        let mut h = std::collections::hash_map::RandomState::new().build_hasher();
        h.write_u128(now_ns());
        let nonce = h.finish();
        Self {
            id: format!("{host}/{pid}/{nonce:016x}"),
            host,
            pid,
        }
    }

    pub fn as_str(&self) -> &str {
        &self.id
    }

    pub fn pid(&self) -> u32 {
        self.pid
    }

    /// Whether the worker `other` (an id as stored) is a dead process on
    /// this host: its pid is gone, or it is this process's pid under
    /// another nonce (an earlier life of a container's pid 1).
    pub fn is_dead_local(&self, other: &str) -> bool {
        if other == self.id {
            return false;
        }
        let mut parts = other.rsplitn(3, '/');
        let (Some(_nonce), Some(pid), Some(host)) = (parts.next(), parts.next(), parts.next())
        else {
            return false;
        };
        let Ok(pid) = pid.parse::<u32>() else {
            return false;
        };
        host == self.host && (pid == self.pid || !pid_alive(pid))
    }
}

/// A claim on one job: fenced writes carry it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Lease {
    pub job_id: i64,
    pub owner: String,
    pub epoch: i64,
}

/// Milliseconds since the Unix epoch.
pub fn now_ms() -> i64 {
    (now_ns() / 1_000_000) as i64
}

/// `now + d`, in milliseconds since the Unix epoch.
pub fn expiry_ms(d: Duration) -> i64 {
    now_ms().saturating_add(d.as_millis().min(i64::MAX as u128) as i64)
}

fn now_ns() -> u128 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_nanos())
        .unwrap_or(0)
}

fn hostname() -> String {
    #[cfg(unix)]
    {
        let mut buf = [0u8; 256];
        // SAFETY: gethostname writes at most `len` bytes into `buf`.
        let rc = unsafe { libc::gethostname(buf.as_mut_ptr().cast(), buf.len()) };
        if rc == 0 {
            let end = buf.iter().position(|&b| b == 0).unwrap_or(buf.len());
            let name = String::from_utf8_lossy(&buf[..end]).replace('/', "_");
            if !name.is_empty() {
                return name;
            }
        }
    }
    "localhost".into()
}

fn pid_alive(pid: u32) -> bool {
    #[cfg(unix)]
    {
        let Ok(pid) = libc::pid_t::try_from(pid) else {
            return false;
        };
        // SAFETY: signal 0 only checks that the process exists.
        let rc = unsafe { libc::kill(pid, 0) };
        rc == 0 || std::io::Error::last_os_error().raw_os_error() == Some(libc::EPERM)
    }
    #[cfg(not(unix))]
    {
        let _ = pid;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dead_local_workers_are_recognised() {
        let me = WorkerId::this_process();
        assert!(!me.is_dead_local(me.as_str()), "not myself");
        let host = &me.host;
        assert!(
            me.is_dead_local(&format!("{host}/{}/00", me.pid)),
            "my pid, another life"
        );
        // pid 1 is alive on every Unix host (init).
        assert!(!me.is_dead_local(&format!("{host}/1/00")));
        assert!(!me.is_dead_local("elsewhere/999999/00"), "another host");
        assert!(
            me.is_dead_local(&format!("{host}/4194303/00")),
            "no such pid"
        );
        assert!(!me.is_dead_local("garbage"));
    }
}
