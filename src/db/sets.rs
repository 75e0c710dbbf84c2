//! Measurement sets: the uploads as received and their parsed rows.

use super::types::text_enum;
use super::{commit_inserted, on_pool, write_for_robot, Db, Json, Listing, StoreError};
use crate::measure::{MeasuredPose, SetRole};
use crate::records::{AngleUnit, LengthUnit, SetFormat, SetRow, StoredRole};
use sqlx::Row;

impl From<SetRole> for StoredRole {
    fn from(r: SetRole) -> Self {
        match r {
            SetRole::Identification => StoredRole::Identification,
            SetRole::Training => StoredRole::Training,
            SetRole::Validation => StoredRole::Validation,
            SetRole::Check => StoredRole::Check,
        }
    }
}

impl From<StoredRole> for SetRole {
    fn from(r: StoredRole) -> Self {
        match r {
            StoredRole::Identification => SetRole::Identification,
            StoredRole::Training => SetRole::Training,
            StoredRole::Validation => SetRole::Validation,
            StoredRole::Check => SetRole::Check,
        }
    }
}

impl StoredRole {
    /// The role as stored and shown: `identification`, `training`, `validation` or `check`.
    pub fn as_str(self) -> &'static str {
        SetRole::from(self).as_str()
    }
}

text_enum!(StoredRole, [Identification, Training, Validation, Check]);
text_enum!(LengthUnit, [Mm, M]);
text_enum!(AngleUnit, [Deg, Rad]);
text_enum!(SetFormat, [Csv, Json]);

impl LengthUnit {
    /// The unit as stored: `mm` or `m`.
    pub fn as_str(self) -> &'static str {
        match self {
            LengthUnit::Mm => "mm",
            LengthUnit::M => "m",
        }
    }
}

impl AngleUnit {
    /// The unit as stored: `deg` or `rad`.
    pub fn as_str(self) -> &'static str {
        match self {
            AngleUnit::Deg => "deg",
            AngleUnit::Rad => "rad",
        }
    }
}

impl SetFormat {
    /// The format as stored: `csv` or `json`.
    pub fn as_str(self) -> &'static str {
        match self {
            SetFormat::Csv => "csv",
            SetFormat::Json => "json",
        }
    }
}

/// The statement inserting the set `$s`, returning its id.
macro_rules! insert_set {
    ($s:expr) => {
        sqlx::query_scalar(
            "INSERT INTO measurement_sets (robot_id, name, role, session, payload_kg, \
             length_unit, angle_unit, format, original, rows_json, row_count, dof, \
             axis_column, axis_value) \
             VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11, $12, $13, $14) RETURNING id",
        )
        .bind($s.robot_id)
        .bind($s.name)
        .bind($s.role)
        .bind($s.session)
        .bind($s.payload_kg)
        .bind($s.length_unit)
        .bind($s.angle_unit)
        .bind($s.format)
        .bind($s.original)
        .bind(Json($s.rows))
        .bind($s.row_count)
        .bind($s.dof)
        .bind($s.axis.map(|a| a.0))
        .bind($s.axis.map(|a| a.1))
    };
}

impl Db {
    /// Stores a set; `None` when its robot does not exist (any more).
    pub async fn insert_set(&self, s: &NewSet<'_>) -> Result<Option<SetRow>, StoreError> {
        Ok(on_pool!(self, |p, k| {
            let Some(mut tx) = write_for_robot!(p, k, s.robot_id) else {
                return Ok(None);
            };
            let id: i64 = insert_set!(s).fetch_one(&mut *tx).await?;
            Some(commit_inserted!(tx, SetRow, SET_SELECT, "id", id))
        }))
    }

    /// Stores sets of one robot in one transaction, all or none, in their
    /// order; `None` when the robot does not exist (any more).
    pub async fn insert_sets(
        &self,
        robot_id: i64,
        sets: &[NewSet<'_>],
    ) -> Result<Option<Vec<SetRow>>, StoreError> {
        Ok(on_pool!(self, |p, k| {
            let Some(mut tx) = write_for_robot!(p, k, robot_id) else {
                return Ok(None);
            };
            let mut rows = Vec::with_capacity(sets.len());
            for s in sets {
                debug_assert_eq!(s.robot_id, robot_id);
                let id: i64 = insert_set!(s).fetch_one(&mut *tx).await?;
                let row = sqlx::query_as::<_, SetRow>(&format!("{SET_SELECT} WHERE id = $1"))
                    .bind(id)
                    .fetch_one(&mut *tx)
                    .await?;
                rows.push(row);
            }
            tx.commit().await?;
            Some(rows)
        }))
    }

    /// One page of a robot's sets by id, and how many it has.
    pub async fn sets_page(
        &self,
        robot_id: i64,
        limit: i64,
        offset: i64,
    ) -> Result<Listing<SetRow>, StoreError> {
        self.robot_page(
            SET_SELECT,
            "measurement_sets",
            "id",
            robot_id,
            limit,
            offset,
        )
        .await
    }

    /// Every set of robot `robot_id`, oldest first.
    pub async fn sets(&self, robot_id: i64) -> Result<Vec<SetRow>, StoreError> {
        self.robot_rows(SET_SELECT, "id", robot_id).await
    }

    /// Set `id` of robot `robot_id`, if it exists.
    pub async fn set(&self, robot_id: i64, id: i64) -> Result<Option<SetRow>, StoreError> {
        self.robot_row(SET_SELECT, "id", robot_id, id).await
    }

    /// The parsed rows of a set (mm/deg).
    pub async fn set_rows(
        &self,
        robot_id: i64,
        id: i64,
    ) -> Result<Option<Vec<MeasuredPose>>, StoreError> {
        let sql = "SELECT rows_json FROM measurement_sets WHERE robot_id = $1 AND id = $2";
        let rows: Option<Json<Vec<MeasuredPose>>> = on_pool!(self, |p, k| {
            sqlx::query_scalar(sql)
                .bind(robot_id)
                .bind(id)
                .fetch_optional(p)
                .await?
        });
        Ok(rows.map(|r| r.0))
    }

    /// The upload as received: (format, text).
    pub async fn set_original(
        &self,
        robot_id: i64,
        id: i64,
    ) -> Result<Option<(SetFormat, String)>, StoreError> {
        let sql = "SELECT format, original FROM measurement_sets WHERE robot_id = $1 AND id = $2";
        Ok(on_pool!(self, |p, k| {
            let row = sqlx::query(sql)
                .bind(robot_id)
                .bind(id)
                .fetch_optional(p)
                .await?;
            match row {
                Some(r) => Some((r.try_get(0)?, r.try_get(1)?)),
                None => None,
            }
        }))
    }
}

const SET_SELECT: &str = "SELECT id, robot_id, name, role, session, payload_kg, length_unit, \
    angle_unit, format, row_count, dof, created_at, axis_column, axis_value FROM measurement_sets";

/// A measurement set to insert.
#[derive(Debug)]
pub struct NewSet<'a> {
    /// The robot the set belongs to.
    pub robot_id: i64,
    /// The set's name.
    pub name: &'a str,
    /// Its data role.
    pub role: StoredRole,
    /// The tracker session it was measured in (one session per set).
    pub session: &'a str,
    /// Payload of rows that carry none [kg], as declared.
    pub payload_kg: Option<f64>,
    /// The length unit the upload declared.
    pub length_unit: LengthUnit,
    /// The angle unit the upload declared.
    pub angle_unit: AngleUnit,
    /// The format the upload came in.
    pub format: SetFormat,
    /// The upload as received.
    pub original: &'a str,
    /// The parsed rows (mm/deg).
    pub rows: &'a [MeasuredPose],
    /// Number of rows.
    pub row_count: i64,
    /// Joints per row (the robot's).
    pub dof: i64,
    /// A track's station set: the track's column and its value there [mm].
    pub axis: Option<(&'a str, f64)>,
}
