//! A track with a positioner or a turntable beside it, exported together
//! (`ExternalAxes::TrackAndPositioner`, `TrackAndTurntable`): the track ET1
//! (`E1`), the positioner or turntable ET2 (`E2`, `E3`) with its root in the
//! world, the cell frame. The text is read back with the parent's reader
//! and the part on the plate composed in the robot's base frame as the
//! controller composes both chains: `base(E1)⁻¹·plate(E2, E3)·BASE_DATA[n]`,
//! compared with the held models (to the text's rounding) and with the
//! calibrated ones (within the not-held terms' sum).

use super::*;

/// Frames chained for the part in the robot's base frame: the track's root
/// and four links, the positioner's root and four links, the base; each
/// written to 1e-6 mm (half of it per coordinate).
const ROUNDING_MM: f64 = 12.0 * 0.5e-6 * 1.7320508075688772 + 1e-7;

/// The fixture in the cell frame and the part on the face plate.
fn cell(part: Pose) -> Cell {
    Cell {
        tools: vec![torch_tool()],
        work_objects: vec![
            WorkObject {
                name: "fixture".into(),
                number: Some(2),
                frame: WorkObjectFrame::Measurement,
                pose: Pose::new(rpy_matrix(0.0, 0.0, 1.0), Vector3::new(2.0, 0.9, -0.4)),
            },
            WorkObject {
                name: "part".into(),
                number: Some(3),
                frame: WorkObjectFrame::FacePlate,
                pose: part,
            },
        ],
    }
}

/// The robot's base in the cell frame as the controller composes ET1 at `e`.
fn track_chain(text: &str, e: f64) -> Isometry3<f64> {
    frame_after(text, "$ERSYSROOT=")
        * frame_after(text, "$ET1_TA1KR=")
        * shift(e)
        * frame_after(text, "$ET1_TA2A1=")
        * frame_after(text, "$ET1_TA3A2=")
        * frame_after(text, "$ET1_TFLA3=")
}

/// The face plate in the cell frame as the controller composes ET2 at `v`
/// (a turntable: no joint for its absent second axis).
fn plate_chain(text: &str, v: [f64; 2], two_axes: bool) -> Isometry3<f64> {
    let second = if two_axes { turn(v[1]) } else { turn(0.0) };
    frame_after(text, ",ROOT ")
        * frame_after(text, "$ET2_TA1KR=")
        * turn(v[0])
        * frame_after(text, "$ET2_TA2A1=")
        * second
        * frame_after(text, "$ET2_TA3A2=")
        * frame_after(text, "$ET2_TFLA3=")
}

/// Track values over the 4 m travel beside the plate's values.
fn track_values() -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    (0..200).map(|_| rng.gen_range(0.0..4000.0)).collect()
}

/// What a chain misses: the worst position [mm] and angle [rad] against the
/// held models, and the worst position against the calibrated ones.
struct Misses {
    held: (f64, f64),
    calibrated: f64,
}

fn misses(
    text: &str,
    two_axes: bool,
    held: impl Fn(f64, [f64; 2]) -> Pose,
    calibrated: impl Fn(f64, [f64; 2]) -> Pose,
) -> Misses {
    let base3 = frame_after(text, "BASE_DATA[3]=");
    let mut m = Misses {
        held: (0.0, 0.0),
        calibrated: 0.0,
    };
    for (e, v) in track_values().into_iter().zip(values()) {
        let v = if two_axes { v } else { [v[1], 0.0] };
        let got = track_chain(text, e).inverse() * plate_chain(text, v, two_axes) * base3;
        let (d, a) = apart(&got, &iso(&held(e, v)));
        m.held = (m.held.0.max(d), m.held.1.max(a));
        m.calibrated = m.calibrated.max(apart(&got, &iso(&calibrated(e, v))).0);
    }
    m
}

#[test]
fn a_track_and_a_positioner_exported_together_compose_to_the_calibrated_cell() {
    let model = CompensatedModel::from_nominal(preset("ys100").unwrap());
    let part = Pose::new(rpy_matrix(0.0, 0.0, 0.4), Vector3::new(0.05, -0.02, 0.06));
    let cell = cell(part);
    for scale_error in [0.0, 2e-4] {
        let t = calibrated_track(scale_error, false);
        let p = calibrated_positioner(scale_error);
        let options = ExportOptions {
            axes: Some(ExternalAxes::TrackAndPositioner(t.clone(), p)),
            ..Default::default()
        };
        let out = export_cell(Language::Krl, &cell, &model, &options).unwrap();
        let text = &out.text;
        assert!(
            text.contains("$EX_KIN={ET1 #ERSYS,ET2 #EASYS,ET3 #NONE,"),
            "{text}"
        );
        assert!(text.contains("$ET1_AX={TR_A1 #E1,TR_A2 #NONE,TR_A3 #NONE}"));
        assert!(text.contains("$ET2_AX={TR_A1 #E2,TR_A2 #E3,TR_A3 #NONE}"));
        assert!(text.contains("ET2 (E2 the tilt, E3 the rotate)"), "{text}");
        assert!(
            text.contains("; BASE_DATA[3] part is on the face plate: $BASE=EK(MACHINE_DEF[2].ROOT,MACHINE_DEF[2].MECH_TYPE,BASE_DATA[3])"),
            "{text}"
        );
        let [track, plate] = out.kinematics.as_slice() else {
            panic!("{:?}", out.kinematics)
        };
        let (HeldAxes::Track(held_track), HeldAxes::Positioner(held_p)) =
            (&track.held, &plate.held)
        else {
            panic!("{:?} {:?}", track.held, plate.held)
        };
        // Beside a track the positioner stays in the cell frame.
        assert!((held_p.cell_from_base.p - p.cell_from_base.p).norm() < 1e-15);
        let in_base = |t: &LinearTrack, p: &TiltRotate, e: f64, v: [f64; 2]| {
            t.cell_from_base(e)
                .unwrap()
                .inverse()
                .compose(&p.cell_from_face_plate(v))
                .compose(&part)
        };
        let m = misses(
            text,
            true,
            |e, v| in_base(held_track, held_p, e, v),
            |e, v| in_base(&t, &p, e, v),
        );
        let names: Vec<&str> = track
            .not_held
            .iter()
            .chain(&plate.not_held)
            .map(|n| n.term.as_str())
            .collect();
        let bound: f64 = track
            .not_held
            .iter()
            .chain(&plate.not_held)
            .map(|n| n.miss_mm)
            .sum();
        eprintln!(
            "track and positioner, scale errors {scale_error}: chain vs held {:.2e} mm / {:.2e} rad; vs calibrated {:.4} mm against {bound:.4} mm ({names:?})",
            m.held.0, m.held.1, m.calibrated
        );
        assert!(m.held.0 < ROUNDING_MM && m.held.1 < 1e-9, "{:?}", m.held);
        if scale_error == 0.0 {
            assert!(names.is_empty(), "{names:?}");
            assert!(m.calibrated < ROUNDING_MM, "{}", m.calibrated);
            assert!(text.contains("; every calibrated term of the track is held"));
            assert!(text.contains("; every calibrated term of the positioner is held"));
        } else {
            assert_eq!(names, ["track scale", "tilt scale", "rotate scale"]);
            // The track's scale moves the base along the rail by up to its
            // entry; the part is within 500 mm of both axes.
            assert!(
                m.calibrated > 0.1 && m.calibrated <= bound,
                "{} vs {bound}",
                m.calibrated
            );
        }
        // The fixture is held in the world, the cell frame, as measured.
        let (d, a) = apart(
            &frame_after(text, "BASE_DATA[2]="),
            &iso(&cell.work_objects[0].pose),
        );
        assert!(d < 1e-6 && a < 1e-9, "{d} {a}");
    }
}

#[test]
fn a_track_and_a_turntable_exported_together_compose_to_the_calibrated_cell() {
    let model = CompensatedModel::from_nominal(preset("ys100").unwrap());
    let part = Pose::new(rpy_matrix(0.0, 0.0, 0.4), Vector3::new(0.05, -0.02, 0.06));
    let cell = cell(part);
    let t = calibrated_track(2e-4, false);
    let tt = calibrated_turntable(-1.5e-4);
    let options = ExportOptions {
        axes: Some(ExternalAxes::TrackAndTurntable(t.clone(), tt)),
        ..Default::default()
    };
    let out = export_cell(Language::Krl, &cell, &model, &options).unwrap();
    let text = &out.text;
    assert!(
        text.contains("$EX_KIN={ET1 #ERSYS,ET2 #EASYS,ET3 #NONE,"),
        "{text}"
    );
    assert!(text.contains("$ET2_AX={TR_A1 #E2,TR_A2 #NONE,TR_A3 #NONE}"));
    assert!(text.contains("NAME[] \"TURNTABLE\""), "{text}");
    let [track, plate] = out.kinematics.as_slice() else {
        panic!("{:?}", out.kinematics)
    };
    let (HeldAxes::Track(held_track), HeldAxes::Turntable(held_tt)) = (&track.held, &plate.held)
    else {
        panic!("{:?} {:?}", track.held, plate.held)
    };
    let in_base = |t: &LinearTrack, tt: &Turntable, e: f64, v: [f64; 2]| {
        t.cell_from_base(e)
            .unwrap()
            .inverse()
            .compose(&tt.cell_from_face_plate(v[0]))
            .compose(&part)
    };
    let m = misses(
        text,
        false,
        |e, v| in_base(held_track, held_tt, e, v),
        |e, v| in_base(&t, &tt, e, v),
    );
    let bound = track.not_held[0].miss_mm + plate.not_held[0].miss_mm;
    eprintln!(
        "track and turntable: chain vs held {:.2e} mm / {:.2e} rad; vs calibrated {:.4} mm against {bound:.4} mm",
        m.held.0, m.held.1, m.calibrated
    );
    assert!(m.held.0 < ROUNDING_MM && m.held.1 < 1e-9, "{:?}", m.held);
    assert!(
        m.calibrated > 0.1 && m.calibrated <= bound,
        "{} vs {bound}",
        m.calibrated
    );
    assert_eq!(plate.not_held[0].term, "turntable scale");
}

#[test]
fn a_track_beside_a_plate_refuses_what_it_cannot_hold() {
    let model = CompensatedModel::from_nominal(preset("ys100").unwrap());
    let mut riding = cell(Pose::identity());
    riding.work_objects[0].frame = WorkObjectFrame::Base;
    let options = ExportOptions {
        axes: Some(ExternalAxes::TrackAndPositioner(
            calibrated_track(0.0, false),
            calibrated_positioner(0.0),
        )),
        ..Default::default()
    };
    let e = export_cell(Language::Krl, &riding, &model, &options).unwrap_err();
    assert_eq!(e, ExportError::RidesTheCarriage("fixture".into()));
    for language in [Language::Rapid, Language::Fanuc, Language::UrScript] {
        let e = export_cell(language, &cell(Pose::identity()), &model, &options).unwrap_err();
        assert_eq!(e, ExportError::AxesNotWritten(language));
    }
}
