-- robocal schema for PostgreSQL, version 6: the `check` role of a measurement
-- set (issue 33), as migrations/sqlite/0007. A check set is scored by checks
-- and re-registrations, never fitted on. The constraint is the one the
-- column's inline CHECK of 0001 created (PostgreSQL names it
-- <table>_<column>_check); it is replaced in place, no row moves.
ALTER TABLE measurement_sets
    DROP CONSTRAINT measurement_sets_role_check,
    ADD CONSTRAINT measurement_sets_role_check
        CHECK (role IN ('identification', 'training', 'validation', 'check'));
