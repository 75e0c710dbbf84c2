-- robocal schema, version 1.
--
-- Conventions: integer surrogate keys; timestamps are UTC RFC 3339 text with
-- milliseconds (strftime('%Y-%m-%dT%H:%M:%fZ')); JSON columns hold text
-- produced by the service (mm/deg boundary units, never SI); every row that
-- belongs to a robot is deleted with it (ON DELETE CASCADE; the service
-- turns foreign keys on for every connection).

-- A robot of the cell: its nominal model (what the controller knows).
CREATE TABLE robots (
    id          INTEGER PRIMARY KEY AUTOINCREMENT,
    name        TEXT    NOT NULL,
    -- Preset name when created from a preset (ys100, hh800, ur5, ur10), else NULL.
    preset      TEXT,
    -- Model description JSON (model::ModelDescription, mm/deg), validated on upload.
    model_json  TEXT    NOT NULL,
    dof         INTEGER NOT NULL CHECK (dof BETWEEN 2 AND 7),
    -- Free JSON object supplied by the user (cell, serial number, ...).
    metadata    TEXT    NOT NULL DEFAULT '{}',
    created_at  TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
    updated_at  TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))
);

-- A measurement set: joint readings paired with measured TCP positions.
CREATE TABLE measurement_sets (
    id            INTEGER PRIMARY KEY AUTOINCREMENT,
    robot_id      INTEGER NOT NULL REFERENCES robots(id) ON DELETE CASCADE,
    name          TEXT    NOT NULL,
    -- Data role (DESIGN "Data roles"): Q1 identification, Q2 training, Q3 validation.
    role          TEXT    NOT NULL CHECK (role IN ('identification', 'training', 'validation')),
    -- Tracker session label: sets measured from one tracker placement share it.
    session       TEXT    NOT NULL DEFAULT 'default',
    -- Payload carried during the measurement [kg] for rows without their own value.
    payload_kg    REAL,
    -- Declared units of the upload: length 'mm' | 'm', angle 'deg' | 'rad'.
    length_unit   TEXT    NOT NULL DEFAULT 'mm' CHECK (length_unit IN ('mm', 'm')),
    angle_unit    TEXT    NOT NULL DEFAULT 'deg' CHECK (angle_unit IN ('deg', 'rad')),
    -- The upload exactly as received, and its format ('csv' or 'json').
    format        TEXT    NOT NULL CHECK (format IN ('csv', 'json')),
    original      TEXT    NOT NULL,
    -- Parsed rows (measure::MeasuredPose list, converted to mm/deg), shortest
    -- round-trip numbers, so the rows read back bit for bit.
    rows_json     TEXT    NOT NULL,
    row_count     INTEGER NOT NULL CHECK (row_count > 0),
    dof           INTEGER NOT NULL,
    created_at    TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))
);
CREATE INDEX measurement_sets_robot ON measurement_sets(robot_id);

-- A calibration job and, once it succeeded, its report.
CREATE TABLE calibrations (
    id                  INTEGER PRIMARY KEY AUTOINCREMENT,
    robot_id            INTEGER NOT NULL REFERENCES robots(id) ON DELETE CASCADE,
    status              TEXT    NOT NULL CHECK (status IN ('queued', 'running', 'succeeded', 'failed', 'cancelled')),
    -- Progress: current phase (registration, identifiability, km, ...), iteration, percent 0..100.
    phase               TEXT,
    iteration           INTEGER NOT NULL DEFAULT 0,
    percent             REAL    NOT NULL DEFAULT 0,
    cancel_requested    INTEGER NOT NULL DEFAULT 0,
    -- JSON array of method names, e.g. ["km","skcm"].
    methods             TEXT    NOT NULL,
    -- JSON arrays of measurement set ids (the rows were read when the job was queued).
    identification_set_ids TEXT NOT NULL,
    validation_set_ids  TEXT    NOT NULL,
    -- The request's options (seed, population, generations, register, ...), JSON.
    options             TEXT    NOT NULL,
    -- Why the job failed or was cancelled.
    error               TEXT,
    -- identify::CalibrationReport as JSON (mm/deg), when succeeded.
    report              TEXT,
    best_method         TEXT,
    created_at          TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
    started_at          TEXT,
    finished_at         TEXT,
    updated_at          TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))
);
CREATE INDEX calibrations_robot ON calibrations(robot_id);
CREATE INDEX calibrations_status ON calibrations(status);

-- A calibrated model: one per method of each successful calibration.
CREATE TABLE model_versions (
    id              INTEGER PRIMARY KEY AUTOINCREMENT,
    robot_id        INTEGER NOT NULL REFERENCES robots(id) ON DELETE CASCADE,
    -- 1, 2, 3, ... per robot.
    version         INTEGER NOT NULL,
    calibration_id  INTEGER REFERENCES calibrations(id) ON DELETE SET NULL,
    method          TEXT    NOT NULL,
    -- compensate::CalibratedModelFile JSON (format robocal-calibrated-model/1, mm/deg).
    model_json      TEXT    NOT NULL,
    -- Error statistics of the calibration for this method (mm), JSON.
    stats_json      TEXT    NOT NULL DEFAULT '{}',
    -- Exactly one active version per robot at most (enforced by the index below).
    active          INTEGER NOT NULL DEFAULT 0 CHECK (active IN (0, 1)),
    created_at      TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
    UNIQUE (robot_id, version)
);
CREATE UNIQUE INDEX model_versions_one_active ON model_versions(robot_id) WHERE active = 1;

-- Activation history, a stack per robot: activating pushes, rolling back marks
-- the newest entry undone and re-activates the entry below it.
CREATE TABLE activations (
    id          INTEGER PRIMARY KEY AUTOINCREMENT,
    robot_id    INTEGER NOT NULL REFERENCES robots(id) ON DELETE CASCADE,
    version_id  INTEGER NOT NULL REFERENCES model_versions(id) ON DELETE CASCADE,
    undone      INTEGER NOT NULL DEFAULT 0 CHECK (undone IN (0, 1)),
    created_at  TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))
);
CREATE INDEX activations_robot ON activations(robot_id, id);
