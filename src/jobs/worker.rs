//! `tetherplan worker`: a process that only runs jobs, from the same store
//! as the API (SQLite on one host, PostgreSQL on many). It registers in the
//! store's live workers, takes queued jobs and pending chunks until SIGTERM
//! or SIGINT, then stops: the running chunk or job is handed back to the
//! queue (or, if it ends first, its result is written), and the worker
//! leaves the live workers.

use std::sync::Arc;
use std::time::Duration;

use super::JobQueue;
use super::store::StoreConfig;
use crate::limits::Limits;

/// Everything `worker` needs.
#[derive(Clone, Debug)]
pub struct WorkerConfig {
    pub store: StoreConfig,
    pub job_threads: usize,
    pub limits: Limits,
}

/// Longest wait for the running work to stop after a signal.
pub const STOP_GRACE: Duration = Duration::from_secs(20);

/// Runs a worker process until SIGTERM/SIGINT.
pub fn run(config: WorkerConfig) -> Result<(), Box<dyn std::error::Error>> {
    crate::shutdown::install_panic_hook();
    let store = config
        .store
        .open()
        .map_err(|e| format!("cannot open the job store {}: {e}", config.store.describe()))?;
    let queue = Arc::new(JobQueue::with_store(
        store,
        config.job_threads,
        config.limits.clone(),
    ));
    let worker = queue.spawn_worker_as("worker");
    tracing::info!(
        store = %config.store.describe(),
        threads = config.job_threads,
        id = queue.store.worker().as_str(),
        "worker started"
    );
    {
        use std::io::Write;
        let mut out = std::io::stdout().lock();
        let _ = writeln!(out, "tetherplan worker {}", queue.store.worker().as_str())
            .and_then(|()| out.flush());
    }
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()?;
    runtime.block_on(crate::shutdown::shutdown_signal());
    tracing::info!("stopping: the running work ends or goes back to the queue");
    queue.shutdown();
    let (done, finished) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = done.send(worker.join().is_ok());
    });
    if finished.recv_timeout(STOP_GRACE).is_err() {
        tracing::warn!("the worker did not stop in time; its work is handed back");
    }
    let requeued = queue.store.release_all()?;
    let _ = queue.store.worker_leave();
    tracing::info!(requeued, "worker stopped");
    Ok(())
}
