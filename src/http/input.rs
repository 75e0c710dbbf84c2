//! Request input rules shared by the routes, written to match `openapi.yaml`
//! exactly, so that the server refuses what the spec refuses and accepts what
//! it allows:
//!
//! - bodies and nested records are JSON objects only ([`from_json_object`],
//!   [`objects`], [`object_or_null`]); serde would otherwise read a struct from
//!   an array of its fields;
//! - an optional field may be left out, but `null` is refused unless the spec
//!   says the field is nullable ([`present`]);
//! - names ([`check_name`]), payloads ([`check_payload`]) and list paging
//!   ([`Page`]).

use super::ApiError;
use crate::measure::external::ExternalAxis;
use crate::service::limits::{PAGE_DEFAULT, PAYLOAD_MAX_KG};
use serde::de::{DeserializeOwned, Deserializer, MapAccess, Visitor};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::marker::PhantomData;

pub use crate::service::limits::NAME_MAX;

/// Parses a JSON object body: 400 when it is not JSON, 422 when it is JSON of
/// the wrong shape (an array, a scalar, a wrong field).
pub fn from_json_object<T: DeserializeOwned>(bytes: &[u8]) -> Result<T, ApiError> {
    let first = bytes.iter().find(|b| !b.is_ascii_whitespace());
    if first != Some(&b'{') {
        return Err(
            match serde_json::from_slice::<serde::de::IgnoredAny>(bytes) {
                Ok(_) => ApiError::invalid("the request body must be a JSON object"),
                Err(e) => ApiError::BadRequest(format!("malformed JSON: {e}")),
            },
        );
    }
    // The path names the field at fault (`versions[1]: …`).
    let mut de = serde_json::Deserializer::from_slice(bytes);
    let value = serde_path_to_error::deserialize::<_, T>(&mut de).map_err(|e| {
        if e.inner().is_data() {
            ApiError::invalid(format!("invalid request body: {e}"))
        } else {
            ApiError::BadRequest(format!("malformed JSON: {}", e.inner()))
        }
    })?;
    de.end()
        .map_err(|e| ApiError::BadRequest(format!("malformed JSON: {e}")))?;
    Ok(value)
}

/// A record that must be a JSON object (not an array of its fields).
struct Obj<T>(T);

impl<'de, T: Deserialize<'de>> Deserialize<'de> for Obj<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V<T>(PhantomData<T>);
        impl<'de, T: Deserialize<'de>> Visitor<'de> for V<T> {
            type Value = T;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a JSON object")
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<T, A::Error> {
                T::deserialize(serde::de::value::MapAccessDeserializer::new(map))
            }
        }
        d.deserialize_map(V(PhantomData)).map(Obj)
    }
}

/// `deserialize_with` for a list of records that must each be a JSON object.
pub fn objects<'de, D, T>(d: D) -> Result<Vec<T>, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    Ok(Vec::<Obj<T>>::deserialize(d)?
        .into_iter()
        .map(|o| o.0)
        .collect())
}

/// `deserialize_with` for a nullable record that must be a JSON object.
pub fn object_or_null<'de, D, T>(d: D) -> Result<Option<T>, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    Ok(Option::<Obj<T>>::deserialize(d)?.map(|o| o.0))
}

/// `deserialize_with` (with `#[serde(default)]`) for an optional field that
/// may be left out but not be `null`.
pub fn present<'de, D, T>(d: D) -> Result<Option<T>, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    T::deserialize(d).map(Some)
}

/// An integer as JSON Schema counts them: `3` and `3.0` alike (serde's integer
/// types refuse `3.0`), within the range of `T`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Int<T>(pub T);

impl<T: Serialize> Serialize for Int<T> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.0.serialize(s)
    }
}

impl<'de, T: TryFrom<i128>> Deserialize<'de> for Int<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V<T>(PhantomData<T>);
        impl<T: TryFrom<i128>> V<T> {
            fn make<E: serde::de::Error>(v: i128) -> Result<Int<T>, E> {
                T::try_from(v)
                    .map(Int)
                    .map_err(|_| E::custom(format!("integer {v} is out of range")))
            }
        }
        impl<'de, T: TryFrom<i128>> Visitor<'de> for V<T> {
            type Value = Int<T>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("an integer")
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Int<T>, E> {
                Self::make(v.into())
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Int<T>, E> {
                Self::make(v.into())
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Int<T>, E> {
                // |v| < 1e30 < 2^100 converts exactly; larger is out of every
                // range here.
                if !v.is_finite() || v.fract() != 0.0 {
                    Err(E::custom(format!("{v} is not an integer")))
                } else if v.abs() < 1e30 {
                    Self::make(v as i128)
                } else {
                    Err(E::custom(format!("integer {v:e} is out of range")))
                }
            }
        }
        d.deserialize_any(V(PhantomData))
    }
}

/// `deserialize_with` for an integer field (see [`Int`]).
pub fn int<'de, D, T>(d: D) -> Result<T, D::Error>
where
    D: Deserializer<'de>,
    T: TryFrom<i128>,
{
    Int::<T>::deserialize(d).map(|i| i.0)
}

/// `deserialize_with` (with `#[serde(default)]`) for an optional integer that
/// may be left out but not be `null`.
pub fn present_int<'de, D, T>(d: D) -> Result<Option<T>, D::Error>
where
    D: Deserializer<'de>,
    T: TryFrom<i128>,
{
    int(d).map(Some)
}

/// `deserialize_with` (with `#[serde(default)]`) for an optional list of
/// integers that may be left out but not be `null`.
pub fn present_ints<'de, D, T>(d: D) -> Result<Option<Vec<T>>, D::Error>
where
    D: Deserializer<'de>,
    T: TryFrom<i128>,
{
    Ok(Some(
        Vec::<Int<T>>::deserialize(d)?
            .into_iter()
            .map(|i| i.0)
            .collect(),
    ))
}

/// An id or a version number: a positive integer as JSON Schema counts them
/// (`73` and `73.0` alike, see [`Int`]), 1 to `i64::MAX`; `73.5`, `0`, `-3`
/// and numbers beyond `i64` are refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Id(pub i64);

impl<'de> Deserialize<'de> for Id {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let Int(v) = Int::<i64>::deserialize(d)?;
        if v < 1 {
            return Err(serde::de::Error::custom(format!(
                "ids and version numbers are positive integers (1 or more), got {v}"
            )));
        }
        Ok(Id(v))
    }
}

/// `deserialize_with` for an id or version number field (see [`Id`]).
pub fn id<'de, D: Deserializer<'de>>(d: D) -> Result<i64, D::Error> {
    Id::deserialize(d).map(|i| i.0)
}

/// `deserialize_with` (with `#[serde(default)]`) for an optional id or
/// version number that may be left out but not be `null`.
pub fn present_id<'de, D: Deserializer<'de>>(d: D) -> Result<Option<i64>, D::Error> {
    id(d).map(Some)
}

/// `deserialize_with` for a list of ids or version numbers.
pub fn ids<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<i64>, D::Error> {
    Ok(Vec::<Id>::deserialize(d)?
        .into_iter()
        .map(|i| i.0)
        .collect())
}

/// `deserialize_with` (with `#[serde(default)]`) for an optional list of ids
/// that may be left out but not be `null`.
pub fn present_ids<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Vec<i64>>, D::Error> {
    ids(d).map(Some)
}

/// Whitespace as `openapi.yaml` counts it for names: a name needs one
/// character that is not a space, tab or line break (pattern `[^ \t\r\n]`).
fn blank(name: &str) -> bool {
    name.chars().all(|c| matches!(c, ' ' | '\t' | '\r' | '\n'))
}

/// A name: 1 to [`NAME_MAX`] characters, not only blanks.
pub fn check_name(name: &str, what: &str) -> Result<(), ApiError> {
    if name.is_empty() || blank(name) {
        return Err(ApiError::invalid(format!(
            "{what} must not be empty or blank"
        )));
    }
    if name.chars().count() > NAME_MAX {
        return Err(ApiError::invalid(format!(
            "{what} is longer than {NAME_MAX} characters"
        )));
    }
    // Text columns hold no NUL on PostgreSQL; a line break or another
    // control character would break the CSV rows and comment lines a name
    // is written into.
    if let Some(c) = name.chars().find(|c| c.is_control()) {
        return Err(ApiError::invalid(format!(
            "{what} must not contain control characters (found U+{:04X})",
            c as u32
        )));
    }
    Ok(())
}

/// A payload in kilograms: finite, 0 to [`PAYLOAD_MAX_KG`].
pub fn check_payload(what: &str, kg: f64) -> Result<(), ApiError> {
    if !(kg.is_finite() && (0.0..=PAYLOAD_MAX_KG).contains(&kg)) {
        return Err(ApiError::invalid(format!(
            "{what} must be between 0 and {PAYLOAD_MAX_KG} kg, got {kg}"
        )));
    }
    Ok(())
}

/// `?limit=&offset=` of a list.
#[derive(Debug, Clone, Copy, Default, Deserialize)]
pub struct PageQuery {
    /// Most items to return; absent: the list's default page size.
    pub limit: Option<u64>,
    /// Items to skip, 0-based; absent: 0.
    pub offset: Option<u64>,
}

/// A checked page: at most `limit` items from `offset` (0-based).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Page {
    /// Most items to return, 1 to the list's maximum.
    pub limit: i64,
    /// Items skipped, 0-based.
    pub offset: i64,
}

impl PageQuery {
    /// The page asked for, with `limit` defaulted and checked against `page_max` (400 outside 1 to
    /// it).
    pub fn check(self, page_max: usize) -> Result<Page, ApiError> {
        let limit = self.limit.unwrap_or(PAGE_DEFAULT.min(page_max) as u64);
        if limit == 0 || limit > page_max as u64 {
            return Err(ApiError::BadRequest(format!(
                "`limit` must be between 1 and {page_max}, got {limit}"
            )));
        }
        let offset = self.offset.unwrap_or(0);
        let offset = i64::try_from(offset)
            .map_err(|_| ApiError::BadRequest(format!("`offset` must be at most {}", i64::MAX)))?;
        Ok(Page {
            limit: limit as i64,
            offset,
        })
    }
}

/// The paging fields of a list response.
pub fn page_fields(page: Page, total: i64) -> serde_json::Value {
    let next = page.offset.saturating_add(page.limit);
    serde_json::json!({
        "total": total,
        "limit": page.limit,
        "offset": page.offset,
        "next_offset": (next < total).then_some(next),
    })
}

/// A list response: the paging fields and the page's items under `key`.
pub fn page_body<T: serde::Serialize>(
    page: Page,
    total: i64,
    key: &str,
    items: T,
) -> Result<serde_json::Value, ApiError> {
    let mut out = page_fields(page, total);
    out[key] = serde_json::to_value(items).map_err(|e| ApiError::Internal(e.to_string()))?;
    Ok(out)
}

/// An `e1` … `e6` column of field `field`, `default` when left out (422
/// naming the field otherwise).
pub fn external_axis(
    field: &str,
    given: Option<&str>,
    default: ExternalAxis,
) -> Result<ExternalAxis, ApiError> {
    match given {
        None => Ok(default),
        Some(c) => ExternalAxis::ALL
            .into_iter()
            .find(|a| a.column() == c)
            .ok_or_else(|| {
                ApiError::invalid(format!(
                    "`{field}`: `{c}`; give an external-axis column, e1 … e6"
                ))
            }),
    }
}

/// 201 for a resource stored for the first time, 200 for one replaced (a
/// fit stored per robot: track, positioner, turntable).
pub fn created_or_ok(created: bool) -> axum::http::StatusCode {
    if created {
        axum::http::StatusCode::CREATED
    } else {
        axum::http::StatusCode::OK
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[derive(Debug, Deserialize, PartialEq)]
    #[serde(deny_unknown_fields)]
    struct Inner {
        a: f64,
    }

    #[derive(Debug, Deserialize, PartialEq)]
    #[serde(deny_unknown_fields)]
    struct Outer {
        #[serde(default, deserialize_with = "present")]
        name: Option<String>,
        #[serde(deserialize_with = "objects")]
        items: Vec<Inner>,
        #[serde(default, deserialize_with = "object_or_null")]
        one: Option<Inner>,
    }

    fn parse(v: serde_json::Value) -> Result<Outer, ApiError> {
        from_json_object(v.to_string().as_bytes())
    }

    #[test]
    fn objects_only_and_no_nulls_where_not_nullable() {
        let ok = parse(json!({"items": [{"a": 1.0}], "one": null})).unwrap();
        assert_eq!(ok.items, vec![Inner { a: 1.0 }]);
        assert_eq!(ok.name, None);
        assert!(parse(json!({"items": [], "one": {"a": 2.0}}))
            .unwrap()
            .one
            .is_some());
        // serde alone would read these structs from arrays of their fields.
        for bad in [
            json!([[], null]),
            json!({"items": [[1.0]]}),
            json!({"items": [], "one": [2.0]}),
            json!({"items": [], "name": null}),
        ] {
            let e = parse(bad.clone()).unwrap_err();
            assert!(matches!(e, ApiError::Unprocessable(_)), "{bad}: {e:?}");
        }
        assert!(matches!(
            from_json_object::<Outer>(b"{\"items\": ["),
            Err(ApiError::BadRequest(_))
        ));
        assert!(matches!(
            from_json_object::<Outer>(b""),
            Err(ApiError::BadRequest(_))
        ));
    }

    #[derive(Debug, Deserialize)]
    struct Ints {
        #[serde(deserialize_with = "int")]
        a: u8,
        #[serde(default, deserialize_with = "present_ints")]
        b: Option<Vec<i64>>,
    }

    #[test]
    fn integers_as_json_schema_counts_them() {
        let v: Ints = serde_json::from_str(r#"{"a": 7.0, "b": [1, -2.0, 3e2]}"#).unwrap();
        assert_eq!(v.a, 7);
        assert_eq!(v.b, Some(vec![1, -2, 300]));
        for bad in [
            r#"{"a": 7.5}"#,
            r#"{"a": 256}"#,
            r#"{"a": -1}"#,
            r#"{"a": "7"}"#,
            r#"{"a": 1, "b": null}"#,
            r#"{"a": 1, "b": [1e300]}"#,
        ] {
            assert!(serde_json::from_str::<Ints>(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn names_and_payloads() {
        assert!(check_name("a", "n").is_ok());
        assert!(check_name("\u{3000}", "n").is_ok());
        for bad in ["", " ", "\t\r\n "] {
            assert!(check_name(bad, "n").is_err(), "{bad:?}");
        }
        assert!(check_name(&"x".repeat(NAME_MAX), "n").is_ok());
        assert!(check_name(&"é".repeat(NAME_MAX + 1), "n").is_err());
        assert!(check_payload("p", 0.0).is_ok());
        assert!(check_payload("p", PAYLOAD_MAX_KG).is_ok());
        for bad in [-1e-9, 10_000.5, 1e308, f64::NAN, f64::INFINITY] {
            assert!(check_payload("p", bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn paging() {
        let p = PageQuery::default().check(1000).unwrap();
        assert_eq!(
            p,
            Page {
                limit: 100,
                offset: 0
            }
        );
        assert!(PageQuery {
            limit: Some(0),
            offset: None
        }
        .check(1000)
        .is_err());
        assert!(PageQuery {
            limit: Some(1001),
            offset: None
        }
        .check(1000)
        .is_err());
        assert!(PageQuery {
            limit: None,
            offset: Some(u64::MAX)
        }
        .check(1000)
        .is_err());
        let f = page_fields(
            Page {
                limit: 2,
                offset: 2,
            },
            5,
        );
        assert_eq!(f["next_offset"], 4);
        let f = page_fields(
            Page {
                limit: 2,
                offset: 4,
            },
            5,
        );
        assert!(f["next_offset"].is_null());
    }
}
