-- robocal schema for PostgreSQL, version 2: jobs shared by replicas.
--
-- A replica claims a queued job (SELECT ... FOR UPDATE SKIP LOCKED), sets
-- `claim` to a new token and holds a lease it renews while the job runs. A
-- job whose lease lapsed (its replica died) is claimed again by another
-- replica and run from the start; every write of a job's runner must match
-- its claim, so a job is stored by one runner only.
ALTER TABLE calibrations ADD COLUMN claim TEXT;
ALTER TABLE calibrations ADD COLUMN lease_expires_at TIMESTAMPTZ;
-- How many times a runner claimed the job (a job interrupted too often fails).
ALTER TABLE calibrations ADD COLUMN attempts BIGINT NOT NULL DEFAULT 0;
-- The queue: the few jobs that are queued or running.
CREATE INDEX calibrations_active ON calibrations(id) WHERE status IN ('queued', 'running');
