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
//!   cannot lock out new clients: the server keeps answering. A connection
//!   whose task has not run yet is not chosen (in a burst of accepts it
//!   would be closed before reading the request its client sent), and at
//!   the cap the accept loop first lets the connection tasks run, so that
//!   connections whose clients have gone are counted out (a reconnect storm
//!   made `/healthz` fail 7 times in 80). Past the cap
//!   by a quarter (a burst accepted before its tasks ran, or closing
//!   takes a moment), the loop asks the oldest to close and stops
//!   accepting for up to [`CEILING_PAUSE`] while they go (new clients wait
//!   in the kernel's backlog); only when none is on its way out is a new
//!   connection closed at once, rather than run the process out of files.
//!   A connection asked to close first reads a request its client has
//!   already sent, and answers it. (Without these, 60 slow bodies at a cap
//!   of 20 held the count at the ceiling until their deadline, and a probe
//!   that connected just before a burst lost its request: `/healthz`
//!   failed about 1 time in 10 under load.)
//! * **Accept errors** (out of files, aborted handshakes) never end the
//!   loop: it pauses briefly and goes on.
//!
//! HTTP/1.1 only: browsers never speak cleartext HTTP/2, and one protocol
//! keeps the timeouts above exhaustive.

use std::collections::VecDeque;
use std::future::Future;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Duration;

use std::pin::Pin;
use std::sync::Mutex;
use std::task::{Context, Poll};
use std::time::Instant;

use axum::Router;
use axum::body::{Body, Bytes};
use axum::http::{Request, Response, StatusCode, header};
use axum::response::IntoResponse;
use hyper::body::{Frame, Incoming, SizeHint};
use hyper::server::conn::http1;
use hyper_util::rt::{TokioIo, TokioTimer};
use hyper_util::service::TowerToHyperService;

use crate::api::error::{ApiError, BodyRefusal};
use tokio::net::TcpListener;
use tokio::sync::{Notify, OwnedSemaphorePermit, Semaphore, watch};

/// Times the accept loop yields to the connection tasks when the cap is
/// reached, before it counts the connections open.
const PRESSURE_YIELDS: usize = 8;

/// How long the accept loop waits, far past the cap, for connections asked
/// to close to go before it closes a new one unread.
const CEILING_PAUSE: Duration = Duration::from_millis(100);

/// File descriptors kept free of connections (database, WAL, job threads,
/// logs, the listener).
pub const RESERVED_FDS: u64 = 64;

pub use crate::limits::ConnectionLimits;

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
    /// Open connections, oldest first: id, close request, and whether its
    /// task has started (read anything).
    open: std::sync::Mutex<VecDeque<(u64, Arc<Notify>, Arc<AtomicBool>)>>,
    /// Gives the heap back a moment after connections close.
    trimmer: crate::api::memory::Trimmer,
}

impl Registry {
    fn forget(&self, id: u64) {
        self.trimmer.closed();
        let mut open = self.open.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(i) = open.iter().position(|(c, ..)| *c == id) {
            open.remove(i);
        }
    }

    /// Whether the count of live connections is about to fall: some were
    /// asked to close and have not ended, or some have not started (and
    /// can be asked once they have).
    fn closing(&self) -> bool {
        let open = self.open.lock().unwrap_or_else(|e| e.into_inner());
        self.live.load(Ordering::Acquire) > open.len()
            || open
                .iter()
                .any(|(_, _, started)| !started.load(Ordering::Acquire))
    }

    /// Asks the oldest connections to close until at most `cap` remain
    /// open. A connection whose task has not started yet is passed over: it
    /// has not had a chance to read the request its client already sent
    /// (in a burst of accepts it would otherwise be closed unread).
    fn shed_to(&self, cap: usize) -> usize {
        let mut open = self.open.lock().unwrap_or_else(|e| e.into_inner());
        let mut shed = 0;
        let mut i = 0;
        while open.len() > cap && i < open.len() {
            if open[i].2.load(Ordering::Acquire) {
                if let Some((_, stop, _)) = open.remove(i) {
                    stop.notify_one();
                    shed += 1;
                }
            } else {
                i += 1;
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
    crate::shutdown::install_panic_hook();
    let registry = Arc::new(Registry {
        live: AtomicUsize::new(0),
        open: std::sync::Mutex::new(VecDeque::new()),
        trimmer: crate::api::memory::Trimmer::default(),
    });
    let trimming = tokio::spawn(registry.trimmer.clone().run());
    let hard_ceiling = cap.saturating_add(cap / 4).max(cap + 1);
    let (stop_all, stopping) = watch::channel(false);
    let mut builder = http1::Builder::new();
    builder
        .timer(TokioTimer::new())
        .header_read_timeout(limits.header_timeout)
        .keep_alive(true);
    let builder = Arc::new(builder);
    let budget = Arc::new(Semaphore::new(
        limits.body_budget_bytes.clamp(1, Semaphore::MAX_PERMITS),
    ));
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
        // At the cap, let the connection tasks run first (those whose
        // clients have gone end, those just accepted read their requests)
        // rather than count connections nobody has polled yet.
        for _ in 0..PRESSURE_YIELDS {
            if registry.live.load(Ordering::Acquire) < cap {
                break;
            }
            tokio::task::yield_now().await;
        }
        // Far past the cap (a burst accepted before its tasks ran), ask the
        // oldest to close and stop accepting for a moment (the kernel's
        // backlog holds new clients) while they go; a new connection is
        // closed unread only when none is on its way out.
        let paused_until = tokio::time::Instant::now() + CEILING_PAUSE;
        while registry.live.load(Ordering::Acquire) >= hard_ceiling
            && tokio::time::Instant::now() < paused_until
        {
            registry.shed_to(cap);
            if !registry.closing() {
                break;
            }
            tokio::time::sleep(Duration::from_millis(1)).await;
        }
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
        let started = Arc::new(AtomicBool::new(false));
        registry.live.fetch_add(1, Ordering::AcqRel);
        registry
            .open
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .push_back((id, stop.clone(), started.clone()));
        let shed = registry.shed_to(cap);
        if shed > 0 {
            tracing::debug!(shed, cap, "connection cap reached: closing the oldest");
        }
        let guard = LiveGuard(registry.clone(), id);
        let builder = builder.clone();
        let conn_state = Arc::new(ConnState::new());
        let service = ConnService {
            app: app.clone(),
            state: conn_state.clone(),
            budget: budget.clone(),
            max_body_bytes: limits.max_body_bytes,
        };
        let mut stopping = stopping.clone();
        let limits = limits.clone();
        tokio::spawn(async move {
            let _guard = guard;
            started.store(true, Ordering::Release);
            let conn = builder.serve_connection(TokioIo::new(stream), service);
            tokio::pin!(conn);
            tokio::select! {
                r = conn.as_mut() => {
                    if let Err(e) = r {
                        tracing::debug!("connection ended: {e}");
                    }
                    return;
                }
                _ = stop.notified() => {}
                _ = stopping.wait_for(|s| *s) => {}
                why = conn_state.past_deadline(&limits) => {
                    tracing::debug!("connection dropped: {why}");
                    return;
                }
            }
            // Asked to close. A request head the client has already sent
            // is read first (one poll): hyper closes a connection that has
            // read nothing at once, and a client that connected just before
            // a burst would otherwise lose the request it sent.
            if conn_state.phase() == Phase::Idle
                && std::future::poll_fn(|cx| Poll::Ready(conn.as_mut().poll(cx).is_ready())).await
            {
                return;
            }
            // A body still arriving is dropped, not waited for: it cannot
            // be answered before it ends.
            if conn_state.phase() == Phase::Body {
                tracing::debug!("connection asked to close while its body arrives: dropped");
                return;
            }
            conn.as_mut().graceful_shutdown();
            let _ = tokio::time::timeout(limits.close_grace, async {
                tokio::select! {
                    _ = conn.as_mut() => {}
                    _ = conn_state.past_deadline(&limits) => {}
                }
            })
            .await;
        });
    }
    drop(listener);
    trimming.abort();
    let _ = stop_all.send(true);
    let deadline = tokio::time::Instant::now() + limits.close_grace;
    while registry.live.load(Ordering::Acquire) > 0 && tokio::time::Instant::now() < deadline {
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
}

/// Where a connection is in its current exchange.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Phase {
    /// Waiting for a request head (hyper's header timeout applies).
    Idle,
    /// A request body is arriving.
    Body,
    /// The answer is being computed (the solve timeout applies).
    Handling,
    /// The answer is being written.
    Writing,
}

/// The phase of one connection and when it began.
pub(crate) struct ConnState {
    phase: Mutex<(Phase, Instant)>,
    /// Signalled at every change of phase.
    changed: Notify,
}

impl ConnState {
    fn new() -> Self {
        Self {
            phase: Mutex::new((Phase::Idle, Instant::now())),
            changed: Notify::new(),
        }
    }

    fn set(&self, phase: Phase) {
        *self.phase.lock().unwrap_or_else(|e| e.into_inner()) = (phase, Instant::now());
        self.changed.notify_one();
    }

    /// Moves from `from` to `to` (nothing when in another phase).
    fn leave(&self, from: Phase, to: Phase) {
        let mut p = self.phase.lock().unwrap_or_else(|e| e.into_inner());
        if p.0 == from {
            *p = (to, Instant::now());
            drop(p);
            self.changed.notify_one();
        }
    }

    /// Resolves when the connection is past the deadline of its phase
    /// (no timer runs while it is idle or computing).
    async fn past_deadline(&self, limits: &ConnectionLimits) -> &'static str {
        loop {
            let changed = self.changed.notified();
            if let Some(why) = self.overdue(limits) {
                return why;
            }
            let (phase, since) = *self.phase.lock().unwrap_or_else(|e| e.into_inner());
            let deadline = match phase {
                Phase::Body => Some(since + limits.body_deadline),
                Phase::Writing => Some(since + limits.write_deadline),
                Phase::Idle | Phase::Handling => None,
            };
            match deadline {
                Some(at) => {
                    tokio::select! {
                        _ = changed => {}
                        _ = tokio::time::sleep_until(at.into()) => {}
                    }
                }
                None => changed.await,
            }
        }
    }

    fn phase(&self) -> Phase {
        self.phase.lock().unwrap_or_else(|e| e.into_inner()).0
    }

    /// Why the connection must be dropped now, if it must.
    fn overdue(&self, limits: &ConnectionLimits) -> Option<&'static str> {
        let (phase, since) = *self.phase.lock().unwrap_or_else(|e| e.into_inner());
        let age = since.elapsed();
        match phase {
            Phase::Body if age > limits.body_deadline => Some("request body past its deadline"),
            Phase::Writing if age > limits.write_deadline => {
                Some("answer not read within its deadline")
            }
            _ => None,
        }
    }
}

/// The service of one connection: the application, with each request's
/// body counted against the byte budget and the connection's phase kept.
#[derive(Clone)]
struct ConnService {
    app: Router,
    state: Arc<ConnState>,
    budget: Arc<Semaphore>,
    max_body_bytes: usize,
}

impl hyper::service::Service<Request<Incoming>> for ConnService {
    type Response = Response<Body>;
    type Error = std::convert::Infallible;
    type Future =
        Pin<Box<dyn Future<Output = Result<Response<Body>, std::convert::Infallible>> + Send>>;

    fn call(&self, req: Request<Incoming>) -> Self::Future {
        let this = self.clone();
        Box::pin(async move {
            let declared = req
                .headers()
                .get(header::CONTENT_LENGTH)
                .and_then(|v| v.to_str().ok())
                .and_then(|v| v.trim().parse::<u64>().ok());
            if declared.is_some_and(|n| n > this.max_body_bytes as u64) {
                // Refused from the head alone: no `100 Continue`, no byte read.
                this.state.set(Phase::Writing);
                let resp = ApiError::new(
                    StatusCode::PAYLOAD_TOO_LARGE,
                    "payload_too_large",
                    Some("body"),
                    format!(
                        "Content-Length {} is larger than the {} bytes the server accepts (see --max-body-bytes)",
                        declared.unwrap_or(0),
                        this.max_body_bytes
                    ),
                )
                .into_response();
                let mut resp = crate::api::guard::security_headers(resp).await;
                resp.headers_mut().insert(
                    header::CONNECTION,
                    header::HeaderValue::from_static("close"),
                );
                return Ok(resp.map(|b| Body::new(WatchedBody::new(b, this.state.clone()))));
            }
            let held = Arc::new(Mutex::new(None::<OwnedSemaphorePermit>));
            let ended = hyper::body::Body::is_end_stream(req.body());
            this.state
                .set(if ended { Phase::Handling } else { Phase::Body });
            let req = req.map(|b| {
                Body::new(GuardedBody {
                    inner: b,
                    state: this.state.clone(),
                    budget: this.budget.clone(),
                    held: held.clone(),
                })
            });
            let app = TowerToHyperService::new(this.app.clone());
            let resp = match hyper::service::Service::call(&app, req).await {
                Ok(r) => r,
                Err(never) => match never {},
            };
            // The request's bytes are freed with the handler: the budget
            // gets them back now (the handler's copy is gone too).
            drop(held.lock().unwrap_or_else(|e| e.into_inner()).take());
            this.state.set(Phase::Writing);
            Ok(resp.map(|b| Body::new(WatchedBody::new(b, this.state.clone()))))
        })
    }
}

/// A request body counted against the byte budget; its end (or drop)
/// ends the connection's body phase.
struct GuardedBody {
    inner: Incoming,
    state: Arc<ConnState>,
    budget: Arc<Semaphore>,
    held: Arc<Mutex<Option<OwnedSemaphorePermit>>>,
}

impl hyper::body::Body for GuardedBody {
    type Data = Bytes;
    type Error = Box<dyn std::error::Error + Send + Sync>;

    fn poll_frame(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
    ) -> Poll<Option<Result<Frame<Bytes>, Self::Error>>> {
        match Pin::new(&mut self.inner).poll_frame(cx) {
            Poll::Pending => Poll::Pending,
            Poll::Ready(None) => {
                self.state.leave(Phase::Body, Phase::Handling);
                Poll::Ready(None)
            }
            Poll::Ready(Some(Err(e))) => Poll::Ready(Some(Err(Box::new(e)))),
            Poll::Ready(Some(Ok(frame))) => {
                if let Some(data) = frame.data_ref() {
                    let n = u32::try_from(data.len()).unwrap_or(u32::MAX);
                    if n > 0 {
                        let Ok(permit) = self.budget.clone().try_acquire_many_owned(n) else {
                            return Poll::Ready(Some(Err(Box::new(BodyRefusal::Busy))));
                        };
                        let mut held = self.held.lock().unwrap_or_else(|e| e.into_inner());
                        match held.as_mut() {
                            Some(p) => p.merge(permit),
                            None => *held = Some(permit),
                        }
                    }
                }
                if self.inner.is_end_stream() {
                    self.state.leave(Phase::Body, Phase::Handling);
                }
                Poll::Ready(Some(Ok(frame)))
            }
        }
    }

    fn is_end_stream(&self) -> bool {
        self.inner.is_end_stream()
    }

    fn size_hint(&self) -> SizeHint {
        self.inner.size_hint()
    }
}

impl Drop for GuardedBody {
    fn drop(&mut self) {
        self.state.leave(Phase::Body, Phase::Handling);
    }
}

/// An answer being written; its end (or drop) makes the connection idle.
struct WatchedBody {
    inner: Body,
    state: Arc<ConnState>,
}

impl WatchedBody {
    fn new(inner: Body, state: Arc<ConnState>) -> Self {
        Self { inner, state }
    }
}

impl hyper::body::Body for WatchedBody {
    type Data = Bytes;
    type Error = axum::Error;

    fn poll_frame(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
    ) -> Poll<Option<Result<Frame<Bytes>, Self::Error>>> {
        let r = Pin::new(&mut self.inner).poll_frame(cx);
        if let Poll::Ready(None) = r {
            self.state.leave(Phase::Writing, Phase::Idle);
        }
        r
    }

    fn is_end_stream(&self) -> bool {
        self.inner.is_end_stream()
    }

    fn size_hint(&self) -> SizeHint {
        self.inner.size_hint()
    }
}

impl Drop for WatchedBody {
    fn drop(&mut self) {
        self.state.leave(Phase::Writing, Phase::Idle);
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
