-- robocal schema, version 7: the `check` role of a measurement set (issue 33).
--
-- A set of role `check` is scored by checks and re-registrations, never fitted
-- on. SQLite cannot alter a CHECK constraint, so the table is rebuilt after
-- SQLite's documented procedure (https://sqlite.org/lang_altertable.html,
-- "Making Other Kinds Of Table Schema Changes"): create the new table, copy the
-- rows with their ids, drop the old one, rename the new one to the old name
-- (never the other way round: renaming the old table would rewrite the other
-- tables' references to it), recreate the indexes.
--
-- One difference: the migrator runs every migration in a transaction, where
-- `PRAGMA foreign_keys = OFF` has no effect, so foreign keys stay on and the
-- DROP's implicit DELETE fires the actions of the tables that reference
-- measurement_sets. The only such reference is checks.set_id (ON DELETE SET
-- NULL, migrations 0005); its values are saved before the drop and restored
-- after the rename. The AUTOINCREMENT counter is carried over too, so the id of
-- a deleted set is never handed out again (calibrations name sets by id).

CREATE TEMP TABLE migrate_0007_check_sets AS
    SELECT id, set_id FROM checks WHERE set_id IS NOT NULL;
CREATE TEMP TABLE migrate_0007_seq AS
    SELECT seq FROM sqlite_sequence WHERE name = 'measurement_sets';

CREATE TABLE measurement_sets_new (
    id            INTEGER PRIMARY KEY AUTOINCREMENT,
    robot_id      INTEGER NOT NULL REFERENCES robots(id) ON DELETE CASCADE,
    name          TEXT    NOT NULL,
    -- Data role (DESIGN "Data roles"): Q1 identification, Q2 training, Q3
    -- validation; check: scored by checks and re-registrations, never fitted on.
    role          TEXT    NOT NULL CHECK (role IN ('identification', 'training', 'validation', 'check')),
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

INSERT INTO measurement_sets_new (id, robot_id, name, role, session, payload_kg,
        length_unit, angle_unit, format, original, rows_json, row_count, dof, created_at)
    SELECT id, robot_id, name, role, session, payload_kg,
        length_unit, angle_unit, format, original, rows_json, row_count, dof, created_at
    FROM measurement_sets;

DROP TABLE measurement_sets;
ALTER TABLE measurement_sets_new RENAME TO measurement_sets;
CREATE INDEX measurement_sets_robot ON measurement_sets(robot_id);

UPDATE sqlite_sequence
    SET seq = MAX(seq, (SELECT seq FROM temp.migrate_0007_seq))
    WHERE name = 'measurement_sets' AND EXISTS (SELECT 1 FROM temp.migrate_0007_seq);
INSERT INTO sqlite_sequence (name, seq)
    SELECT 'measurement_sets', seq FROM temp.migrate_0007_seq
    WHERE NOT EXISTS (SELECT 1 FROM sqlite_sequence WHERE name = 'measurement_sets');

UPDATE checks
    SET set_id = (SELECT s.set_id FROM temp.migrate_0007_check_sets s WHERE s.id = checks.id)
    WHERE id IN (SELECT id FROM temp.migrate_0007_check_sets);

DROP TABLE temp.migrate_0007_check_sets;
DROP TABLE temp.migrate_0007_seq;
