-- robocal schema for PostgreSQL, version 12: a work object on the positioner's
-- face plate (issue 46), as migrations/sqlite/0013. The constraint is the one
-- the column's inline CHECK of 0003 created (<table>_<column>_check); it is
-- replaced in place, no row moves.
ALTER TABLE cell_items
    DROP CONSTRAINT cell_items_frame_check,
    ADD CONSTRAINT cell_items_frame_check
        CHECK (frame IN ('flange', 'base', 'measurement', 'face_plate'));
