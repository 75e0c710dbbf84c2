//! The cell around a robot: its named tools and work objects (table
//! `cell_items`), the entries of a cell file (`core::cell::file`) in mm and
//! degrees. Names are unique per robot and kind regardless of ASCII case, and
//! so are the controller's numbers.

use super::types::text_enum;
use super::{on_pool, write_for_robot, Db, Json, StoreError};
use crate::records::{CellItemRow, CellKind, CellPut, ItemFrame, NewCellItem};

impl CellKind {
    /// The kind as stored: `tool` or `work_object`.
    pub fn as_str(self) -> &'static str {
        match self {
            CellKind::Tool => "tool",
            CellKind::WorkObject => "work_object",
        }
    }

    /// The words for messages: `tool`, `work object`.
    pub fn label(self) -> &'static str {
        match self {
            CellKind::Tool => "tool",
            CellKind::WorkObject => "work object",
        }
    }
}

impl ItemFrame {
    /// The frame as stored: `flange`, `base`, `measurement` or `face_plate`.
    pub fn as_str(self) -> &'static str {
        match self {
            ItemFrame::Flange => "flange",
            ItemFrame::Base => "base",
            ItemFrame::Measurement => "measurement",
            ItemFrame::FacePlate => "face_plate",
        }
    }
}

text_enum!(CellKind, [Tool, WorkObject]);
text_enum!(ItemFrame, [Flange, Base, Measurement, FacePlate]);

const ITEM_SELECT: &str =
    "SELECT name, number, frame, pose_json, load_json, created_at, updated_at FROM cell_items";

/// Inserts one item in the transaction `$tx`.
macro_rules! insert_item {
    ($tx:ident, $robot:expr, $kind:expr, $item:expr) => {
        sqlx::query(
            "INSERT INTO cell_items (robot_id, kind, name, name_key, number, frame, pose_json, \
             load_json) VALUES ($1, $2, $3, $4, $5, $6, $7, $8)",
        )
        .bind($robot)
        .bind($kind)
        .bind(&$item.name)
        .bind(name_key(&$item.name))
        .bind($item.number)
        .bind($item.frame)
        .bind(Json(&$item.pose))
        .bind($item.load.as_ref().map(Json))
        .execute(&mut *$tx)
        .await?
    };
}

/// The key names are unique by.
pub fn name_key(name: &str) -> String {
    name.to_ascii_lowercase()
}

impl Db {
    /// A robot's tools or work objects by name.
    pub async fn cell_items(
        &self,
        robot_id: i64,
        kind: CellKind,
    ) -> Result<Vec<CellItemRow>, StoreError> {
        let sql = format!("{ITEM_SELECT} WHERE robot_id = $1 AND kind = $2 ORDER BY name_key");
        Ok(on_pool!(self, |p, k| sqlx::query_as::<_, CellItemRow>(
            &sql
        )
        .bind(robot_id)
        .bind(kind)
        .fetch_all(p)
        .await?))
    }

    /// One tool or work object by name (any ASCII case).
    pub async fn cell_item(
        &self,
        robot_id: i64,
        kind: CellKind,
        name: &str,
    ) -> Result<Option<CellItemRow>, StoreError> {
        let sql = format!("{ITEM_SELECT} WHERE robot_id = $1 AND kind = $2 AND name_key = $3");
        Ok(on_pool!(self, |p, k| sqlx::query_as::<_, CellItemRow>(
            &sql
        )
        .bind(robot_id)
        .bind(kind)
        .bind(name_key(name))
        .fetch_optional(p)
        .await?))
    }

    /// Creates or replaces the item of that name; `None` when the robot does
    /// not exist; `Conflict` when another item has its number.
    pub async fn put_cell_item(
        &self,
        robot_id: i64,
        kind: CellKind,
        item: &NewCellItem,
    ) -> Result<Option<CellPut>, StoreError> {
        let key = name_key(&item.name);
        on_pool!(self, |p, k| {
            let Some(mut tx) = write_for_robot!(p, k, robot_id) else {
                return Ok(None);
            };
            // Names are identities: the item of this name in another letter
            // case is not renamed by a PUT.
            let same: Option<String> = sqlx::query_scalar(
                "SELECT name FROM cell_items WHERE robot_id = $1 AND kind = $2 AND name_key = $3",
            )
            .bind(robot_id)
            .bind(kind)
            .bind(&key)
            .fetch_optional(&mut *tx)
            .await?;
            if let Some(existing) = same.filter(|e| *e != item.name) {
                tx.rollback().await?;
                return Err(StoreError::Conflict(format!(
                    "{} `{existing}` of robot {robot_id} exists; names are unique regardless of case, so `{}` would rename it: PUT `{existing}` to replace it, or choose another name",
                    kind.label(),
                    item.name
                )));
            }
            if let Some(n) = item.number {
                let other: Option<String> = sqlx::query_scalar(
                    "SELECT name FROM cell_items WHERE robot_id = $1 AND kind = $2 \
                     AND number = $3 AND name_key <> $4",
                )
                .bind(robot_id)
                .bind(kind)
                .bind(n)
                .bind(&key)
                .fetch_optional(&mut *tx)
                .await?;
                if let Some(other) = other {
                    tx.rollback().await?;
                    return Err(StoreError::Conflict(format!(
                        "{} `{other}` of robot {robot_id} already has number {n}; numbers are unique per robot",
                        kind.label()
                    )));
                }
            }
            let update = k.sql(
                "UPDATE cell_items SET name = $1, number = $2, frame = $3, pose_json = $4, \
                 load_json = $8, updated_at = {now} \
                 WHERE robot_id = $5 AND kind = $6 AND name_key = $7",
            );
            let n = sqlx::query(&update)
                .bind(&item.name)
                .bind(item.number)
                .bind(item.frame)
                .bind(Json(&item.pose))
                .bind(robot_id)
                .bind(kind)
                .bind(&key)
                .bind(item.load.as_ref().map(Json))
                .execute(&mut *tx)
                .await?
                .rows_affected();
            let created = n == 0;
            if created {
                insert_item!(tx, robot_id, kind, item);
            }
            let row = sqlx::query_as::<_, CellItemRow>(&format!(
                "{ITEM_SELECT} WHERE robot_id = $1 AND kind = $2 AND name_key = $3"
            ))
            .bind(robot_id)
            .bind(kind)
            .bind(&key)
            .fetch_one(&mut *tx)
            .await?;
            tx.commit().await?;
            Ok(Some(CellPut { row, created }))
        })
    }

    /// Replaces all of a robot's tools or work objects (names and numbers
    /// checked unique by the caller); `None` when the robot does not exist.
    pub async fn replace_cell_items(
        &self,
        robot_id: i64,
        kind: CellKind,
        items: &[NewCellItem],
    ) -> Result<Option<Vec<CellItemRow>>, StoreError> {
        on_pool!(self, |p, k| {
            let Some(mut tx) = write_for_robot!(p, k, robot_id) else {
                return Ok(None);
            };
            sqlx::query("DELETE FROM cell_items WHERE robot_id = $1 AND kind = $2")
                .bind(robot_id)
                .bind(kind)
                .execute(&mut *tx)
                .await?;
            for item in items {
                insert_item!(tx, robot_id, kind, item);
            }
            let rows = sqlx::query_as::<_, CellItemRow>(&format!(
                "{ITEM_SELECT} WHERE robot_id = $1 AND kind = $2 ORDER BY name_key"
            ))
            .bind(robot_id)
            .bind(kind)
            .fetch_all(&mut *tx)
            .await?;
            tx.commit().await?;
            Ok(Some(rows))
        })
    }

    /// Deletes the item of that name; false when there is none.
    pub async fn delete_cell_item(
        &self,
        robot_id: i64,
        kind: CellKind,
        name: &str,
    ) -> Result<bool, StoreError> {
        let n = on_pool!(self, |p, k| super::write_one!(
            p,
            k,
            sqlx::query(
                "DELETE FROM cell_items WHERE robot_id = $1 AND kind = $2 AND name_key = $3"
            )
            .bind(robot_id)
            .bind(kind)
            .bind(name_key(name))
        ));
        Ok(n > 0)
    }
}
