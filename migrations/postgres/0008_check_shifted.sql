-- robocal schema for PostgreSQL, version 8: the `shifted` status of a check
-- (issue 42), as migrations/sqlite/0009. The constraint is the one the
-- column's inline CHECK of 0004 created (PostgreSQL names it
-- <table>_<column>_check); it is replaced in place, no row moves.
ALTER TABLE checks
    DROP CONSTRAINT checks_status_check,
    ADD CONSTRAINT checks_status_check
        CHECK (status IN ('ok', 'degraded', 'recalibrate', 'shifted'));
