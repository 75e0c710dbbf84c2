-- robocal schema for PostgreSQL, version 15: a track's station sets keep
-- their track value, as migrations/sqlite/0016.
ALTER TABLE measurement_sets ADD COLUMN axis_column TEXT
    CHECK (axis_column IS NULL OR axis_column IN ('e1', 'e2', 'e3', 'e4', 'e5', 'e6'));
ALTER TABLE measurement_sets ADD COLUMN axis_value DOUBLE PRECISION;
ALTER TABLE robot_tracks ADD COLUMN set_ids TEXT;
