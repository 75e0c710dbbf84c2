-- robocal schema, version 3: job claims.
--
-- On PostgreSQL replicas claim queued jobs (migrations/postgres/0002); the
-- columns exist here too so both stores run the same statements. On SQLite
-- the one process owns every job and they stay NULL / 0.
-- claim: token of the runner's claim, which every write of the job must match.
ALTER TABLE calibrations ADD COLUMN claim TEXT;
-- When the claim lapses unless renewed (unused on SQLite).
ALTER TABLE calibrations ADD COLUMN lease_expires_at TEXT;
-- How many times a runner claimed the job.
ALTER TABLE calibrations ADD COLUMN attempts INTEGER NOT NULL DEFAULT 0;
