//! External-axis values corrected on request (`FilterAxes::correct_values`):
//! the value written to the program is the one at which the real axis
//! stands where the controller believes the programmed value puts it, so
//! the robot's correction is left with what no axis value can hold.
//!
//! Track: the programmed value `e` moves the robot's base by
//! `N(e) − N(r)` from the middle of the travel measured, `r`, by the
//! controller's nominal track; the written value `e'` is the one at which
//! the calibrated track moves it most nearly so, `B(e') − B(r)` (the
//! scale and the carriage's error along the rail). Displacements, not
//! places: the track's zero along the rail and the robot's registration
//! are one unknown of the fit (the calibrated robot's base frame is its
//! own convention), so a place would trade the one for the other. A bent
//! rail's sideways and vertical errors, the carriage's angles and any
//! offset at `r` stay the robot's to correct. Newton steps along the rail,
//! the slope by a 1 mm difference.
//!
//! Positioner: the programmed values `v` turn the face plate to `P_nom(v)`
//! in the controller's world; the written values `v'` are those at which
//! the calibrated plate `P(v')`, seen in that world, turns the part most
//! nearly as the controller believes (the zero offsets and scales; tilted
//! axis lines stay the robot's to correct): Gauss–Newton on the rotation
//! vector `θ·n` of `R_nom(v)ᵀ·R(v') = Rot(n, θ)` (`orientation::
//! rotation_log`, exact near the identity), the Jacobian by 1e-4°
//! differences. The
//! part's position follows from the robot's solve as before. A one-axis
//! turntable's value likewise, its axis 1 standing at 0 ([`turntable_value`]).
//!
//! Units: track values in mm, positioner values in degrees, poses SI.

use crate::model::external::{LinearTrack, OutsideTravel, TiltRotate};
use crate::model::orientation::rotation_log;
use crate::model::Pose;
use nalgebra::{Matrix3x2, Vector2, Vector3};

/// The track value [mm], to 0.001 mm, at which `calibrated` moves the
/// robot's base from the middle of its travel most nearly as `nominal`
/// does at `programmed` (module docs); refused when it lies beyond either
/// travel.
pub(super) fn track_value(
    calibrated: &LinearTrack,
    nominal: &LinearTrack,
    programmed: f64,
) -> Result<f64, OutsideTravel> {
    let r = (calibrated.travel.lo_mm + calibrated.travel.hi_mm) / 2.0;
    let moved = nominal.cell_from_base(programmed)?.p - nominal.cell_from_base(r)?.p;
    let want = calibrated.cell_from_base(r)?.p + moved;
    let mut e = programmed;
    for _ in 0..8 {
        let here = calibrated.cell_from_base(e)?.p;
        let slope = slope_at(calibrated, e, &here)?;
        let step = (want - here).dot(&slope) / slope.norm_squared();
        e += step;
        if step.abs() < 1e-9 {
            break;
        }
    }
    // Written with 3 decimals: composed at what the controller will run.
    let e = (e * 1e3).round() / 1e3;
    calibrated.cell_from_base(e)?;
    Ok(e)
}

/// `dB(e)/de` [m/mm] by a 1 mm difference, backwards at the travel's end.
fn slope_at(
    track: &LinearTrack,
    e: f64,
    here: &Vector3<f64>,
) -> Result<Vector3<f64>, OutsideTravel> {
    match track.cell_from_base(e + 1.0) {
        Ok(ahead) => Ok(ahead.p - here),
        Err(_) => Ok(here - track.cell_from_base(e - 1.0)?.p),
    }
}

/// The positioner values [deg], to 0.0001°, at which `calibrated` (cell frame), seen in
/// the controller's world through `world_from_cell`, turns the face plate
/// most nearly as `nominal` (the controller's world) does at `programmed`;
/// `None` when the axes cannot turn the plate independently there.
pub(super) fn positioner_values(
    calibrated: &TiltRotate,
    nominal: &TiltRotate,
    world_from_cell: &Pose,
    programmed: [f64; 2],
) -> Option<[f64; 2]> {
    let want = nominal.cell_from_face_plate(programmed).r.transpose();
    let calibrated_in_world =
        |v: [f64; 2]| world_from_cell.r * calibrated.cell_from_face_plate(v).r;
    let residual = |v: [f64; 2]| -> Vector3<f64> { rotation_log(&(want * calibrated_in_world(v))) };
    const H_DEG: f64 = 1e-4;
    let mut v = programmed;
    for _ in 0..10 {
        let r = residual(v);
        let column = |k: usize| {
            let mut at = v;
            at[k] += H_DEG;
            (residual(at) - r) / H_DEG
        };
        let j = Matrix3x2::from_columns(&[column(0), column(1)]);
        let step: Vector2<f64> = (j.transpose() * j).try_inverse()? * (j.transpose() * -r);
        v = [v[0] + step[0], v[1] + step[1]];
        if step.norm() < 1e-10 {
            break;
        }
    }
    // Written with 4 decimals: composed at what the controller will run.
    Some(v.map(|x| (x * 1e4).round() / 1e4))
}

/// A one-axis turntable's value [deg], to 0.0001°, at which `calibrated`
/// (the positioner whose axis 1 stands at 0, cell frame), seen in the
/// controller's world through `world_from_cell`, turns the face plate most
/// nearly as `nominal` does at `programmed`: [`positioner_values`] with
/// axis 2 alone free; `None` when the axis does not turn the plate there.
pub(super) fn turntable_value(
    calibrated: &TiltRotate,
    nominal: &TiltRotate,
    world_from_cell: &Pose,
    programmed: f64,
) -> Option<f64> {
    let want = nominal
        .cell_from_face_plate([0.0, programmed])
        .r
        .transpose();
    let residual = |v: f64| -> Vector3<f64> {
        rotation_log(&(want * world_from_cell.r * calibrated.cell_from_face_plate([0.0, v]).r))
    };
    const H_DEG: f64 = 1e-4;
    let mut v = programmed;
    for _ in 0..10 {
        let r = residual(v);
        let j = (residual(v + H_DEG) - r) / H_DEG;
        if j.norm_squared() < 1e-12 {
            return None;
        }
        let step = -j.dot(&r) / j.norm_squared();
        v += step;
        if step.abs() < 1e-10 {
            break;
        }
    }
    Some((v * 1e4).round() / 1e4)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::external::{RotaryAxis, Travel};
    use crate::model::orientation::rotation_angle_between;
    use nalgebra::Matrix3;

    /// Closed form: a turntable whose calibrated zero is 1° and scale 1e-3
    /// off the controller's, on the same line, is written `(v − 1°)/1.001`.
    #[test]
    fn a_turntables_value_follows_its_zero_and_scale() {
        use crate::model::external::Turntable;
        let table = |zero_deg: f64, scale: f64| {
            Turntable {
                cell_from_base: Pose::from_translation(Vector3::new(1.5, 0.2, -0.9)),
                axis: RotaryAxis::new(Vector3::z(), Vector3::zeros(), zero_deg.to_radians(), scale),
                face_plate: Pose::from_translation(Vector3::new(0.0, 0.0, 0.9)),
            }
            .as_tilt_rotate()
        };
        let (nominal, calibrated) = (table(0.0, 1.0), table(1.0, 1.001));
        for v in [-170.0, -35.5, 0.0, 48.25, 179.0] {
            let w = turntable_value(&calibrated, &nominal, &Pose::identity(), v).unwrap();
            assert!((w - (v - 1.0) / 1.001).abs() < 1e-4, "{v}: {w}");
        }
    }

    fn rail(scale: f64, zero_m: f64) -> LinearTrack {
        let mut t = LinearTrack::nominal(
            Vector3::x(),
            Vector3::zeros(),
            zero_m,
            Matrix3::identity(),
            Travel {
                lo_mm: 0.0,
                hi_mm: 4000.0,
            },
        );
        t.scale = scale;
        t
    }

    /// Closed form: a track with scale 1.0002 (and a zero 0.3 mm off, which
    /// the displacement does not see) moves the base from the middle of
    /// the travel, 2000 mm, as the nominal one does when
    /// `1.0002·(e' − 2000) = e − 2000` [mm].
    #[test]
    fn a_tracks_scale_is_undone_in_closed_form() {
        let (cal, nom) = (rail(1.0002, 0.3e-3), rail(1.0, 0.0));
        for e in [0.5, 1000.0, 2345.6, 3999.0] {
            let got = track_value(&cal, &nom, e).unwrap();
            let expected = 2000.0 + (e - 2000.0) / 1.0002;
            // Rounded to the 3 decimals written.
            assert_eq!(got, (expected * 1e3).round() / 1e3, "{e}: {expected}");
        }
        // Where the calibrated travel cannot reach: refused.
        assert!(track_value(&rail(0.9999, 0.0), &nom, 0.0).is_err());
    }

    fn table(zero: [f64; 2], scale: [f64; 2]) -> TiltRotate {
        TiltRotate {
            cell_from_base: Pose::identity(),
            tilt: RotaryAxis::new(Vector3::x(), Vector3::zeros(), zero[0], scale[0]),
            rotate: RotaryAxis::new(Vector3::z(), Vector3::zeros(), zero[1], scale[1]),
            face_plate: Pose::from_translation(Vector3::new(0.0, 0.0, 0.5)),
        }
    }

    /// Closed form: zero offsets of 0.2° and −0.1° and a rotate scale of
    /// 1.001 are undone, `v' = (v − δ)/s` on each axis; the plate then
    /// turns as the nominal one does at `v`.
    #[test]
    fn a_positioners_zeros_and_scales_are_undone_in_closed_form() {
        let (d1, d2, s2) = (0.2f64, -0.1f64, 1.001);
        let cal = table([d1.to_radians(), d2.to_radians()], [1.0, s2]);
        let nom = table([0.0, 0.0], [1.0, 1.0]);
        for v in [[0.0, 0.0], [-35.0, 120.0], [20.0, -170.0]] {
            let got = positioner_values(&cal, &nom, &Pose::identity(), v).unwrap();
            let expected = [v[0] - d1, (v[1] - d2) / s2];
            for k in 0..2 {
                // Rounded to the 4 decimals written.
                assert!((got[k] - expected[k]).abs() <= 5e-5, "{v:?}: {got:?}");
                assert_eq!(got[k], (expected[k] * 1e4).round() / 1e4, "{v:?}: {got:?}");
            }
            let turned = rotation_angle_between(
                &nom.cell_from_face_plate(v).r,
                &cal.cell_from_face_plate(got).r,
            );
            // Half of 0.0001° on each axis at most: 1.23e-6 rad.
            assert!(turned < 1.3e-6, "{turned}");
        }
    }
}
