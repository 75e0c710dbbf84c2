-- robocal schema for PostgreSQL, version 14: a one-axis turntable beside a
-- robot, as migrations/sqlite/0015.
--
-- One calibrated turntable per robot (model::external::Turntable), fitted by
-- POST /v1/robots/{id}/turntable/calibrate from tracker readings of
-- reflectors on its face plate; a refit replaces it. `turntable_json` is the
-- turntable's JSON description exactly as `robocal turntable calibrate --out`
-- writes it (mm, degrees), stated in the cell (tracker) frame the robot is
-- registered in.
CREATE TABLE robot_turntables (
    robot_id        BIGINT  PRIMARY KEY REFERENCES robots(id) ON DELETE CASCADE,
    -- The measurement files' column of the axis's value.
    value_column    TEXT    NOT NULL CHECK (value_column IN ('e1', 'e2', 'e3', 'e4', 'e5', 'e6')),
    -- The tracker's σ per coordinate the fit was judged against [mm].
    sigma_mm        DOUBLE PRECISION NOT NULL,
    reflectors      BIGINT  NOT NULL,
    readings        BIGINT  NOT NULL,
    -- The fit's 3-D residuals [mm].
    rms_mm          DOUBLE PRECISION NOT NULL,
    max_mm          DOUBLE PRECISION NOT NULL,
    turntable_json  TEXT    NOT NULL,
    created_at      TEXT    NOT NULL DEFAULT robocal_now()
);
