//! Schema migrations on a database that already holds data: a SQLite file at
//! schema 6 (sets, a calibration, versions, checks referencing the sets) is
//! opened by the service, which rebuilds `measurement_sets` for the `check`
//! role (migration 0007); every row, reference, index and id counter survives.

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

async fn pairs(pool: &SqlitePool, sql: &str) -> Vec<(i64, Option<i64>)> {
    sqlx::query_as(sql).fetch_all(pool).await.unwrap()
}

#[tokio::test]
async fn sqlite_check_role_migration_keeps_sets_versions_and_check_references() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("old.db");
    let url = format!("sqlite://{}?mode=rwc", path.display());
    let options = SqliteConnectOptions::from_str(&url)
        .unwrap()
        .foreign_keys(true);
    let pool = SqlitePool::connect_with(options.clone()).await.unwrap();
    // The schema as it was before the `check` role: migrations 1 to 6.
    let mut old = sqlx::migrate!("migrations/sqlite");
    let before: Vec<_> = old
        .migrations
        .iter()
        .filter(|m| m.version <= 6)
        .cloned()
        .collect();
    assert_eq!(before.len(), 6);
    old.migrations = Cow::Owned(before);
    old.run(&pool).await.unwrap();

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
