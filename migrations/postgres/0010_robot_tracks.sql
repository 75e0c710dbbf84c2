-- robocal schema for PostgreSQL, version 10: a linear track carrying a
-- robot, as migrations/sqlite/0011.
--
-- One calibrated track per robot (model::external::LinearTrack), fitted by
-- POST /v1/robots/{id}/track/calibrate from tracker readings at several
-- track values with the robot's calibrated version held; a refit replaces
-- it. `track_json` is the track's JSON description exactly as
-- `robocal track calibrate --out` writes it (mm, degrees, arcsec).
CREATE TABLE robot_tracks (
    robot_id    BIGINT  PRIMARY KEY REFERENCES robots(id) ON DELETE CASCADE,
    -- The model version the fit held (its number, not its row).
    version     BIGINT  NOT NULL,
    -- The measurement file's column of the track's value: 'e1' … 'e6'.
    axis_column TEXT    NOT NULL CHECK (axis_column IN ('e1', 'e2', 'e3', 'e4', 'e5', 'e6')),
    -- The tracker's σ per coordinate the fit was judged against [mm].
    sigma_mm    DOUBLE PRECISION NOT NULL,
    -- The highest carriage-map order tried.
    max_order   BIGINT  NOT NULL,
    readings    BIGINT  NOT NULL,
    stations    BIGINT  NOT NULL,
    -- The fit's residuals through the track and the held robot [mm].
    rms_mm      DOUBLE PRECISION NOT NULL,
    max_mm      DOUBLE PRECISION NOT NULL,
    track_json  TEXT    NOT NULL,
    created_at  TEXT    NOT NULL DEFAULT robocal_now()
);
