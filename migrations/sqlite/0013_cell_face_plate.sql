-- robocal schema, version 13: a work object on the positioner's face plate
-- (issue 46). Its pose is stated on the plate (`frame = 'face_plate'`); only
-- a program filter given the positioner places it.
--
-- SQLite cannot alter a CHECK constraint, so the table is rebuilt after
-- SQLite's documented procedure, as migration 0007 rebuilt measurement_sets:
-- create the new table, copy the rows with their ids, drop the old one,
-- rename the new one to the old name, carry the AUTOINCREMENT counter over.
-- No table references cell_items, so the drop fires no foreign-key action.

CREATE TEMP TABLE migrate_0013_seq AS
    SELECT seq FROM sqlite_sequence WHERE name = 'cell_items';

CREATE TABLE cell_items_new (
    id          INTEGER PRIMARY KEY AUTOINCREMENT,
    robot_id    INTEGER NOT NULL REFERENCES robots(id) ON DELETE CASCADE,
    -- 'tool' or 'work_object'.
    kind        TEXT    NOT NULL CHECK (kind IN ('tool', 'work_object')),
    name        TEXT    NOT NULL,
    -- The name in ASCII lower case: names are unique per robot and kind
    -- regardless of case, as programs refer to them.
    name_key    TEXT    NOT NULL,
    -- The controller's number (KUKA TOOL_DATA[n]/BASE_DATA[n], Fanuc UT/UF).
    number      INTEGER,
    -- Work objects: 'base', 'measurement' or 'face_plate'; tools: 'flange'.
    frame       TEXT    NOT NULL CHECK (frame IN ('flange', 'base', 'measurement', 'face_plate')),
    -- The pose as the API takes it: {"xyz_mm": [..], "rpy_deg": [..]}.
    pose_json   TEXT    NOT NULL,
    created_at  TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
    updated_at  TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
    -- A tool's load (migration 0006); NULL for work objects.
    load_json   TEXT,
    UNIQUE (robot_id, kind, name_key),
    UNIQUE (robot_id, kind, number)
);

INSERT INTO cell_items_new (id, robot_id, kind, name, name_key, number, frame, pose_json,
        created_at, updated_at, load_json)
    SELECT id, robot_id, kind, name, name_key, number, frame, pose_json,
        created_at, updated_at, load_json
    FROM cell_items;

DROP TABLE cell_items;
ALTER TABLE cell_items_new RENAME TO cell_items;

UPDATE sqlite_sequence
    SET seq = MAX(seq, (SELECT seq FROM temp.migrate_0013_seq))
    WHERE name = 'cell_items' AND EXISTS (SELECT 1 FROM temp.migrate_0013_seq);
INSERT INTO sqlite_sequence (name, seq)
    SELECT 'cell_items', seq FROM temp.migrate_0013_seq
    WHERE NOT EXISTS (SELECT 1 FROM sqlite_sequence WHERE name = 'cell_items');

DROP TABLE temp.migrate_0013_seq;
