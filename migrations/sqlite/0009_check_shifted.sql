-- robocal schema, version 9: the `shifted` status of a check (issue 42).
--
-- A check whose errors a rigid frame shift explains (the robot's base or the
-- tracker moved) gets the status `shifted`, never `ok`
-- (core::check::CheckStatus). SQLite cannot alter a CHECK constraint, so the
-- table is rebuilt as migration 0007 rebuilt measurement_sets (SQLite's
-- documented procedure, https://sqlite.org/lang_altertable.html): create the
-- new table, copy the rows with their ids, drop the old one, rename the new
-- one to the old name, recreate the index. No table references checks. The
-- AUTOINCREMENT counter is carried over, so the id of a deleted check is never
-- handed out again.

CREATE TEMP TABLE migrate_0009_seq AS
    SELECT seq FROM sqlite_sequence WHERE name = 'checks';

CREATE TABLE checks_new (
    id              INTEGER PRIMARY KEY AUTOINCREMENT,
    robot_id        INTEGER NOT NULL REFERENCES robots(id) ON DELETE CASCADE,
    -- The set scored; NULL once that set is deleted (the figures stay).
    set_id          INTEGER REFERENCES measurement_sets(id) ON DELETE SET NULL,
    -- The version number scored against.
    version         INTEGER NOT NULL,
    -- core::check::CheckStatus names.
    status          TEXT    NOT NULL CHECK (status IN ('ok', 'degraded', 'recalibrate', 'shifted')),
    mean_mm         REAL    NOT NULL,
    -- Temperature during the check [°C], when given.
    temperature_c   REAL,
    -- core::check::CheckResult and the thresholds used, JSON (mm/deg); the
    -- per-pose errors at most service::checks::CHECK_POSES_KEPT of them.
    result_json     TEXT    NOT NULL,
    created_at      TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))
);

INSERT INTO checks_new (id, robot_id, set_id, version, status, mean_mm, temperature_c,
        result_json, created_at)
    SELECT id, robot_id, set_id, version, status, mean_mm, temperature_c, result_json, created_at
    FROM checks;

DROP TABLE checks;
ALTER TABLE checks_new RENAME TO checks;
CREATE INDEX checks_robot ON checks(robot_id, id);

UPDATE sqlite_sequence
    SET seq = MAX(seq, (SELECT seq FROM temp.migrate_0009_seq))
    WHERE name = 'checks' AND EXISTS (SELECT 1 FROM temp.migrate_0009_seq);
INSERT INTO sqlite_sequence (name, seq)
    SELECT 'checks', seq FROM temp.migrate_0009_seq
    WHERE NOT EXISTS (SELECT 1 FROM sqlite_sequence WHERE name = 'checks');

DROP TABLE temp.migrate_0009_seq;
