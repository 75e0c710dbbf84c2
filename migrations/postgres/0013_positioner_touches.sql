-- robocal schema for PostgreSQL, version 13: a positioner fitted from touches
-- with a calibrated tool says so, as migrations/sqlite/0014. Both NULL for
-- tracker readings, as every positioner stored before this version was fitted.
ALTER TABLE robot_positioners
    ADD COLUMN touched_version BIGINT,
    ADD COLUMN touched_tool TEXT;
