-- robocal schema, version 14: a positioner fitted from touches with a
-- calibrated tool (issue 46) says so. POST /v1/robots/{id}/positioner/calibrate
-- with `touched_with` reads touches (joints files placed by a model version
-- carrying a cell tool) instead of tracker readings; the stored positioner
-- names that version's number and the tool. Both NULL for tracker readings,
-- as every positioner stored before this version was fitted.
ALTER TABLE robot_positioners ADD COLUMN touched_version INTEGER;
ALTER TABLE robot_positioners ADD COLUMN touched_tool TEXT;
