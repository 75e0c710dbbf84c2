-- robocal schema, version 12: a two-axis positioner beside a robot.
--
-- One calibrated tilt-rotate positioner per robot (model::external::TiltRotate),
-- fitted by POST /v1/robots/{id}/positioner/calibrate from tracker readings of
-- reflectors on its face plate; a refit replaces it. `positioner_json` is the
-- positioner's JSON description exactly as `robocal positioner calibrate --out`
-- writes it (mm, degrees), stated in the cell (tracker) frame the robot is
-- registered in.
CREATE TABLE robot_positioners (
    robot_id        INTEGER PRIMARY KEY REFERENCES robots(id) ON DELETE CASCADE,
    -- The measurement files' columns of axis 1 (tilt) and axis 2 (rotate).
    tilt_column     TEXT    NOT NULL CHECK (tilt_column IN ('e1', 'e2', 'e3', 'e4', 'e5', 'e6')),
    rotate_column   TEXT    NOT NULL CHECK (rotate_column IN ('e1', 'e2', 'e3', 'e4', 'e5', 'e6')),
    -- The tracker's σ per coordinate the fit was judged against [mm].
    sigma_mm        REAL    NOT NULL,
    reflectors      INTEGER NOT NULL,
    readings        INTEGER NOT NULL,
    -- The fit's 3-D residuals [mm].
    rms_mm          REAL    NOT NULL,
    max_mm          REAL    NOT NULL,
    positioner_json TEXT    NOT NULL,
    created_at      TEXT    NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))
);
