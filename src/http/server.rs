//! The service's HTTP/1 connection loop over [`ServiceListener`], in place
//! of `axum::serve`, which sets no timer: with it a client that opens a
//! connection and never finishes its request head holds it, and its file
//! descriptor, for ever, and a few hundred such clients take the service
//! down. Here:
//! - a request head must arrive within [`ServerSettings::header_read_timeout`]
//!   of the connection's start (or of the previous answer on a kept-alive
//!   connection), else hyper closes the connection; a connection accepted
//!   while more than half the cap is open gets a fifth of that (slow clients
//!   crowding the service are shed faster, a normal client sends its head in
//!   milliseconds);
//! - a request body must keep arriving (`Limits::body_pause`, a layer of
//!   the router);
//! - at most [`ServerSettings::max_connections`] connections are open: the
//!   loop accepts no more until one closes, so the process stays below its
//!   file-descriptor limit and keeps descriptors for the database;
//! - on shutdown it stops accepting, lets every connection finish the request
//!   it is serving and waits for them.

use super::listener::ServiceListener;
use axum::Router;
use hyper_util::rt::{TokioIo, TokioTimer};
use hyper_util::service::TowerToHyperService;
use std::future::Future;
use std::sync::Arc;
use std::time::Duration;
use tokio::sync::{watch, Semaphore};

/// Connection limits of the server.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ServerSettings {
    /// Longest wait for a request head.
    pub header_read_timeout: Duration,
    /// Most connections open at once.
    pub max_connections: usize,
}

/// The default wait for a request head.
pub const HEADER_READ_TIMEOUT: Duration = Duration::from_secs(10);
/// File descriptors kept free of connections (database, files, logs).
const DESCRIPTORS_KEPT: usize = 64;
/// The default cap on connections, where the descriptor limit allows it.
const MAX_CONNECTIONS: usize = 4096;

impl Default for ServerSettings {
    fn default() -> Self {
        ServerSettings {
            header_read_timeout: HEADER_READ_TIMEOUT,
            max_connections: connection_cap(descriptor_limit()),
        }
    }
}

/// The process's soft limit on open file descriptors (`None`: unknown).
pub fn descriptor_limit() -> Option<usize> {
    #[cfg(unix)]
    {
        let mut l = libc::rlimit {
            rlim_cur: 0,
            rlim_max: 0,
        };
        // SAFETY: getrlimit writes the struct it is given.
        if unsafe { libc::getrlimit(libc::RLIMIT_NOFILE, &mut l) } == 0 {
            return Some(usize::try_from(l.rlim_cur).unwrap_or(usize::MAX));
        }
    }
    None
}

/// Connections allowed under a descriptor limit: all but [`DESCRIPTORS_KEPT`]
/// of them (at least 16), and at most [`MAX_CONNECTIONS`].
pub fn connection_cap(descriptors: Option<usize>) -> usize {
    match descriptors {
        Some(n) => n
            .saturating_sub(DESCRIPTORS_KEPT)
            .clamp(16, MAX_CONNECTIONS),
        None => MAX_CONNECTIONS,
    }
}

/// Serves `router` on `listener` until `shutdown` completes, then lets the
/// open connections finish their requests.
pub async fn serve(
    mut listener: ServiceListener,
    router: Router,
    settings: ServerSettings,
    shutdown: impl Future<Output = ()> + Send,
) {
    let slots = Arc::new(Semaphore::new(settings.max_connections.max(1)));
    // Each connection holds a receiver: the sender sees them all gone.
    let (stop_tx, stop_rx) = watch::channel(false);
    let mut shutdown = std::pin::pin!(shutdown);
    let mut full = false;
    loop {
        let slot = tokio::select! {
            s = slots.clone().acquire_owned() => s.expect("the semaphore is never closed"),
            _ = &mut shutdown => break,
        };
        if full {
            tracing::info!("connections below the cap again; accepting");
            full = false;
        }
        let (io, _addr) = tokio::select! {
            c = axum::serve::Listener::accept(&mut listener) => c,
            _ = &mut shutdown => break,
        };
        if slots.available_permits() == 0 {
            full = true;
            tracing::warn!(
                max = settings.max_connections,
                "the most connections this service holds are open; new ones wait"
            );
        }
        let service = TowerToHyperService::new(router.clone());
        let mut stop = stop_rx.clone();
        let crowded = slots.available_permits() < settings.max_connections / 2;
        let header_timeout = if crowded {
            settings.header_read_timeout / 5
        } else {
            settings.header_read_timeout
        };
        tokio::spawn(async move {
            let _slot = slot;
            let mut builder = hyper::server::conn::http1::Builder::new();
            builder
                .timer(TokioTimer::new())
                .header_read_timeout(header_timeout);
            let conn = builder
                .serve_connection(TokioIo::new(io), service)
                .with_upgrades();
            let mut conn = std::pin::pin!(conn);
            tokio::select! {
                r = conn.as_mut() => {
                    if let Err(e) = r {
                        tracing::debug!(error = %e, "connection ended");
                    }
                }
                _ = stop.changed() => {
                    conn.as_mut().graceful_shutdown();
                    let _ = conn.await;
                }
            }
            drop(stop);
        });
    }
    drop(stop_rx);
    let _ = stop_tx.send(true);
    stop_tx.closed().await;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cap_keeps_descriptors_for_the_rest_and_stays_in_bounds() {
        assert_eq!(connection_cap(Some(256)), 192);
        assert_eq!(connection_cap(Some(1024)), 960);
        assert_eq!(connection_cap(Some(1 << 20)), MAX_CONNECTIONS);
        assert_eq!(connection_cap(Some(40)), 16);
        assert_eq!(connection_cap(None), MAX_CONNECTIONS);
    }
}
