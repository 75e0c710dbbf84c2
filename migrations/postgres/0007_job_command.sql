-- robocal schema for PostgreSQL, version 7: a calibration job keeps the
-- command it runs (issue 34), as migrations/sqlite/0008. NULL for a job queued
-- before this version, which runs from its format-1 columns (methods, set ids,
-- options).
ALTER TABLE calibrations ADD COLUMN command TEXT;
