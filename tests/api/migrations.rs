//! Schema migrations on a database that already holds data: a SQLite file at
//! schema 6 (sets, a calibration, versions, checks referencing the sets) is
//! opened by the service, which rebuilds `measurement_sets` for the `check`
//! role (migration 0007); every row, reference, index and id counter survives.
//! Likewise `checks` at schema 8 for the `shifted` status (migration 0009),
//! its old checks read through the service.

use robocal::db::Db;
use sqlx::sqlite::{SqliteConnectOptions, SqlitePool};
use sqlx::Row;
use std::borrow::Cow;
use std::str::FromStr;

/// Every column of every set, ordered by id, as text.
async fn sets_dump(pool: &SqlitePool) -> Vec<String> {
    sqlx::query(
        "SELECT id, robot_id, name, role, session, payload_kg, length_unit, angle_unit, format, \
         original, rows_json, row_count, dof, created_at FROM measurement_sets ORDER BY id",
    )
    .fetch_all(pool)
    .await
    .unwrap()
    .iter()
    .map(|r| {
        let payload: Option<f64> = r.get(5);
        format!(
            "{}|{}|{}|{}|{}|{payload:?}|{}|{}|{}|{}|{}|{}|{}|{}",
            r.get::<i64, _>(0),
            r.get::<i64, _>(1),
            r.get::<String, _>(2),
            r.get::<String, _>(3),
            r.get::<String, _>(4),
            r.get::<String, _>(6),
            r.get::<String, _>(7),
            r.get::<String, _>(8),
            r.get::<String, _>(9),
            r.get::<String, _>(10),
            r.get::<i64, _>(11),
            r.get::<i64, _>(12),
            r.get::<String, _>(13),
        )
    })
    .collect()
}

/// A SQLite file `old.db` in `dir` at schema `version` (migrations 1 to
/// `version` applied): its URL, connection options (foreign keys on) and a
/// pool on it.
async fn at_schema(
    dir: &std::path::Path,
    version: i64,
) -> (String, SqliteConnectOptions, SqlitePool) {
    let url = format!("sqlite://{}?mode=rwc", dir.join("old.db").display());
    let options = SqliteConnectOptions::from_str(&url)
        .unwrap()
        .foreign_keys(true);
    let pool = SqlitePool::connect_with(options.clone()).await.unwrap();
    let mut old = sqlx::migrate!("migrations/sqlite");
    let before: Vec<_> = old
        .migrations
        .iter()
        .filter(|m| m.version <= version)
        .cloned()
        .collect();
    assert_eq!(before.len() as i64, version);
    old.migrations = Cow::Owned(before);
    old.run(&pool).await.unwrap();
    (url, options, pool)
}

async fn pairs(pool: &SqlitePool, sql: &str) -> Vec<(i64, Option<i64>)> {
    sqlx::query_as(sql).fetch_all(pool).await.unwrap()
}

#[tokio::test]
async fn sqlite_check_role_migration_keeps_sets_versions_and_check_references() {
    let dir = tempfile::tempdir().unwrap();
    // The schema as it was before the `check` role: migrations 1 to 6.
    let (url, options, pool) = at_schema(dir.path(), 6).await;

    let exec = |sql: &'static str| {
        let pool = pool.clone();
        async move { sqlx::query(sql).execute(&pool).await.unwrap() }
    };
    exec("INSERT INTO robots (name, model_json, dof) VALUES ('r', '{}', 6)").await;
    for (name, role) in [
        ("q1", "identification"),
        ("q3", "validation"),
        ("q2", "training"),
        ("gone", "validation"),
        ("spot", "validation"),
    ] {
        sqlx::query(
            "INSERT INTO measurement_sets (robot_id, name, role, session, payload_kg, format, \
             original, rows_json, row_count, dof) \
             VALUES (1, $1, $2, 's1', 12.5, 'csv', 'q1,q2\n1,2', '[{\"q_deg\":[1.5]}]', 1, 6)",
        )
        .bind(name)
        .bind(role)
        .execute(&pool)
        .await
        .unwrap();
    }
    exec(
        "INSERT INTO calibrations (robot_id, status, methods, identification_set_ids, \
         validation_set_ids, options) VALUES (1, 'succeeded', '[\"km\"]', '[1]', '[2]', '{}')",
    )
    .await;
    exec(
        "INSERT INTO model_versions (robot_id, version, calibration_id, method, model_json, active) \
         VALUES (1, 1, 1, 'km', '{\"m\":1}', 1)",
    )
    .await;
    exec("INSERT INTO activations (robot_id, version_id) VALUES (1, 1)").await;
    for set in [2, 5, 3] {
        sqlx::query(
            "INSERT INTO checks (robot_id, set_id, version, status, mean_mm, result_json) \
             VALUES (1, $1, 1, 'ok', 0.2, '{}')",
        )
        .bind(set)
        .execute(&pool)
        .await
        .unwrap();
    }
    // The newest set deleted: its id (5) must not come back.
    exec("DELETE FROM measurement_sets WHERE id = 5").await;
    exec("DELETE FROM measurement_sets WHERE id = 4").await;
    let sets_before = sets_dump(&pool).await;
    let checks_before = pairs(&pool, "SELECT id, set_id FROM checks ORDER BY id").await;
    assert_eq!(checks_before, [(1, Some(2)), (2, None), (3, Some(3))]);
    let versions_before = pairs(
        &pool,
        "SELECT version, calibration_id FROM model_versions ORDER BY id",
    )
    .await;
    // A check role is refused by the old schema.
    let refused = sqlx::query(
        "INSERT INTO measurement_sets (robot_id, name, role, format, original, rows_json, row_count, dof) \
         VALUES (1, 'c', 'check', 'csv', 'x', '[]', 1, 6)",
    )
    .execute(&pool)
    .await;
    assert!(refused.is_err());
    pool.close().await;

    // The service opens it and applies 0007.
    let db = Db::connect(&url).await.unwrap();
    assert_eq!(db.pending_migrations().await.unwrap(), 0);
    drop(db);
    let pool = SqlitePool::connect_with(options).await.unwrap();
    assert_eq!(sets_dump(&pool).await, sets_before);
    assert_eq!(
        pairs(&pool, "SELECT id, set_id FROM checks ORDER BY id").await,
        checks_before
    );
    assert_eq!(
        pairs(
            &pool,
            "SELECT version, calibration_id FROM model_versions ORDER BY id"
        )
        .await,
        versions_before
    );
    let (activations,): (i64,) = sqlx::query_as("SELECT COUNT(*) FROM activations")
        .fetch_one(&pool)
        .await
        .unwrap();
    assert_eq!(activations, 1);

    // The schema: the index is back, checks still reference the sets, no
    // dangling reference, no table left over.
    let index: Option<String> = sqlx::query_scalar(
        "SELECT sql FROM sqlite_master WHERE type = 'index' AND name = 'measurement_sets_robot'",
    )
    .fetch_optional(&pool)
    .await
    .unwrap();
    assert!(index.is_some_and(|s| s.contains("measurement_sets(robot_id)")));
    let refs: Vec<String> = sqlx::query_scalar(
        "SELECT \"table\" FROM pragma_foreign_key_list('checks') WHERE \"from\" = 'set_id'",
    )
    .fetch_all(&pool)
    .await
    .unwrap();
    assert_eq!(refs, ["measurement_sets"]);
    let dangling = sqlx::query("PRAGMA foreign_key_check")
        .fetch_all(&pool)
        .await
        .unwrap();
    assert!(dangling.is_empty());
    let tables: Vec<String> = sqlx::query_scalar(
        "SELECT name FROM sqlite_master WHERE name LIKE '%measurement_sets%' ORDER BY name",
    )
    .fetch_all(&pool)
    .await
    .unwrap();
    assert_eq!(tables, ["measurement_sets", "measurement_sets_robot"]);

    // The new role is stored; an unknown one is still refused; the deleted
    // set's id is not handed out again.
    let id: i64 = sqlx::query_scalar(
        "INSERT INTO measurement_sets (robot_id, name, role, format, original, rows_json, row_count, dof) \
         VALUES (1, 'c', 'check', 'csv', 'x', '[]', 1, 6) RETURNING id",
    )
    .fetch_one(&pool)
    .await
    .unwrap();
    assert_eq!(id, 6);
    let bogus = sqlx::query(
        "INSERT INTO measurement_sets (robot_id, name, role, format, original, rows_json, row_count, dof) \
         VALUES (1, 'c', 'bogus', 'csv', 'x', '[]', 1, 6)",
    )
    .execute(&pool)
    .await;
    assert!(bogus.is_err());

    // The references still act: deleting set 2 clears its check's set_id,
    // deleting the robot removes its sets.
    sqlx::query("DELETE FROM measurement_sets WHERE id = 2")
        .execute(&pool)
        .await
        .unwrap();
    assert_eq!(
        pairs(&pool, "SELECT id, set_id FROM checks ORDER BY id").await,
        [(1, None), (2, None), (3, Some(3))]
    );
    sqlx::query("DELETE FROM robots WHERE id = 1")
        .execute(&pool)
        .await
        .unwrap();
    let (left,): (i64,) = sqlx::query_as("SELECT COUNT(*) FROM measurement_sets")
        .fetch_one(&pool)
        .await
        .unwrap();
    assert_eq!(left, 0);
}

/// A check as robocal stored it before the `shifted` status (schema 8):
/// every pose's error, a frame shift that explains the errors, status `ok`.
fn old_check_json(poses: usize) -> String {
    use robocal::check::{CheckResult, CheckStatus, FrameShift, PoseError};
    let errors: Vec<f64> = (0..poses).map(|i| 10.0 + 0.01 * i as f64).collect();
    let result = CheckResult {
        position: robocal::stats::ErrorStats::from_errors_mm(&errors),
        orientation: None,
        poses: errors
            .iter()
            .enumerate()
            .map(|(i, e)| PoseError {
                index: i + 1,
                position_mm: *e,
                orientation_deg: None,
            })
            .collect(),
        frame_shift: Some(FrameShift {
            translation_mm: 10.7,
            rotation_deg: 0.01,
            residual_mean_mm: 0.02,
            explains: true,
        }),
        status: CheckStatus::Ok,
        summary: "the errors are a rigid frame shift".into(),
    };
    let mut v = serde_json::to_value(result).unwrap();
    v["thresholds"] = serde_json::json!({
        "degraded_mm": 0.5, "margin_mm": 0.5, "recalibrate_mm": 1.0, "frame_shift_ratio": 0.5
    });
    v.to_string()
}

/// A SQLite file at schema 8 in `dir` with a robot, a check set and two
/// checks in the old form (`ok` and `recalibrate`) of `total` poses each; a
/// third was deleted (its id must not come back). Its URL and options.
async fn schema_8_with_old_checks(
    dir: &std::path::Path,
    total: usize,
) -> (String, SqliteConnectOptions) {
    let (url, options, pool) = at_schema(dir, 8).await;
    sqlx::query("INSERT INTO robots (name, model_json, dof) VALUES ('r', '{}', 6)")
        .execute(&pool)
        .await
        .unwrap();
    sqlx::query(
        "INSERT INTO measurement_sets (robot_id, name, role, format, original, rows_json, row_count, dof) \
         VALUES (1, 'c', 'check', 'csv', 'x', '[]', 1, 6)",
    )
    .execute(&pool)
    .await
    .unwrap();
    for (set, status) in [
        (Some(1), "ok"),
        (None, "recalibrate"),
        (Some(1), "degraded"),
    ] {
        sqlx::query(
            "INSERT INTO checks (robot_id, set_id, version, status, mean_mm, temperature_c, result_json) \
             VALUES (1, $1, 1, $2, 10.5, 21.5, $3)",
        )
        .bind(set)
        .bind(status)
        .bind(old_check_json(total))
        .execute(&pool)
        .await
        .unwrap();
    }
    // The newest check deleted: its id (3) must not come back.
    sqlx::query("DELETE FROM checks WHERE id = 3")
        .execute(&pool)
        .await
        .unwrap();
    let refused = sqlx::query(
        "INSERT INTO checks (robot_id, version, status, mean_mm, result_json) \
         VALUES (1, 1, 'shifted', 1, '{}')",
    )
    .execute(&pool)
    .await;
    assert!(refused.is_err());
    pool.close().await;
    (url, options)
}

/// Migration 0009 (the `shifted` status) on a file at schema 8: the checks
/// keep their ids, columns and the id counter; `shifted` is stored, an
/// unknown status still refused; the old checks read through the service
/// (their `ok` stays as stored, no shift named, the per-pose errors capped).
#[tokio::test]
async fn sqlite_shifted_status_migration_keeps_old_checks_readable() {
    use robocal::service::checks::CHECK_POSES_KEPT;
    let dir = tempfile::tempdir().unwrap();
    let total = CHECK_POSES_KEPT + 50;
    let (url, options) = schema_8_with_old_checks(dir.path(), total).await;
    let pool = SqlitePool::connect_with(options.clone()).await.unwrap();
    let dump =
        "SELECT id, robot_id, set_id, version, status, mean_mm, temperature_c, result_json, \
                created_at FROM checks ORDER BY id";
    type Row = (
        i64,
        i64,
        Option<i64>,
        i64,
        String,
        f64,
        Option<f64>,
        String,
        String,
    );
    let checks_before: Vec<Row> = sqlx::query_as(dump).fetch_all(&pool).await.unwrap();
    pool.close().await;

    let db = Db::connect(&url).await.unwrap();
    assert_eq!(db.pending_migrations().await.unwrap(), 0);
    let pool = SqlitePool::connect_with(options).await.unwrap();
    let checks_after: Vec<Row> = sqlx::query_as(dump).fetch_all(&pool).await.unwrap();
    assert_eq!(checks_after, checks_before);
    let index: Option<String> = sqlx::query_scalar(
        "SELECT sql FROM sqlite_master WHERE type = 'index' AND name = 'checks_robot'",
    )
    .fetch_optional(&pool)
    .await
    .unwrap();
    assert!(index.is_some_and(|s| s.contains("checks(robot_id, id)")));
    let tables: Vec<String> = sqlx::query_scalar(
        "SELECT name FROM sqlite_master WHERE type = 'table' AND name LIKE 'checks%' ORDER BY name",
    )
    .fetch_all(&pool)
    .await
    .unwrap();
    assert_eq!(tables, ["checks"]);
    let id: i64 = sqlx::query_scalar(
        "INSERT INTO checks (robot_id, version, status, mean_mm, result_json) \
         VALUES (1, 1, 'shifted', 1, '{}') RETURNING id",
    )
    .fetch_one(&pool)
    .await
    .unwrap();
    assert_eq!(id, 4);
    let bogus = sqlx::query(
        "INSERT INTO checks (robot_id, version, status, mean_mm, result_json) \
         VALUES (1, 1, 'bogus', 1, '{}')",
    )
    .execute(&pool)
    .await;
    assert!(bogus.is_err());
    sqlx::query("DELETE FROM checks WHERE id = 4")
        .execute(&pool)
        .await
        .unwrap();
    // Deleting the set still clears its checks' set_id.
    sqlx::query("DELETE FROM measurement_sets WHERE id = 1")
        .execute(&pool)
        .await
        .unwrap();
    let sets: Vec<Option<i64>> = sqlx::query_scalar("SELECT set_id FROM checks ORDER BY id")
        .fetch_all(&pool)
        .await
        .unwrap();
    assert_eq!(sets, [None, None]);
    pool.close().await;
    old_checks_read_through_the_service(db, dir, total).await;
}

/// The checks of [`schema_8_with_old_checks`], migrated, through the service
/// (every answer checked against the spec).
async fn old_checks_read_through_the_service(db: Db, dir: tempfile::TempDir, total: usize) {
    use crate::support::{Spec, TestApp};
    use axum::http::StatusCode;
    use robocal::service::checks::CHECK_POSES_KEPT;
    let state = robocal::http::AppState::new(db.clone(), robocal::http::ServiceConfig::default());
    let t = TestApp {
        router: robocal::http::app(state.clone()),
        state,
        db,
        spec: std::sync::Arc::new(Spec::load()),
        _dir: dir,
        _pg: None,
        key: None,
    };
    let r = t.get("/v1/robots/{id}/checks", &["1"]).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let checks = r.json()["checks"].clone();
    assert_eq!(checks[0]["status"], "ok");
    assert_eq!(checks[0]["shift"], serde_json::Value::Null);
    assert_eq!(checks[1]["status"], "recalibrate");
    for c in checks.as_array().unwrap() {
        assert_eq!(c["result"]["poses_total"], total);
        let poses = c["result"]["poses"].as_array().unwrap();
        assert_eq!(poses.len(), CHECK_POSES_KEPT);
        // The largest errors: the last rows.
        assert_eq!(poses[0]["index"], total - CHECK_POSES_KEPT + 1);
    }
    let r = t.get("/v1/robots/{id}/status", &["1"]).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    assert_eq!(r.json()["status"], "recalibrate");
    assert_eq!(r.json()["shift"], serde_json::Value::Null);
}

/// Every column of every cell item, ordered by id, as text.
async fn items_dump(pool: &SqlitePool) -> Vec<String> {
    sqlx::query(
        "SELECT id, robot_id, kind, name, name_key, number, frame, pose_json, created_at, \
         updated_at, load_json FROM cell_items ORDER BY id",
    )
    .fetch_all(pool)
    .await
    .unwrap()
    .iter()
    .map(|r| {
        let (number, load): (Option<i64>, Option<String>) = (r.get(5), r.get(10));
        format!(
            "{}|{}|{}|{}|{}|{number:?}|{}|{}|{}|{}|{load:?}",
            r.get::<i64, _>(0),
            r.get::<i64, _>(1),
            r.get::<String, _>(2),
            r.get::<String, _>(3),
            r.get::<String, _>(4),
            r.get::<String, _>(6),
            r.get::<String, _>(7),
            r.get::<String, _>(8),
            r.get::<String, _>(9),
        )
    })
    .collect()
}

/// `cell_items` at schema 12 (tools with and without loads, work objects in
/// both frames, a deleted item) rebuilt for the `face_plate` frame
/// (migration 0013): every row and the id counter survive; the new frame is
/// stored, an unknown one still refused, the unique keys still hold.
#[tokio::test]
async fn sqlite_face_plate_migration_keeps_the_cell_items() {
    let dir = tempfile::tempdir().unwrap();
    let (url, options, pool) = at_schema(dir.path(), 12).await;
    sqlx::query("INSERT INTO robots (name, model_json, dof) VALUES ('r', '{}', 6)")
        .execute(&pool)
        .await
        .unwrap();
    let insert = "INSERT INTO cell_items (robot_id, kind, name, name_key, number, frame, pose_json, load_json) \
                  VALUES (1, $1, $2, $3, $4, $5, '{\"xyz_mm\":[1,2,3],\"rpy_deg\":[0,0,9]}', $6)";
    for (kind, name, number, frame, load) in [
        (
            "tool",
            "Torch",
            Some(1),
            "flange",
            Some("{\"mass_kg\":2.5}"),
        ),
        ("tool", "gun", None, "flange", None),
        ("work_object", "table", Some(2), "base", None),
        ("work_object", "fixture", Some(3), "measurement", None),
        ("work_object", "gone", Some(4), "base", None),
    ] {
        sqlx::query(insert)
            .bind(kind)
            .bind(name)
            .bind(name.to_ascii_lowercase())
            .bind(number)
            .bind(frame)
            .bind(load)
            .execute(&pool)
            .await
            .unwrap();
    }
    sqlx::query("DELETE FROM cell_items WHERE name = 'gone'")
        .execute(&pool)
        .await
        .unwrap();
    let plate = |name: &'static str, number: i64| {
        sqlx::query(insert)
            .bind("work_object")
            .bind(name)
            .bind(name.to_ascii_lowercase())
            .bind(number)
            .bind("face_plate")
            .bind(None::<String>)
    };
    assert!(plate("part", 6).execute(&pool).await.is_err());
    let before = items_dump(&pool).await;
    assert_eq!(before.len(), 4);
    pool.close().await;

    let db = Db::connect(&url).await.unwrap();
    assert_eq!(db.pending_migrations().await.unwrap(), 0);
    drop(db);
    let pool = SqlitePool::connect_with(options).await.unwrap();
    assert_eq!(items_dump(&pool).await, before);
    let id = plate("part", 6)
        .execute(&pool)
        .await
        .unwrap()
        .last_insert_rowid();
    assert_eq!(id, 6, "the deleted item's id is not handed out again");
    let bogus = sqlx::query(insert)
        .bind("work_object")
        .bind("x")
        .bind("x")
        .bind(7)
        .bind("world")
        .bind(None::<String>)
        .execute(&pool)
        .await;
    assert!(bogus.is_err());
    assert!(
        plate("PART", 8).execute(&pool).await.is_err(),
        "name_key unique"
    );
    assert!(
        plate("other", 6).execute(&pool).await.is_err(),
        "number unique"
    );
    let dangling = sqlx::query("PRAGMA foreign_key_check")
        .fetch_all(&pool)
        .await
        .unwrap();
    assert!(dangling.is_empty());
}
