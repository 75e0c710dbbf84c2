-- robocal schema, version 8: a calibration job keeps the command it runs
-- (issue 34).
--
-- `command` holds the job's start command as one JSON document with its
-- format number ({"format": 2, "methods": [...], ...}); the runner reads it as
-- it is. A job queued before this version has NULL here and runs from the
-- columns it was stored with (methods, identification_set_ids,
-- validation_set_ids, options: format 1). Those columns are still written for
-- every job: they are what the API shows.
ALTER TABLE calibrations ADD COLUMN command TEXT;
