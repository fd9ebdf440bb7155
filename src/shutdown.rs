//! The process's life, below the HTTP service and the job worker that both
//! run it: the panic hook that logs a panic once per place and window
//! ([`install_panic_hook`]), and the future that resolves at SIGINT or
//! SIGTERM ([`shutdown_signal`]).

/// Repeats of a panic at one source location within this window are
/// counted, not logged.
pub const PANIC_LOG_WINDOW: std::time::Duration = std::time::Duration::from_secs(60);

/// Per source location: the last line written, panics since it, lines written.
type PanicLog = std::collections::HashMap<String, (std::time::Instant, u64, u64)>;

static PANICS: std::sync::Mutex<Option<PanicLog>> = std::sync::Mutex::new(None);

/// Log lines written by the hook of [`install_panic_hook`] for panics at
/// `file:line` locations containing `location`.
pub fn panic_log_lines(location: &str) -> u64 {
    let seen = PANICS.lock().unwrap_or_else(|e| e.into_inner());
    seen.as_ref().map_or(0, |m| {
        m.iter()
            .filter(|(k, _)| k.contains(location))
            .map(|(_, v)| v.2)
            .sum()
    })
}

/// Installs the process panic hook (once; later calls do nothing): a panic
/// is one log line (message and location, no backtrace), and repeats at
/// the same location within [`PANIC_LOG_WINDOW`] are only counted (the
/// next line there says how many were left out). A request whose every
/// Monte-Carlo draw panics on the rayon pool writes one line, not one per
/// draw; the solve's `catch_unwind` turns it into one 500.
pub fn install_panic_hook() {
    use std::time::Instant;
    static INSTALL: std::sync::Once = std::sync::Once::new();
    INSTALL.call_once(|| {
        std::panic::set_hook(Box::new(|info| {
            let location = info.location().map_or_else(
                || "unknown".to_string(),
                |l| format!("{}:{}", l.file(), l.line()),
            );
            let now = Instant::now();
            let suppressed = {
                let mut seen = PANICS.lock().unwrap_or_else(|e| e.into_inner());
                let entry = seen
                    .get_or_insert_with(Default::default)
                    .entry(location.clone())
                    .or_insert((now, 0, 0));
                if entry.2 > 0 && now.duration_since(entry.0) < PANIC_LOG_WINDOW {
                    entry.1 += 1;
                    return;
                }
                let suppressed = entry.1;
                *entry = (now, 0, entry.2 + 1);
                suppressed
            };
            let message = info
                .payload()
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| info.payload().downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "(no message)".into());
            let message: String = message.chars().take(500).collect();
            tracing::error!(
                %location,
                suppressed_since_last = suppressed,
                "panic: {message} (repeats here within {} s are counted, not logged)",
                PANIC_LOG_WINDOW.as_secs()
            );
        }));
    });
}

/// Resolves at SIGINT or SIGTERM.
pub async fn shutdown_signal() {
    let ctrl_c = async {
        let _ = tokio::signal::ctrl_c().await;
    };
    #[cfg(unix)]
    let terminate = async {
        match tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate()) {
            Ok(mut s) => {
                s.recv().await;
            }
            Err(_) => std::future::pending::<()>().await,
        }
    };
    #[cfg(not(unix))]
    let terminate = std::future::pending::<()>();
    tokio::select! {
        _ = ctrl_c => tracing::info!("SIGINT received"),
        _ = terminate => tracing::info!("SIGTERM received"),
    }
}

#[cfg(test)]
mod tests {
    /// Ten thousand panics of one request on the rayon pool (every draw of
    /// a Monte-Carlo run) write one log line; the default hook writes one
    /// each (with a backtrace under RUST_BACKTRACE=1).
    #[test]
    fn a_panic_per_draw_is_logged_once() {
        use rayon::prelude::*;
        super::install_panic_hook();
        let here = format!("{}:{}", file!(), line!() + 4);
        let out = std::panic::catch_unwind(|| {
            (0..10_000)
                .into_par_iter()
                .map(|i: u32| -> u32 { panic!("draw {i} failed") })
                .sum::<u32>()
        });
        assert!(out.is_err());
        assert_eq!(super::panic_log_lines(&here), 1);
    }
}
