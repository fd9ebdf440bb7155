//! The handlers' shared state: the job queue, the limits, the permits of
//! the synchronous solves and the API tokens.

use std::sync::Arc;

use tokio::sync::Semaphore;

use crate::api::auth;
use crate::config::Limits;
use crate::jobs::JobQueue;

/// Shared state of the handlers.
#[derive(Clone)]
pub struct AppState {
    pub queue: Arc<JobQueue>,
    pub limits: Limits,
    pub(crate) solves: Arc<Semaphore>,
    /// API tokens (none: open).
    pub tokens: Arc<auth::Tokens>,
}

impl AppState {
    pub fn new(queue: Arc<JobQueue>) -> Self {
        let limits = queue.limits().clone();
        let solves = Arc::new(Semaphore::new(limits.max_in_flight));
        Self {
            queue,
            limits,
            solves,
            tokens: Arc::new(auth::Tokens::default()),
        }
    }

    /// The same, requiring one of `tokens` on every `/api` route.
    pub fn with_tokens(mut self, tokens: &[String]) -> Self {
        self.tokens = Arc::new(auth::Tokens::new(tokens));
        self
    }
}
