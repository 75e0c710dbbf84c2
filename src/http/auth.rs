//! Which role each route needs, and the check of `Authorization: Bearer <key>`.
//!
//! [`access`] is the one table: probes and the API description are public;
//! every other GET needs `read`; the computations an operator runs on the
//! active model ([`OPERATE`]) need `operate`; every other write needs `admin`.
//! [`super::app`] wraps each route in [`guard`] with the access the table
//! gives its (method, path template). Without keys configured every route is
//! open; with `open_reads`, routes that need `read` are open too.

use super::{ApiError, AppState};
use crate::service::keys::Role;
use axum::extract::{Request, State};
use axum::http::{header, Method};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};

/// What a route needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Access {
    /// Open to anyone, keys or not (health probes, `/openapi.yaml`).
    Public,
    /// A key of this role or a higher one, when keys are configured.
    Role(Role),
}

/// GET routes any caller may use: load-balancer probes and the API description.
pub const PUBLIC: &[&str] = &["/healthz", "/readyz", "/openapi.yaml"];

/// POST routes of `operate`: they compute on the robot's models or score
/// check poses, and change no model, set or cell item.
pub const OPERATE: &[&str] = &[
    "/v1/robots/{id}/solve",
    "/v1/robots/{id}/predict",
    "/v1/robots/{id}/programs/filter",
    "/v1/robots/{id}/measurement-plans",
    "/v1/robots/{id}/checks",
    "/v1/robots/{id}/compare",
    "/v1/iso9283",
    "/v1/iso9283/csv",
    "/v1/robots/{id}/iso9283/plan",
];

/// The access a route (method and path template, as in `openapi.yaml`) needs.
pub fn access(method: &Method, template: &str) -> Access {
    let read = *method == Method::GET || *method == Method::HEAD;
    if read && PUBLIC.contains(&template) {
        Access::Public
    } else if read {
        Access::Role(Role::Read)
    } else if *method == Method::POST && OPERATE.contains(&template) {
        Access::Role(Role::Operate)
    } else {
        Access::Role(Role::Admin)
    }
}

/// Lets a request through when its key's role grants `access`; otherwise
/// 401 (no key or an unknown one) or 403 (a role too low), naming the role
/// needed.
pub async fn guard(
    State((state, access)): State<(AppState, Access)>,
    req: Request,
    next: Next,
) -> Response {
    let config = state.config();
    let needed = match access {
        Access::Public => return next.run(req).await,
        Access::Role(_) if config.api_keys.is_empty() => return next.run(req).await,
        Access::Role(Role::Read) if config.open_reads => return next.run(req).await,
        Access::Role(role) => role,
    };
    let presented = req
        .headers()
        .get(header::AUTHORIZATION)
        .and_then(|v| v.to_str().ok())
        .and_then(bearer_token);
    let Some(token) = presented else {
        return ApiError::Unauthorized(format!(
            "this operation needs an API key with the role `{needed}` or higher: \
             send `Authorization: Bearer <key>`"
        ))
        .into_response();
    };
    // Every key is compared, so the time taken does not tell which matched.
    let matched = config.api_keys.iter().fold(None, |found, k| {
        let equal = constant_time_eq(k.key.as_bytes(), token.as_bytes());
        found.or(equal.then_some(k.role))
    });
    match matched {
        None => ApiError::Unauthorized("the API key is not valid".into()).into_response(),
        Some(role) if role.grants(needed) => next.run(req).await,
        Some(role) => ApiError::Forbidden(format!(
            "this operation needs the role `{needed}` or higher; this key has the role `{role}`"
        ))
        .into_response(),
    }
}

/// The token of `Authorization: Bearer <token>`; the scheme is
/// case-insensitive (RFC 9110 §11.1), followed by one or more spaces.
pub(crate) fn bearer_token(value: &str) -> Option<&str> {
    let (scheme, rest) = value.split_once(' ')?;
    scheme
        .eq_ignore_ascii_case("bearer")
        .then(|| rest.trim_matches(' '))
        .filter(|t| !t.is_empty())
}

/// Compares without an early exit on the first differing byte.
fn constant_time_eq(a: &[u8], b: &[u8]) -> bool {
    if a.len() != b.len() {
        return false;
    }
    a.iter().zip(b).fold(0u8, |acc, (x, y)| acc | (x ^ y)) == 0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bearer_scheme_is_case_insensitive() {
        for v in ["Bearer k1", "bearer k1", "BEARER k1", "bEaReR   k1"] {
            assert_eq!(bearer_token(v), Some("k1"), "{v}");
        }
        for v in ["Basic k1", "Bearerk1", "Bearer ", "k1", ""] {
            assert_eq!(bearer_token(v), None, "{v}");
        }
    }

    /// Every path the table names is a route with that method, so a renamed
    /// route cannot silently fall back to `admin` or lose its openness.
    #[test]
    fn the_table_names_only_routes_that_exist() {
        let routes = super::super::route_table();
        for path in PUBLIC {
            assert!(routes.contains(&(Method::GET, *path)), "GET {path}");
        }
        for path in OPERATE {
            assert!(routes.contains(&(Method::POST, *path)), "POST {path}");
        }
    }
}
