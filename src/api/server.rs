//! The connection layer of `tetherplan serve`: our own accept loop over
//! hyper's HTTP/1.1 server, so that no client can hold the server with
//! connections.
//!
//! * **Header timeout.** A request head (request line and headers) must
//!   arrive within [`ConnectionLimits::header_timeout`] of the moment the
//!   server starts waiting for it; otherwise the connection is dropped.
//!   hyper starts that timer on a fresh connection and again after every
//!   answer, so it is also the idle keep-alive timeout.
//! * **Body timeout.** Each frame of a request body must arrive within
//!   [`ConnectionLimits::body_timeout`] of the previous one
//!   (`tower_http::timeout::RequestBodyTimeoutLayer`, applied in
//!   [`crate::api::serve`]).
//! * **Connection cap.** At start the soft `RLIMIT_NOFILE` is raised to the
//!   hard limit ([`raise_fd_limit`]); the cap is the configured maximum, at
//!   most the file limit minus [`RESERVED_FDS`] for the database, the job
//!   threads and logs ([`connection_cap`]). When a new connection would
//!   exceed the cap, the *oldest* connection is asked to close (hyper's
//!   graceful shutdown: an idle or half-sent connection closes at once, a
//!   request in progress is answered first), so a flood of idle connections
//!   cannot lock out new clients: the server keeps answering. Past the cap
//!   by a quarter (closing takes a moment), new connections are closed at
//!   once rather than run the process out of files.
//! * **Accept errors** (out of files, aborted handshakes) never end the
//!   loop: it pauses briefly and goes on.
//!
//! HTTP/1.1 only: browsers never speak cleartext HTTP/2, and one protocol
//! keeps the timeouts above exhaustive.

use std::collections::VecDeque;
use std::future::Future;
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Duration;

use axum::Router;
use hyper::server::conn::http1;
use hyper_util::rt::{TokioIo, TokioTimer};
use hyper_util::service::TowerToHyperService;
use tokio::net::TcpListener;
use tokio::sync::{Notify, watch};

/// File descriptors kept free of connections (database, WAL, job threads,
/// logs, the listener).
pub const RESERVED_FDS: u64 = 64;

/// Timeouts and the connection cap.
#[derive(Clone, Debug, PartialEq)]
pub struct ConnectionLimits {
    /// Time allowed for a request head to arrive (also the idle keep-alive
    /// timeout).
    pub header_timeout: Duration,
    /// Time allowed between two frames of a request body.
    pub body_timeout: Duration,
    /// Connections open at once (before the file-limit clamp).
    pub max_connections: usize,
    /// How long a connection asked to close may take to finish its answer.
    pub close_grace: Duration,
}

impl Default for ConnectionLimits {
    fn default() -> Self {
        Self {
            header_timeout: Duration::from_secs(5),
            body_timeout: Duration::from_secs(10),
            max_connections: 10_000,
            close_grace: Duration::from_secs(60),
        }
    }
}

/// An `rlim_t` as `u64`.
// The cast is a no-op where `rlim_t` is `u64` (64-bit Linux, macOS), which
// is what clippy sees; on 32-bit Linux `rlim_t` is `u32` and it is needed.
#[cfg(unix)]
#[allow(clippy::unnecessary_cast)]
fn rlim_u64(v: libc::rlim_t) -> u64 {
    v as u64
}

/// Raises the soft `RLIMIT_NOFILE` to the hard limit; returns the soft limit
/// in force afterwards (`None` when it cannot be read).
pub fn raise_fd_limit() -> Option<u64> {
    #[cfg(unix)]
    {
        let mut lim = libc::rlimit {
            rlim_cur: 0,
            rlim_max: 0,
        };
        // SAFETY: getrlimit/setrlimit only read and write the struct passed.
        unsafe {
            if libc::getrlimit(libc::RLIMIT_NOFILE, &mut lim) != 0 {
                return None;
            }
            if lim.rlim_cur < lim.rlim_max {
                let raised = libc::rlimit {
                    rlim_cur: lim.rlim_max,
                    rlim_max: lim.rlim_max,
                };
                if libc::setrlimit(libc::RLIMIT_NOFILE, &raised) == 0 {
                    lim.rlim_cur = lim.rlim_max;
                }
            }
        }
        Some(rlim_u64(lim.rlim_cur))
    }
    #[cfg(not(unix))]
    {
        None
    }
}

/// The connection cap: the configured maximum, at most the file limit less
/// the reserve and a quarter of headroom for connections being closed
/// (see the module docs); at least 1.
pub fn connection_cap(max_connections: usize, fd_limit: Option<u64>) -> usize {
    let by_files = fd_limit.map_or(usize::MAX, |l| {
        let usable = l.saturating_sub(RESERVED_FDS);
        usize::try_from(usable.saturating_mul(4) / 5).unwrap_or(usize::MAX)
    });
    max_connections.min(by_files).max(1)
}

/// Live connections: their count, and the close signals of those not yet
/// asked to close, oldest first.
struct Registry {
    live: AtomicUsize,
    open: std::sync::Mutex<VecDeque<(u64, Arc<Notify>)>>,
}

impl Registry {
    fn forget(&self, id: u64) {
        let mut open = self.open.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(i) = open.iter().position(|(c, _)| *c == id) {
            open.remove(i);
        }
    }

    /// Asks the oldest connections to close until at most `cap` remain open.
    fn shed_to(&self, cap: usize) -> usize {
        let mut open = self.open.lock().unwrap_or_else(|e| e.into_inner());
        let mut shed = 0;
        while open.len() > cap {
            if let Some((_, stop)) = open.pop_front() {
                stop.notify_one();
                shed += 1;
            }
        }
        shed
    }
}

/// Counts a connection task out of [`Registry::live`] when it ends.
struct LiveGuard(Arc<Registry>, u64);

impl Drop for LiveGuard {
    fn drop(&mut self) {
        self.0.forget(self.1);
        self.0.live.fetch_sub(1, Ordering::AcqRel);
    }
}

/// Serves `app` on `listener` until `shutdown` resolves; then stops
/// accepting, asks every connection to close, and waits (at most
/// `close_grace`) for the answers in progress.
pub async fn run(
    listener: TcpListener,
    app: Router,
    limits: ConnectionLimits,
    cap: usize,
    shutdown: impl Future<Output = ()>,
) {
    let registry = Arc::new(Registry {
        live: AtomicUsize::new(0),
        open: std::sync::Mutex::new(VecDeque::new()),
    });
    let hard_ceiling = cap.saturating_add(cap / 4).max(cap + 1);
    let (stop_all, stopping) = watch::channel(false);
    let mut builder = http1::Builder::new();
    builder
        .timer(TokioTimer::new())
        .header_read_timeout(limits.header_timeout)
        .keep_alive(true);
    let builder = Arc::new(builder);
    let mut next_id: u64 = 0;
    let mut refused_logged = false;
    tokio::pin!(shutdown);
    loop {
        let (stream, _peer) = tokio::select! {
            _ = &mut shutdown => break,
            accepted = listener.accept() => match accepted {
                Ok(c) => c,
                Err(e) => {
                    if !is_connection_error(&e) {
                        tracing::warn!("accept failed: {e}; pausing 50 ms");
                        tokio::time::sleep(Duration::from_millis(50)).await;
                    }
                    continue;
                }
            },
        };
        if registry.live.load(Ordering::Acquire) >= hard_ceiling {
            if !refused_logged {
                tracing::warn!(
                    cap,
                    "connections far above the cap while old ones close; closing new ones at once"
                );
                refused_logged = true;
            }
            drop(stream);
            continue;
        }
        refused_logged = false;
        let _ = stream.set_nodelay(true);
        next_id += 1;
        let id = next_id;
        let stop = Arc::new(Notify::new());
        registry.live.fetch_add(1, Ordering::AcqRel);
        registry
            .open
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .push_back((id, stop.clone()));
        let shed = registry.shed_to(cap);
        if shed > 0 {
            tracing::debug!(shed, cap, "connection cap reached: closing the oldest");
        }
        let guard = LiveGuard(registry.clone(), id);
        let builder = builder.clone();
        let service = TowerToHyperService::new(app.clone());
        let mut stopping = stopping.clone();
        let grace = limits.close_grace;
        tokio::spawn(async move {
            let _guard = guard;
            let conn = builder.serve_connection(TokioIo::new(stream), service);
            tokio::pin!(conn);
            let asked_to_close = tokio::select! {
                r = conn.as_mut() => {
                    if let Err(e) = r {
                        tracing::debug!("connection ended: {e}");
                    }
                    false
                }
                _ = stop.notified() => true,
                _ = stopping.wait_for(|s| *s) => true,
            };
            if asked_to_close {
                conn.as_mut().graceful_shutdown();
                let _ = tokio::time::timeout(grace, conn).await;
            }
        });
    }
    drop(listener);
    let _ = stop_all.send(true);
    let deadline = tokio::time::Instant::now() + limits.close_grace;
    while registry.live.load(Ordering::Acquire) > 0 && tokio::time::Instant::now() < deadline {
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
}

/// Errors of one incoming connection (not of the listener).
fn is_connection_error(e: &std::io::Error) -> bool {
    use std::io::ErrorKind::*;
    matches!(
        e.kind(),
        ConnectionRefused | ConnectionAborted | ConnectionReset
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cap_leaves_room_below_the_file_limit() {
        assert_eq!(connection_cap(10_000, Some(1024)), (1024 - 64) * 4 / 5);
        assert_eq!(connection_cap(500, Some(1024)), 500);
        assert_eq!(connection_cap(10_000, None), 10_000);
        assert_eq!(connection_cap(10_000, Some(10)), 1);
    }

    #[test]
    fn raising_the_file_limit_reaches_the_hard_limit() {
        let soft = raise_fd_limit().expect("readable on unix");
        let mut lim = libc::rlimit {
            rlim_cur: 0,
            rlim_max: 0,
        };
        // SAFETY: reads into the struct.
        assert_eq!(unsafe { libc::getrlimit(libc::RLIMIT_NOFILE, &mut lim) }, 0);
        assert_eq!(soft, super::rlim_u64(lim.rlim_cur));
        assert_eq!(lim.rlim_cur, lim.rlim_max);
    }
}
