//! The HTTP API (axum): routes under `/v1`, JSON in millimetres and degrees,
//! errors as `application/problem+json`, described by `openapi.yaml`.
//!
//! - [`app`] builds the router over an [`AppState`] (database, API keys,
//!   bounded job workers, solver caches); tests drive it in-process.
//! - When API keys are configured, each route needs a key of a role
//!   (`read` ⊆ `operate` ⊆ `admin`, sent as `Authorization: Bearer <key>`),
//!   decided by one table in [`auth`]; `open_reads` leaves GETs open. Keys
//!   are never logged.
//! - CPU-heavy work runs off the async runtime: calibrations on a pool of
//!   `workers` blocking tasks, solve batches above [`SMALL_SOLVE_MAX`] targets
//!   on the blocking pool (rayon inside), bounded by a semaphore. Both queues
//!   are bounded: when full, the service answers 429 with `Retry-After`
//!   ([`limits`]).
//! - Request sizes, list pages and job budgets are limited by [`Limits`].

use axum::extract::{DefaultBodyLimit, Request, State};
use axum::http::{header, HeaderValue, Method};
use axum::middleware;
use axum::response::{IntoResponse, Response};
use axum::Router;
use tower_http::catch_panic::CatchPanicLayer;
use tower_http::trace::{DefaultMakeSpan, DefaultOnFailure, DefaultOnResponse, TraceLayer};
use tracing::Level;

pub mod auth;
pub mod calibrations;
pub mod cell;
pub mod cell_fit;
pub mod checks;
pub mod console;
pub mod error;
pub mod extract;
pub mod fit_requests;
pub mod input;
pub mod iso9283;
pub mod iso9283_plan;

pub mod listener;
pub mod plans;
pub mod positioners;
pub mod predict;
pub mod programs;
pub mod record;
pub mod robots;
mod routing;
pub mod server;
pub mod sets;
pub mod solve;
pub mod solve_columns;
pub mod station_sets;
pub mod target_values;
pub mod tracks;
pub mod turntables;
pub mod versions;

pub use crate::service::limits::{
    Admission, Limits, Ticket, BODY_LIMIT_BYTES, PAYLOAD_MAX_KG, SMALL_SOLVE_MAX,
};
pub use crate::service::{AppState, RobotContext, ServiceConfig};
pub use error::{ApiError, Problem, PROBLEM_JSON};
pub use extract::{ApiJson, ApiPath, ApiQuery};
pub use listener::ServiceListener;
pub use routing::Route;
pub(crate) use routing::{delete, get, links, located, post, route};

/// The text of `openapi.yaml`, served at `/openapi.yaml`.
pub const OPENAPI_YAML: &str = include_str!("../../openapi.yaml");

/// Every route of the service, resource by resource.
fn routes() -> Vec<Route> {
    let mut all = vec![
        get("/healthz", healthz),
        get("/readyz", readyz),
        get("/openapi.yaml", openapi),
    ];
    all.extend(robots::routes());
    all.extend(sets::routes());
    all.extend(calibrations::routes());
    all.extend(versions::routes());
    all.extend(solve::routes());
    all.extend(predict::routes());
    all.extend(cell::routes());
    all.extend(cell_fit::routes());
    all.extend(programs::routes());
    all.extend(plans::routes());
    all.extend(checks::routes());
    all.extend(record::routes());
    all.extend(iso9283::routes());
    all.extend(tracks::routes());
    all.extend(station_sets::routes());
    all.extend(positioners::routes());
    all.extend(turntables::routes());
    all.extend(fit_requests::routes());
    all
}

/// (method, path template) of every route the router serves.
pub fn route_table() -> Vec<(Method, &'static str)> {
    routes().into_iter().map(|r| (r.method, r.path)).collect()
}

/// (method, path template, access) of every JSON API route (see [`auth::access`]).
pub fn route_access() -> Vec<(Method, &'static str, auth::Access)> {
    routes()
        .into_iter()
        .map(|r| {
            let access = auth::access(&r.method, r.path);
            (r.method, r.path, access)
        })
        .collect()
}

/// The router of the service: the JSON API and the web console.
pub fn app(state: AppState) -> Router {
    let mut router = Router::new();
    for r in routes().into_iter().chain(console::routes()) {
        // Each route checks the key its access needs; routes of one path with
        // different methods merge into one.
        let access = auth::access(&r.method, r.path);
        let guard = middleware::from_fn_with_state((state.clone(), access), auth::guard);
        router = router.route(r.path, r.handler.layer(guard));
    }
    router
        .fallback(not_found)
        .method_not_allowed_fallback(method_not_allowed)
        .layer(DefaultBodyLimit::max(state.limits().body_bytes))
        // A body that stops arriving fails its request (the head's own
        // timeout is the server's: `server.rs`).
        .layer(middleware::map_request_with_state(
            state.limits().body_pause,
            body_timeout,
        ))
        .layer(CatchPanicLayer::custom(panic_response))
        .layer(middleware::map_response(safe_to_open))
        .layer(
            // Method, path, status and latency; never headers (they may hold keys).
            TraceLayer::new_for_http()
                .make_span_with(DefaultMakeSpan::new().level(Level::DEBUG))
                .on_request(())
                .on_response(DefaultOnResponse::new().level(Level::DEBUG))
                .on_failure(DefaultOnFailure::new().level(Level::WARN)),
        )
        .with_state(state)
}

/// Bounds the pause between two pieces of a request body by `pause`
/// (`Limits::body_pause`): a client that stops sending mid-body gets its
/// request failed and its connection freed.
async fn body_timeout(State(pause): State<std::time::Duration>, req: Request) -> Request {
    req.map(|b| axum::body::Body::new(tower_http::timeout::TimeoutBody::new(pause, b)))
}

/// The policy of every answer that does not state its own (the console's
/// pages do): a document may style itself and show inline images, nothing
/// else — no script, no fetch, no form, no frame around it. The calibration
/// report is such a document; downloads and JSON need even less.
const DOCUMENT_CSP: &str = "default-src 'none'; style-src 'unsafe-inline'; img-src data:; \
     base-uri 'none'; form-action 'none'; frame-ancestors 'none'";

/// Headers that keep every answer safe to open in a browser: no MIME
/// sniffing, no framing, and [`DOCUMENT_CSP`] unless the handler set a policy.
async fn safe_to_open(mut res: Response) -> Response {
    let h = res.headers_mut();
    h.insert(
        header::X_CONTENT_TYPE_OPTIONS,
        HeaderValue::from_static("nosniff"),
    );
    h.entry(header::X_FRAME_OPTIONS)
        .or_insert(HeaderValue::from_static("DENY"));
    h.entry(header::CONTENT_SECURITY_POLICY)
        .or_insert(HeaderValue::from_static(DOCUMENT_CSP));
    res
}

async fn healthz(State(state): State<AppState>) -> Result<Response, ApiError> {
    crate::service::health(&state).await?;
    Ok(axum::Json(serde_json::json!({
        "status": "ok",
        "version": env!("CARGO_PKG_VERSION"),
    }))
    .into_response())
}

/// Readiness for a load balancer (see [`crate::service::ready`]).
async fn readyz(State(state): State<AppState>) -> Result<Response, ApiError> {
    crate::service::ready(&state).await?;
    Ok(axum::Json(serde_json::json!({
        "status": "ok",
        "version": env!("CARGO_PKG_VERSION"),
    }))
    .into_response())
}

async fn openapi() -> Response {
    (
        [(header::CONTENT_TYPE, "application/yaml; charset=utf-8")],
        OPENAPI_YAML,
    )
        .into_response()
}

async fn not_found(req: Request) -> ApiError {
    ApiError::NotFound(format!(
        "no route for {} {}; the routes are listed in /openapi.yaml",
        req.method(),
        req.uri().path()
    ))
}

async fn method_not_allowed(req: Request) -> ApiError {
    ApiError::MethodNotAllowed(format!(
        "{} is not allowed on {}; see /openapi.yaml for the methods of this route",
        req.method(),
        req.uri().path()
    ))
}

/// A handler that panics answers a problem+json 500 instead of dropping the
/// connection (the panic message is logged, not sent).
fn panic_response(panic: Box<dyn std::any::Any + Send + 'static>) -> Response {
    let what = panic
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| panic.downcast_ref::<String>().cloned())
        .unwrap_or_default();
    ApiError::Internal(format!("request handler panicked: {what}")).into_response()
}

#[cfg(test)]
mod tests {
    use axum::body::Body;
    use axum::http::{Request, StatusCode};
    use tower::ServiceExt;

    /// A panicking handler answers a problem+json 500 without the panic text.
    #[tokio::test]
    async fn a_panic_becomes_a_problem_500() {
        async fn boom() -> &'static str {
            panic!("secret detail")
        }
        let app = axum::Router::new()
            .route("/boom", axum::routing::get(boom))
            .layer(tower_http::catch_panic::CatchPanicLayer::custom(
                super::panic_response,
            ));
        let res = app
            .oneshot(Request::get("/boom").body(Body::empty()).unwrap())
            .await
            .unwrap();
        assert_eq!(res.status(), StatusCode::INTERNAL_SERVER_ERROR);
        assert_eq!(res.headers()["content-type"], super::error::PROBLEM_JSON);
        let body = axum::body::to_bytes(res.into_body(), 1 << 16)
            .await
            .unwrap();
        let text = String::from_utf8(body.to_vec()).unwrap();
        assert!(text.contains("\"status\":500"), "{text}");
        assert!(!text.contains("secret detail"), "{text}");
    }
}
