-- robocal schema for PostgreSQL, version 9: a running job's progress names
-- what it is on, as migrations/sqlite/0010.
ALTER TABLE calibrations ADD COLUMN progress_detail TEXT;
