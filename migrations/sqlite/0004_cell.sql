-- robocal schema, version 4: the cell around a robot (issue 21).
--
-- Named production tools (TCP pose in the flange frame) and work objects
-- (pose in the robot base frame or the measurement frame), the entries of a
-- cell file (core::cell::file) stored per robot.
CREATE TABLE cell_items (
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
    -- Work objects: 'base' or 'measurement'; tools: 'flange'.
    frame       TEXT    NOT NULL CHECK (frame IN ('flange', 'base', 'measurement')),
    -- The pose as the API takes it: {"xyz_mm": [..], "rpy_deg": [..]}.
    pose_json   TEXT    NOT NULL,
    created_at  TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
    updated_at  TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
    UNIQUE (robot_id, kind, name_key),
    UNIQUE (robot_id, kind, number)
);
