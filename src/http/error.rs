//! One error shape for every 4xx/5xx: `application/problem+json` (RFC 9457)
//! `{type, title, status, detail}`, and axum's rejections (bad JSON, wrong
//! content type, body too large, bad path or query) mapped into it for the
//! request extractors (`extract.rs`).
//!
//! 4xx details say what to fix. Database and internal errors are logged with
//! their cause and returned as a generic 500 without it.

use axum::extract::rejection::{BytesRejection, PathRejection, QueryRejection};
use axum::http::{header, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use serde::Serialize;

/// Media type of error bodies.
pub const PROBLEM_JSON: &str = "application/problem+json";

/// Every error the API returns.
#[derive(Debug, thiserror::Error)]
pub enum ApiError {
    /// 400: the request cannot be read (malformed JSON, bad path or query).
    #[error("{0}")]
    BadRequest(String),
    /// 401: no valid API key while keys are configured and the route needs one.
    #[error("{0}")]
    Unauthorized(String),
    /// 403: a valid API key whose role is below the one the route needs.
    #[error("{0}")]
    Forbidden(String),
    /// 404: the resource or route does not exist.
    #[error("{0}")]
    NotFound(String),
    /// 405: the route exists but not with this method.
    #[error("{0}")]
    MethodNotAllowed(String),
    /// 409: the resource is not in a state that allows the operation.
    #[error("{0}")]
    Conflict(String),
    /// 413: the body exceeds the size limit.
    #[error("{0}")]
    PayloadTooLarge(String),
    /// 415: the body's content type is not accepted here.
    #[error("{0}")]
    UnsupportedMediaType(String),
    /// 414: the URL is too long (answered for the HTTP parser, see `listener`).
    #[error("{0}")]
    UriTooLong(String),
    /// 422: well-formed but invalid content (unknown preset, bad CSV line, ...).
    #[error("{0}")]
    Unprocessable(String),
    /// 422 with `file`, `line` and `column`: a robot program that cannot be parsed.
    #[error("{0}")]
    Unparsable(crate::program::ParseError),
    /// 431: the request head is too large (answered for the HTTP parser).
    #[error("{0}")]
    HeadersTooLarge(String),
    /// 503: the database is unavailable or the service is shutting down.
    #[error("{0}")]
    Unavailable(String),
    /// 429 with `Retry-After`: the service is saturated (job or solve queue
    /// full); the client should send this work again later.
    #[error("{detail}")]
    Busy {
        /// What is saturated and what to do.
        detail: String,
        /// The `Retry-After` header's value [s].
        retry_after_s: u32,
    },
    /// 500: logged with its cause; the client sees a generic message.
    #[error("internal error: {0}")]
    Internal(String),
}

/// The problem document.
#[derive(Debug, Serialize)]
pub struct Problem {
    /// `urn:robocal:problem:` and the error's [`ApiError::code`].
    #[serde(rename = "type")]
    pub kind: String,
    /// The status's reason phrase (`Not Found`, …).
    pub title: String,
    /// The HTTP status code.
    pub status: u16,
    /// What went wrong and, for a 4xx, what to fix; generic for a 500.
    pub detail: String,
    /// Where a program cannot be parsed (422 `unparsable-program` only).
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub location: Option<ProgramLocation>,
}

/// The place in a program's files that cannot be parsed.
#[derive(Debug, Serialize)]
pub struct ProgramLocation {
    /// The program file, as the request named it.
    pub file: String,
    /// 1-based.
    pub line: usize,
    /// 1-based, in characters.
    pub column: usize,
}

impl ApiError {
    /// The HTTP status the error answers with.
    pub fn status(&self) -> StatusCode {
        match self {
            ApiError::BadRequest(_) => StatusCode::BAD_REQUEST,
            ApiError::Unauthorized(_) => StatusCode::UNAUTHORIZED,
            ApiError::Forbidden(_) => StatusCode::FORBIDDEN,
            ApiError::NotFound(_) => StatusCode::NOT_FOUND,
            ApiError::MethodNotAllowed(_) => StatusCode::METHOD_NOT_ALLOWED,
            ApiError::Conflict(_) => StatusCode::CONFLICT,
            ApiError::PayloadTooLarge(_) => StatusCode::PAYLOAD_TOO_LARGE,
            ApiError::UnsupportedMediaType(_) => StatusCode::UNSUPPORTED_MEDIA_TYPE,
            ApiError::UriTooLong(_) => StatusCode::URI_TOO_LONG,
            ApiError::Unprocessable(_) | ApiError::Unparsable(_) => {
                StatusCode::UNPROCESSABLE_ENTITY
            }
            ApiError::HeadersTooLarge(_) => StatusCode::REQUEST_HEADER_FIELDS_TOO_LARGE,
            ApiError::Unavailable(_) => StatusCode::SERVICE_UNAVAILABLE,
            ApiError::Busy { .. } => StatusCode::TOO_MANY_REQUESTS,
            ApiError::Internal(_) => StatusCode::INTERNAL_SERVER_ERROR,
        }
    }

    /// Short machine-readable code, the last part of the problem `type`.
    pub fn code(&self) -> &'static str {
        match self {
            ApiError::BadRequest(_) => "bad-request",
            ApiError::Unauthorized(_) => "unauthorized",
            ApiError::Forbidden(_) => "forbidden",
            ApiError::NotFound(_) => "not-found",
            ApiError::MethodNotAllowed(_) => "method-not-allowed",
            ApiError::Conflict(_) => "conflict",
            ApiError::PayloadTooLarge(_) => "payload-too-large",
            ApiError::UnsupportedMediaType(_) => "unsupported-media-type",
            ApiError::UriTooLong(_) => "uri-too-long",
            ApiError::Unprocessable(_) => "invalid-input",
            ApiError::Unparsable(_) => "unparsable-program",
            ApiError::HeadersTooLarge(_) => "headers-too-large",
            ApiError::Unavailable(_) => "unavailable",
            ApiError::Busy { .. } => "busy",
            ApiError::Internal(_) => "internal",
        }
    }

    /// The problem document of the error (a 500's detail without its cause).
    pub fn problem(&self) -> Problem {
        let status = self.status();
        let detail = match self {
            ApiError::Internal(_) => {
                "the server failed to handle the request; the cause is in the server log".into()
            }
            other => other.to_string(),
        };
        Problem {
            kind: format!("urn:robocal:problem:{}", self.code()),
            title: status.canonical_reason().unwrap_or("Error").to_string(),
            status: status.as_u16(),
            detail,
            location: match self {
                ApiError::Unparsable(e) => Some(ProgramLocation {
                    file: e.file.clone(),
                    line: e.line,
                    column: e.column,
                }),
                _ => None,
            },
        }
    }

    /// A 404 saying what is missing.
    pub fn not_found(what: impl std::fmt::Display) -> Self {
        ApiError::NotFound(what.to_string())
    }

    /// A 422 saying what is invalid.
    pub fn invalid(what: impl std::fmt::Display) -> Self {
        ApiError::Unprocessable(what.to_string())
    }
}

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        if let ApiError::Internal(cause) = &self {
            tracing::error!(%cause, "internal error");
        }
        let status = self.status();
        let body = serde_json::to_vec(&self.problem()).unwrap_or_default();
        let mut res = (status, body).into_response();
        res.headers_mut()
            .insert(header::CONTENT_TYPE, HeaderValue::from_static(PROBLEM_JSON));
        if let ApiError::Busy { retry_after_s, .. } = &self {
            res.headers_mut()
                .insert(header::RETRY_AFTER, HeaderValue::from(*retry_after_s));
        }
        if status == StatusCode::UNAUTHORIZED {
            res.headers_mut().insert(
                header::WWW_AUTHENTICATE,
                HeaderValue::from_static("Bearer realm=\"robocal\""),
            );
        }
        res
    }
}

impl From<crate::service::ServiceError> for ApiError {
    fn from(e: crate::service::ServiceError) -> Self {
        use crate::service::ServiceError as S;
        match e {
            S::Invalid(m) => ApiError::Unprocessable(m),
            S::NotFound(m) => ApiError::NotFound(m),
            S::Conflict(m) => ApiError::Conflict(m),
            S::Busy {
                detail,
                retry_after_s,
            } => ApiError::Busy {
                detail,
                retry_after_s,
            },
            S::Unavailable(m) => ApiError::Unavailable(m),
            S::Unparsable(e) => ApiError::Unparsable(e),
            S::Internal(m) => ApiError::Internal(m),
        }
    }
}

/// A delimiter or decimal separator option that names none (422).
impl From<crate::measure::csv_text::DialectError> for ApiError {
    fn from(e: crate::measure::csv_text::DialectError) -> Self {
        ApiError::Unprocessable(e.to_string())
    }
}

/// A `branch` option that is not a configuration branch (422).
impl From<crate::solve::ik::BranchError> for ApiError {
    fn from(e: crate::solve::ik::BranchError) -> Self {
        ApiError::Unprocessable(format!("`branch`: {e}"))
    }
}

/// A targets file whose header cannot be read (422, naming the line).
impl From<crate::solve::ik::TargetsCsvError> for ApiError {
    fn from(e: crate::solve::ik::TargetsCsvError) -> Self {
        ApiError::Unprocessable(format!("targets CSV: {e}"))
    }
}

fn bytes_rejection(e: BytesRejection) -> ApiError {
    if e.status() == StatusCode::PAYLOAD_TOO_LARGE {
        ApiError::PayloadTooLarge(
            "the request body is larger than the service's limit (`--body-limit`, default 16 MiB); split the upload or the batch".into(),
        )
    } else {
        ApiError::BadRequest(format!("cannot read the request body: {}", e.body_text()))
    }
}

impl From<BytesRejection> for ApiError {
    fn from(e: BytesRejection) -> Self {
        bytes_rejection(e)
    }
}

impl From<PathRejection> for ApiError {
    fn from(r: PathRejection) -> Self {
        ApiError::BadRequest(format!(
            "invalid path parameter: {} (ids and version numbers are positive integers)",
            r.body_text()
        ))
    }
}

impl From<QueryRejection> for ApiError {
    fn from(r: QueryRejection) -> Self {
        ApiError::BadRequest(format!("invalid query string: {}", r.body_text()))
    }
}

/// The media type of the request body (`text/csv` of `text/csv; charset=…`),
/// lower case; empty when none is declared.
pub fn content_type(headers: &axum::http::HeaderMap) -> String {
    headers
        .get(header::CONTENT_TYPE)
        .and_then(|v| v.to_str().ok())
        .map(|v| {
            v.split(';')
                .next()
                .unwrap_or("")
                .trim()
                .to_ascii_lowercase()
        })
        .unwrap_or_default()
}

/// Whether the request declares a JSON body (`application/json` or `*/*+json`).
pub fn json_content_type(headers: &axum::http::HeaderMap) -> bool {
    let Some(ct) = headers
        .get(header::CONTENT_TYPE)
        .and_then(|v| v.to_str().ok())
    else {
        return false;
    };
    let essence = ct.split(';').next().unwrap_or("").trim();
    essence.eq_ignore_ascii_case("application/json")
        || essence
            .rsplit_once('+')
            .is_some_and(|(t, suffix)| t.contains('/') && suffix.eq_ignore_ascii_case("json"))
}
