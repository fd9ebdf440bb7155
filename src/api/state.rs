//! The handlers' shared state: the job queue, the limits, the permits of
//! the synchronous solves and the priced work in flight, the API tokens, the live flights and the forecast source.

use std::sync::Arc;

use tokio::sync::Semaphore;

use crate::api::auth;
use crate::api::flights::hub::FlightHub;
use crate::config::{ForecastSource, Limits};
use crate::contract::price::InFlight;
use crate::jobs::JobQueue;

/// Shared state of the handlers.
#[derive(Clone)]
pub struct AppState {
    pub queue: Arc<JobQueue>,
    pub limits: Limits,
    pub(crate) solves: Arc<Semaphore>,
    /// Priced synchronous work running now ([`crate::contract::price`]).
    pub(crate) priced: Arc<InFlight>,
    /// API tokens (none: open).
    pub tokens: Arc<auth::Tokens>,
    /// Live flights (in memory until [`Self::with_flights`]).
    pub flights: Arc<FlightHub>,
    /// Where `GET /api/v1/forecast` fetches (none: not configured).
    pub forecast: Option<Arc<ForecastSource>>,
}

impl AppState {
    pub fn new(queue: Arc<JobQueue>) -> Self {
        let limits = queue.limits().clone();
        let solves = Arc::new(Semaphore::new(limits.max_in_flight));
        Self {
            queue,
            limits,
            solves,
            priced: Arc::new(InFlight::default()),
            tokens: Arc::new(auth::Tokens::default()),
            flights: Arc::new(FlightHub::in_memory()),
            forecast: None,
        }
    }

    /// The same, keeping its flights in `hub`.
    pub fn with_flights(mut self, hub: FlightHub) -> Self {
        self.flights = Arc::new(hub);
        self
    }

    /// The same, fetching today's forecast from `source`.
    pub fn with_forecast_source(mut self, source: Option<ForecastSource>) -> Self {
        self.forecast = source.map(Arc::new);
        self
    }

    /// The same, requiring one of `tokens` on every `/api` route.
    pub fn with_tokens(mut self, tokens: &[String]) -> Self {
        self.tokens = Arc::new(auth::Tokens::new(tokens));
        self
    }
}
