-- robocal schema for PostgreSQL, version 11: a two-axis positioner beside a
-- robot, as migrations/sqlite/0012.
--
-- One calibrated tilt-rotate positioner per robot (model::external::TiltRotate),
-- fitted by POST /v1/robots/{id}/positioner/calibrate from tracker readings of
-- reflectors on its face plate; a refit replaces it. `positioner_json` is the
-- positioner's JSON description exactly as `robocal positioner calibrate --out`
-- writes it (mm, degrees), stated in the cell (tracker) frame the robot is
-- registered in.
CREATE TABLE robot_positioners (
    robot_id        BIGINT  PRIMARY KEY REFERENCES robots(id) ON DELETE CASCADE,
    -- The measurement files' columns of axis 1 (tilt) and axis 2 (rotate).
    tilt_column     TEXT    NOT NULL CHECK (tilt_column IN ('e1', 'e2', 'e3', 'e4', 'e5', 'e6')),
    rotate_column   TEXT    NOT NULL CHECK (rotate_column IN ('e1', 'e2', 'e3', 'e4', 'e5', 'e6')),
    -- The tracker's σ per coordinate the fit was judged against [mm].
    sigma_mm        DOUBLE PRECISION NOT NULL,
    reflectors      BIGINT  NOT NULL,
    readings        BIGINT  NOT NULL,
    -- The fit's 3-D residuals [mm].
    rms_mm          DOUBLE PRECISION NOT NULL,
    max_mm          DOUBLE PRECISION NOT NULL,
    positioner_json TEXT    NOT NULL,
    created_at      TEXT    NOT NULL DEFAULT robocal_now()
);
