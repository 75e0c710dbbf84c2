-- robocal schema, version 16: a track's station sets keep their track value.
-- POST /v1/robots/{id}/track/measurement-sets stores a measurement file with
-- a track's column as one set per track value (station); each such set now
-- names that column and its value (mm, as the file gave it), so the track can
-- be fitted from the stored sets (POST /v1/robots/{id}/track/calibrate with
-- `set_ids`). Both NULL for every other set, and for station sets stored
-- before this version (their value is in their original text only).
ALTER TABLE measurement_sets ADD COLUMN axis_column TEXT
    CHECK (axis_column IS NULL OR axis_column IN ('e1', 'e2', 'e3', 'e4', 'e5', 'e6'));
ALTER TABLE measurement_sets ADD COLUMN axis_value REAL;
-- A stored track fitted from stored sets names them (a JSON array of ids);
-- NULL for one fitted from a posted file.
ALTER TABLE robot_tracks ADD COLUMN set_ids TEXT;
-- Each stored track, positioner and turntable keeps the request that fitted
-- it (its calibrate body as JSON, the track's with the version it held), so
-- its readings are not lost and GET …/fit-request gives a body that fits it
-- again; NULL for fits stored before this version.
ALTER TABLE robot_tracks ADD COLUMN fit_request TEXT;
ALTER TABLE robot_positioners ADD COLUMN fit_request TEXT;
ALTER TABLE robot_turntables ADD COLUMN fit_request TEXT;
