-- robocal schema, version 10: a running job's progress names what it is on.
--
-- `progress_detail` holds, as one JSON document, what a progress report adds
-- to phase, iteration and percent (records::ProgressDetail): the candidate
-- and cross-validation fold the phase works on, the residual and the
-- estimated seconds left. NULL while nothing is known (queued, starting,
-- done, a job queued before this version).
ALTER TABLE calibrations ADD COLUMN progress_detail TEXT;
