-- robocal schema, version 5: check poses (issue 33, "Is it still accurate?").
--
-- A check scores a measurement set against a model version without fitting
-- (core::check); the robot's status is its latest check's, judged with the
-- robot's thresholds (defaults in core::check::CheckThresholds when none are set).
CREATE TABLE checks (
    id              INTEGER PRIMARY KEY AUTOINCREMENT,
    robot_id        INTEGER NOT NULL REFERENCES robots(id) ON DELETE CASCADE,
    -- The set scored; NULL once that set is deleted (the figures stay).
    set_id          INTEGER REFERENCES measurement_sets(id) ON DELETE SET NULL,
    -- The version number scored against.
    version         INTEGER NOT NULL,
    status          TEXT    NOT NULL CHECK (status IN ('ok', 'degraded', 'recalibrate')),
    mean_mm         REAL    NOT NULL,
    -- Temperature during the check [°C], when given.
    temperature_c   REAL,
    -- core::check::CheckResult and the thresholds used, JSON (mm/deg).
    result_json     TEXT    NOT NULL,
    created_at      TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))
);
CREATE INDEX checks_robot ON checks(robot_id, id);

-- Per-robot thresholds of the status (core::check::CheckThresholds, mm).
CREATE TABLE check_thresholds (
    robot_id          INTEGER PRIMARY KEY REFERENCES robots(id) ON DELETE CASCADE,
    degraded_mm       REAL NOT NULL,
    recalibrate_mm    REAL NOT NULL,
    frame_shift_ratio REAL NOT NULL,
    updated_at        TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))
);
