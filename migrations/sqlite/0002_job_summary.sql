-- robocal schema, version 2.
--
-- A finished calibration's summary, so a job's status answers "how good is
-- it" without the full report: the best method (by validation mean, or
-- identification mean without validation data), its mean and maximum error,
-- the nominal model's mean on the same poses, warnings and failed methods.
-- JSON (db::JobSummary, mm); NULL until the job succeeds.
ALTER TABLE calibrations ADD COLUMN summary TEXT;
