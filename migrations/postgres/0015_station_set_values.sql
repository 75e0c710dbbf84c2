-- robocal schema for PostgreSQL, version 15: a track's station sets keep
-- their track value, as migrations/sqlite/0016.
ALTER TABLE measurement_sets ADD COLUMN axis_column TEXT
    CHECK (axis_column IS NULL OR axis_column IN ('e1', 'e2', 'e3', 'e4', 'e5', 'e6'));
ALTER TABLE measurement_sets ADD COLUMN axis_value DOUBLE PRECISION;
ALTER TABLE robot_tracks ADD COLUMN set_ids TEXT;
-- Each stored track, positioner and turntable keeps the request that fitted
-- it (its calibrate body as JSON, the track's with the version it held), so
-- its readings are not lost and GET …/fit-request gives a body that fits it
-- again; NULL for fits stored before this version.
ALTER TABLE robot_tracks ADD COLUMN fit_request TEXT;
ALTER TABLE robot_positioners ADD COLUMN fit_request TEXT;
ALTER TABLE robot_turntables ADD COLUMN fit_request TEXT;
