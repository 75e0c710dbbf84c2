//! What every handler file shares with the router: a [`Route`] (method,
//! path template, handler) and its constructors, which each resource's
//! `routes()` lists and `super::app` serves, and the shapes of an answer
//! (`links`, a created resource's `located` answer). A file of its own, so
//! the handlers import it and not the router that imports them.

use crate::service::AppState;
use axum::handler::Handler;
use axum::http::{header, Method};
use axum::response::{IntoResponse, Response};
use axum::routing::{on, MethodFilter, MethodRouter};

/// One route of the service: method, path template and handler. Each
/// resource module lists its own in `routes()`; [`super::app`] builds the router from
/// them and [`super::route_table`] reports the same list (a test checks it against
/// `openapi.yaml`), so no list of routes is kept by hand beside the router.
pub struct Route {
    /// The HTTP method.
    pub method: Method,
    /// The path template, with `{id}`-style parameters.
    pub path: &'static str,
    pub(super) handler: MethodRouter<AppState>,
}

/// A route for one method of a path.
pub(crate) fn route<H, T>(method: Method, path: &'static str, handler: H) -> Route
where
    H: Handler<T, AppState>,
    T: 'static,
{
    let filter = MethodFilter::try_from(method.clone()).expect("a standard HTTP method");
    Route {
        method,
        path,
        handler: on(filter, handler),
    }
}

/// A `GET` route.
pub(crate) fn get<H, T>(path: &'static str, handler: H) -> Route
where
    H: Handler<T, AppState>,
    T: 'static,
{
    route(Method::GET, path, handler)
}

/// A `POST` route.
pub(crate) fn post<H, T>(path: &'static str, handler: H) -> Route
where
    H: Handler<T, AppState>,
    T: 'static,
{
    route(Method::POST, path, handler)
}

/// A `DELETE` route.
pub(crate) fn delete<H, T>(path: &'static str, handler: H) -> Route
where
    H: Handler<T, AppState>,
    T: 'static,
{
    route(Method::DELETE, path, handler)
}

/// The `links` of a resource at `base`: `self`, and each other relation at
/// `base` followed by its suffix.
pub(crate) fn links(base: &str, relations: &[(&str, &str)]) -> serde_json::Value {
    let mut out = serde_json::Map::new();
    out.insert("self".into(), base.into());
    for (rel, suffix) in relations {
        out.insert((*rel).into(), format!("{base}{suffix}").into());
    }
    out.into()
}

/// The answer to a request that made a resource: `status` (201 Created, 202
/// Accepted), `Location: location` and the resource as JSON.
pub(crate) fn located<B: serde::Serialize>(
    status: axum::http::StatusCode,
    location: String,
    body: B,
) -> Response {
    (status, [(header::LOCATION, location)], axum::Json(body)).into_response()
}
