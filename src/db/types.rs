//! Column types that read and write the same text on SQLite and PostgreSQL:
//! [`Json<T>`] (a JSON document in a TEXT column, written and read by
//! `serde_json`, so it reads back byte for byte) and the text enums (status,
//! role, units, format) stored as the lowercase names the schemas' CHECK
//! constraints list.
//!
//! sqlx's own `Json` is JSONB on PostgreSQL (it reorders keys and rewrites
//! numbers) and its derived enums name a PostgreSQL enum type; both would make
//! the two stores differ, hence these.

use crate::records::Json;
use serde::de::DeserializeOwned;
use serde::Serialize;
use sqlx::encode::IsNull;
use sqlx::error::BoxDynError;
use sqlx::{Database, Decode, Encode, Type};

impl<T, DB: Database> Type<DB> for Json<T>
where
    str: Type<DB>,
{
    fn type_info() -> DB::TypeInfo {
        <str as Type<DB>>::type_info()
    }

    fn compatible(ty: &DB::TypeInfo) -> bool {
        <str as Type<DB>>::compatible(ty)
    }
}

impl<'q, T: Serialize, DB: Database> Encode<'q, DB> for Json<T>
where
    String: Encode<'q, DB>,
{
    fn encode_by_ref(
        &self,
        buf: &mut <DB as Database>::ArgumentBuffer<'q>,
    ) -> Result<IsNull, BoxDynError> {
        serde_json::to_string(&self.0)?.encode(buf)
    }
}

impl<'r, T: DeserializeOwned, DB: Database> Decode<'r, DB> for Json<T>
where
    &'r str: Decode<'r, DB>,
{
    fn decode(value: <DB as Database>::ValueRef<'r>) -> Result<Self, BoxDynError> {
        let text = <&str as Decode<DB>>::decode(value)?;
        Ok(Json(serde_json::from_str(text)?))
    }
}

/// A fieldless enum stored as the text of its `as_str` (read back by name).
macro_rules! text_enum {
    ($t:ty, [$($v:ident),+ $(,)?]) => {
        impl<DB: ::sqlx::Database> ::sqlx::Type<DB> for $t
        where
            str: ::sqlx::Type<DB>,
        {
            fn type_info() -> DB::TypeInfo {
                <str as ::sqlx::Type<DB>>::type_info()
            }

            fn compatible(ty: &DB::TypeInfo) -> bool {
                <str as ::sqlx::Type<DB>>::compatible(ty)
            }
        }

        impl<'q, DB: ::sqlx::Database> ::sqlx::Encode<'q, DB> for $t
        where
            &'q str: ::sqlx::Encode<'q, DB>,
        {
            fn encode_by_ref(
                &self,
                buf: &mut <DB as ::sqlx::Database>::ArgumentBuffer<'q>,
            ) -> Result<::sqlx::encode::IsNull, ::sqlx::error::BoxDynError> {
                let name: &'static str = self.as_str();
                <&str as ::sqlx::Encode<'q, DB>>::encode(name, buf)
            }
        }

        impl<'r, DB: ::sqlx::Database> ::sqlx::Decode<'r, DB> for $t
        where
            &'r str: ::sqlx::Decode<'r, DB>,
        {
            fn decode(
                value: <DB as ::sqlx::Database>::ValueRef<'r>,
            ) -> Result<Self, ::sqlx::error::BoxDynError> {
                let text = <&str as ::sqlx::Decode<DB>>::decode(value)?;
                [$(<$t>::$v),+]
                    .into_iter()
                    .find(|v| v.as_str() == text)
                    .ok_or_else(|| {
                        format!("`{text}` is not a stored {}", stringify!($t)).into()
                    })
            }
        }
    };
}
pub(crate) use text_enum;
