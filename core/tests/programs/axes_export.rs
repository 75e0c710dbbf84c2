//! `cell export` with a positioner's, a turntable's or a track's axes (KRL: a KUKA external
//! kinematic system). The exported text is read back here with this file's
//! own reader and composed as the controller composes it,
//! `ROOT·TA1KR·J1(E1)·TA2A1·J2(E2)·TA3A2·TFLA3` with `J` a turn about or a
//! shift along z and `R = Rz(A)·Ry(B)·Rx(C)` (nalgebra's Euler angles, not
//! the project's orientation code), and compared with the calibrated model:
//! equal to the text's rounding (~5e-6 mm) where the model's terms are held, off by no more than
//! the terms reported as not held where they are not.

use super::*;
use crate::common::positioner as example;
use nalgebra::{Isometry3, Rotation3, Translation3, UnitQuaternion};
use robocal_core::model::external::{
    LinearTrack, RotaryAxis, TiltRotate, Travel, TravelMap, Turntable,
};
use robocal_core::model::pose::rpy_matrix;
use robocal_core::program::controller::{
    export_cell, ExportError, ExportOptions, ExternalAxes, HeldAxes, ANGLE_ARM_MM, SCALE_RADIUS_MM,
    SCALE_TURN_DEG,
};

mod beside_track;

/// `{X …,Y …,Z …,A …,B …,C …}` after `key` in `text`, as an isometry [mm].
pub(super) fn frame_after(text: &str, key: &str) -> Isometry3<f64> {
    let start = text
        .find(key)
        .unwrap_or_else(|| panic!("{key} not in\n{text}"))
        + key.len();
    let body = &text[start..];
    let open = body.find('{').unwrap();
    let close = body.find('}').unwrap();
    let mut v = [f64::NAN; 6];
    for part in body[open + 1..close].split(',') {
        let (name, value) = part.trim().split_once(' ').unwrap();
        let i = ["X", "Y", "Z", "A", "B", "C"]
            .iter()
            .position(|n| *n == name)
            .unwrap();
        v[i] = value.parse().unwrap();
    }
    let (a, b, c) = (v[3].to_radians(), v[4].to_radians(), v[5].to_radians());
    Isometry3::from_parts(
        Translation3::new(v[0], v[1], v[2]),
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_euler_angles(c, b, a)),
    )
}

fn turn(deg: f64) -> Isometry3<f64> {
    Isometry3::rotation(Vector3::z() * deg.to_radians())
}

fn shift(mm: f64) -> Isometry3<f64> {
    Isometry3::translation(0.0, 0.0, mm)
}

pub(super) fn iso(p: &Pose) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::from(p.p * 1e3),
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(p.r)),
    )
}

/// What the text's rounding leaves [mm]: up to six frames chained (the
/// root, four links and a base), each written to 1e-6 mm (half of it per
/// coordinate), the angles to 1e-9°.
pub(super) const ROUNDING_MM: f64 = 6.0 * 0.5e-6 * 1.7320508075688772 + 1e-7;

/// Position [mm] and angle [rad] between two frames.
pub(super) fn apart(a: &Isometry3<f64>, b: &Isometry3<f64>) -> (f64, f64) {
    (
        (a.translation.vector - b.translation.vector).norm(),
        a.rotation.angle_to(&b.rotation),
    )
}

/// The calibrated positioner: the drawing's axes tilted by 0.05° and moved
/// by 0.5 mm, zero offsets, and scales off by `scale_error` and −0.75 of it.
fn calibrated_positioner(scale_error: f64) -> TiltRotate {
    let d = example::nominal();
    let tilt_dir = example::turned(Vector3::x(), Vector3::z(), 0.05);
    let rotate_dir = example::turned(Vector3::z(), Vector3::x(), -0.05);
    TiltRotate {
        tilt: RotaryAxis::new(
            tilt_dir,
            d.tilt.point + Vector3::new(0.0, 0.0005, -0.0003),
            0.3f64.to_radians(),
            1.0 + scale_error,
        ),
        rotate: RotaryAxis::new(
            rotate_dir,
            Vector3::new(0.0005, -0.0002, 0.0),
            (-0.4f64).to_radians(),
            1.0 - 0.75 * scale_error,
        ),
        ..d
    }
}

/// A robot registered 1.7 m from the tracker, turned 30°, with a torch, a
/// fixture measured in the tracker frame and a part on the face plate.
fn positioner_cell() -> (CompensatedModel, Cell, Pose) {
    let mut model = CompensatedModel::from_nominal(preset("ys100").unwrap());
    model.cell_from_base = Pose::new(
        rpy_matrix(0.01, -0.02, 30f64.to_radians()),
        Vector3::new(1.2, -1.7, -0.85),
    );
    let part = Pose::new(rpy_matrix(0.0, 0.0, 0.4), Vector3::new(0.05, -0.02, 0.06));
    let cell = Cell {
        tools: vec![torch_tool()],
        work_objects: vec![
            WorkObject {
                name: "fixture".into(),
                number: Some(2),
                frame: WorkObjectFrame::Measurement,
                pose: Pose::from_translation(Vector3::new(2.0, -0.5, -0.4)),
            },
            WorkObject {
                name: "part".into(),
                number: Some(3),
                frame: WorkObjectFrame::FacePlate,
                pose: part,
            },
        ],
    };
    (model, cell, part)
}

/// The positioner's chain as the controller composes it from the text.
fn positioner_chain(text: &str, v: [f64; 2]) -> Isometry3<f64> {
    frame_after(text, ",ROOT ")
        * frame_after(text, "$ET1_TA1KR=")
        * turn(v[0])
        * frame_after(text, "$ET1_TA2A1=")
        * turn(v[1])
        * frame_after(text, "$ET1_TA3A2=")
        * frame_after(text, "$ET1_TFLA3=")
}

/// Pairs of values over both axes' full turn.
fn values() -> Vec<[f64; 2]> {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    (0..200)
        .map(|_| [rng.gen_range(-180.0..180.0), rng.gen_range(-180.0..180.0)])
        .collect()
}

#[test]
fn a_positioner_exported_for_kuka_composes_to_the_calibrated_positioner() {
    let (model, cell, part) = positioner_cell();
    let base_from_cell = model.cell_from_base.inverse();
    for scale_error in [0.0, 2e-4] {
        let p = calibrated_positioner(scale_error);
        let options = ExportOptions {
            axes: Some(ExternalAxes::Positioner(p)),
            ..Default::default()
        };
        let out = export_cell(Language::Krl, &cell, &model, &options).unwrap();
        let text = &out.text;
        assert!(text.contains("$EX_KIN={ET1 #EASYS,"), "{text}");
        assert!(text.contains("$ET1_AX={TR_A1 #E1,TR_A2 #E2,TR_A3 #NONE}"));
        assert!(text.contains("MECH_TYPE #EASYS"));
        assert!(
            text.contains("; BASE_DATA[3] part is on the face plate: $BASE=EK(MACHINE_DEF[2].ROOT,MACHINE_DEF[2].MECH_TYPE,BASE_DATA[3])"),
            "{text}"
        );
        let k = out.kinematics.first().unwrap();
        let HeldAxes::Positioner(held) = &k.held else {
            panic!("{:?}", k.held)
        };
        // The part's base, coupled: the chain's flange times BASE_DATA[3].
        let base3 = frame_after(text, "BASE_DATA[3]=");
        let mut worst_held = (0.0f64, 0.0f64);
        let mut worst_calibrated = 0.0f64;
        for v in values() {
            let got = positioner_chain(text, v) * base3;
            // What the filter's controller positioner gives: the held model,
            // in the robot's base frame.
            let held_part = iso(&held.cell_from_face_plate(v).compose(&part));
            let (d, a) = apart(&got, &held_part);
            worst_held = (worst_held.0.max(d), worst_held.1.max(a));
            // The calibrated positioner, in the robot's base frame.
            let calibrated = iso(&base_from_cell
                .compose(&p.cell_from_face_plate(v))
                .compose(&part));
            worst_calibrated = worst_calibrated.max(apart(&got, &calibrated).0);
        }
        assert!(
            worst_held.0 < ROUNDING_MM && worst_held.1 < 1e-9,
            "{worst_held:?}"
        );
        // The part is within 130 mm of the face plate's origin, which is
        // within 400 mm of both axes: a scale's miss at 500 mm over 180°
        // bounds it.
        let bound: f64 = k.not_held.iter().map(|n| n.miss_mm).sum();
        eprintln!(
            "scale error {scale_error}: chain vs held {:.2e} mm / {:.2e} rad; vs calibrated {worst_calibrated:.4} mm (not held: {:?})",
            worst_held.0, worst_held.1, k.not_held
        );
        if scale_error == 0.0 {
            assert!(k.not_held.is_empty(), "{:?}", k.not_held);
            assert!(worst_calibrated < ROUNDING_MM, "{worst_calibrated}");
            assert!(text.contains("; every calibrated term of the positioner is held"));
        } else {
            let names: Vec<&str> = k.not_held.iter().map(|n| n.term.as_str()).collect();
            assert_eq!(names, ["tilt scale", "rotate scale"]);
            let want = 2e-4 * SCALE_TURN_DEG.to_radians() * SCALE_RADIUS_MM;
            assert!((k.not_held[0].miss_mm - want).abs() < 1e-12);
            assert!(
                worst_calibrated > 0.01 && worst_calibrated <= bound,
                "{worst_calibrated} vs {bound}"
            );
        }
        // The fixture, measured in the tracker frame: in the robot's base frame.
        let fixture = frame_after(text, "BASE_DATA[2]=");
        let want = iso(&model.cell_to_base(&cell.work_objects[0].pose));
        let (d, a) = apart(&fixture, &want);
        assert!(d < 1e-6 && a < 1e-9, "{d} {a}");
    }
    // The drawing's positioner as the controller held it misses the
    // calibrated one by millimetres at the part.
    let p = calibrated_positioner(2e-4);
    let drawing = example::nominal();
    let miss = values()
        .iter()
        .map(|v| {
            let a = base_from_cell
                .compose(&p.cell_from_face_plate(*v))
                .compose(&part);
            let b = base_from_cell
                .compose(&drawing.cell_from_face_plate(*v))
                .compose(&part);
            (a.p - b.p).norm() * 1e3
        })
        .fold(0.0, f64::max);
    eprintln!("the drawing's positioner misses the calibrated part by up to {miss:.3} mm");
    assert!(miss > 1.0, "{miss}");
}

/// A calibrated 4 m track: the rail 25° off the cell's x, rising 0.1°, with
/// scale `1 + scale_error`, a zero, a turned mount and, with `maps`, the
/// carriage's straightness, pitch and yaw over the travel.
fn calibrated_track(scale_error: f64, maps: bool) -> LinearTrack {
    let direction = Vector3::new(
        25f64.to_radians().cos(),
        25f64.to_radians().sin(),
        0.1f64.to_radians().tan(),
    );
    let mut t = LinearTrack::nominal(
        direction,
        Vector3::new(0.3, -1.2, -0.9),
        0.12,
        rpy_matrix(0.002, -0.001, 0.5),
        Travel {
            lo_mm: 0.0,
            hi_mm: 4000.0,
        },
    );
    t.scale = 1.0 + scale_error;
    if maps {
        let arcsec = std::f64::consts::PI / (180.0 * 3600.0);
        let map = |c: &[f64]| TravelMap {
            coefficients: c.to_vec(),
        };
        t.maps[1] = map(&[0.0, 0.0, 0.00008]);
        t.maps[4] = map(&[0.0, 10.0 * arcsec]);
        t.maps[5] = map(&[0.0, 0.0, 0.0, 25.0 * arcsec]);
    }
    t
}

#[test]
fn a_track_exported_for_kuka_composes_to_the_calibrated_track() {
    let model = CompensatedModel::from_nominal(preset("ys100").unwrap());
    let fixture = Pose::new(rpy_matrix(0.0, 0.0, 1.0), Vector3::new(2.0, 0.9, -0.4));
    let cell = Cell {
        tools: vec![torch_tool()],
        work_objects: vec![WorkObject {
            name: "fixture".into(),
            number: Some(2),
            frame: WorkObjectFrame::Measurement,
            pose: fixture,
        }],
    };
    for (scale_error, maps) in [(0.0, false), (2e-4, true)] {
        let t = calibrated_track(scale_error, maps);
        let options = ExportOptions {
            axes: Some(ExternalAxes::Track(t.clone())),
            ..Default::default()
        };
        let out = export_cell(Language::Krl, &cell, &model, &options).unwrap();
        let text = &out.text;
        assert!(text.contains("$EX_KIN={ET1 #ERSYS,"), "{text}");
        let k = out.kinematics.first().unwrap();
        let HeldAxes::Track(held) = &k.held else {
            panic!("{:?}", k.held)
        };
        let (mut worst_held, mut worst_calibrated) = ((0.0f64, 0.0f64), 0.0f64);
        // The robot's base and a point 1 m out in each of its axes.
        let arm = ANGLE_ARM_MM * 1e-3;
        let points = [
            Vector3::zeros(),
            Vector3::x() * arm,
            Vector3::y() * arm,
            Vector3::z() * arm,
        ];
        for i in 0..=80 {
            let e = 50.0 * f64::from(i);
            let chain = frame_after(text, "$ERSYSROOT=")
                * frame_after(text, "$ET1_TA1KR=")
                * shift(e)
                * frame_after(text, "$ET1_TA2A1=")
                * frame_after(text, "$ET1_TA3A2=")
                * frame_after(text, "$ET1_TFLA3=");
            let (d, a) = apart(&chain, &iso(&held.cell_from_base(e).unwrap()));
            worst_held = (worst_held.0.max(d), worst_held.1.max(a));
            let calibrated = t.cell_from_base(e).unwrap();
            for x in &points {
                let got = chain.transform_point(&(x * 1e3).into());
                let want = calibrated.transform_point(x) * 1e3;
                worst_calibrated = worst_calibrated.max((got.coords - want).norm());
            }
        }
        assert!(
            worst_held.0 < ROUNDING_MM && worst_held.1 < 1e-9,
            "{worst_held:?}"
        );
        let bound: f64 = k.not_held.iter().map(|n| n.miss_mm).sum();
        eprintln!(
            "track, scale error {scale_error}: chain vs held {:.2e} mm / {:.2e} rad; vs calibrated {worst_calibrated:.4} mm within 1 m of the base (not held: {:?})",
            worst_held.0, worst_held.1, k.not_held
        );
        if maps {
            let names: Vec<&str> = k.not_held.iter().map(|n| n.term.as_str()).collect();
            assert_eq!(
                names,
                ["track scale", "lateral straightness", "pitch", "yaw"]
            );
            assert!(
                (k.not_held[0].miss_mm - 0.8).abs() < 1e-9,
                "{:?}",
                k.not_held[0]
            );
            assert!(
                (k.not_held[3].value - 25.0).abs() < 1e-9,
                "{:?}",
                k.not_held[3]
            );
            assert!(
                worst_calibrated > 0.5 && worst_calibrated <= bound,
                "{worst_calibrated} vs {bound}"
            );
        } else {
            assert!(k.not_held.is_empty());
            assert!(worst_calibrated < ROUNDING_MM, "{worst_calibrated}");
        }
        // A base of a robot on a track is held in the world: the cell frame.
        let (d, a) = apart(&frame_after(text, "BASE_DATA[2]="), &iso(&fixture));
        assert!(d < 1e-6 && a < 1e-9, "{d} {a}");
    }
}

#[test]
fn axes_the_export_cannot_write_are_refused_naming_why() {
    let (model, cell, _) = positioner_cell();
    let positioner = ExportOptions {
        axes: Some(ExternalAxes::Positioner(calibrated_positioner(2e-4))),
        ..Default::default()
    };
    for language in [Language::Rapid, Language::Fanuc, Language::UrScript] {
        let e = export_cell(language, &cell, &model, &positioner).unwrap_err();
        assert_eq!(e, ExportError::AxesNotWritten(language));
        assert!(e.to_string().contains("KRL only"), "{e}");
    }
    // Without the positioner, the part on the plate is refused as before.
    let e = export_cell(Language::Krl, &cell, &model, &ExportOptions::default()).unwrap_err();
    assert_eq!(e, ExportError::OnFacePlate("part".into()));
    // A track with the part on a positioner's plate, or a work object riding
    // the carriage.
    let track = ExportOptions {
        axes: Some(ExternalAxes::Track(calibrated_track(0.0, false))),
        ..Default::default()
    };
    let e = export_cell(Language::Krl, &cell, &model, &track).unwrap_err();
    assert_eq!(e, ExportError::OnFacePlate("part".into()));
    let mut riding = cell.clone();
    riding.work_objects[1].frame = WorkObjectFrame::Base;
    let e = export_cell(Language::Krl, &riding, &model, &track).unwrap_err();
    assert_eq!(e, ExportError::RidesTheCarriage("part".into()));
    assert!(e.to_string().contains("\"frame\": \"measurement\""), "{e}");
}

#[test]
fn the_held_positioner_differs_from_the_calibrated_one_only_by_its_scales() {
    let p = calibrated_positioner(2e-4);
    let (model, cell, _) = positioner_cell();
    let options = ExportOptions {
        axes: Some(ExternalAxes::Positioner(p)),
        ..Default::default()
    };
    let out = export_cell(Language::Krl, &cell, &model, &options).unwrap();
    let HeldAxes::Positioner(held) = out.kinematics[0].held else {
        panic!()
    };
    assert_eq!(held.tilt.scale, 1.0);
    assert_eq!(held.rotate.scale, 1.0);
    assert_eq!(held.tilt.zero_offset, p.tilt.zero_offset);
    let base_from_cell = model.cell_from_base.inverse();
    let want = base_from_cell.compose(&p.cell_from_base);
    assert!((held.cell_from_base.p - want.p).norm() < 1e-12);
    assert!((held.cell_from_base.r - want.r).norm() < 1e-12);
}

/// The calibrated turntable: the example's drawing with its axis tilted by
/// 0.05° about x, moved by 0.5 mm, a zero offset of −0.4° and a scale off by
/// `scale_error`.
fn calibrated_turntable(scale_error: f64) -> Turntable {
    let d = robocal_core::sim::turntable_example::nominal();
    let tilt = Rotation3::from_axis_angle(&Vector3::x_axis(), 0.05f64.to_radians());
    Turntable {
        axis: RotaryAxis::new(
            tilt * d.axis.direction,
            d.axis.point + Vector3::new(0.0005, -0.0002, 0.0),
            (-0.4f64).to_radians(),
            1.0 + scale_error,
        ),
        ..d
    }
}

#[test]
fn a_turntable_exported_for_kuka_composes_to_the_calibrated_turntable() {
    let (model, cell, part) = positioner_cell();
    let base_from_cell = model.cell_from_base.inverse();
    for scale_error in [0.0, -1.5e-4] {
        let t = calibrated_turntable(scale_error);
        let options = ExportOptions {
            axes: Some(ExternalAxes::Turntable(t)),
            ..Default::default()
        };
        let out = export_cell(Language::Krl, &cell, &model, &options).unwrap();
        let text = &out.text;
        assert!(text.contains("$EX_KIN={ET1 #EASYS,"), "{text}");
        assert!(text.contains("$ET1_AX={TR_A1 #E1,TR_A2 #NONE,TR_A3 #NONE}"));
        assert!(text.contains("NAME[] \"TURNTABLE\""), "{text}");
        assert!(
            text.contains("; BASE_DATA[3] part is on the face plate: $BASE=EK(MACHINE_DEF[2].ROOT,MACHINE_DEF[2].MECH_TYPE,BASE_DATA[3])"),
            "{text}"
        );
        let k = out.kinematics.first().unwrap();
        let HeldAxes::Turntable(held) = &k.held else {
            panic!("{:?}", k.held)
        };
        let base3 = frame_after(text, "BASE_DATA[3]=");
        let (mut worst_held, mut worst_calibrated) = ((0.0f64, 0.0f64), 0.0f64);
        for v in values().iter().map(|v| v[1]) {
            // One axis: E2 is #NONE, so no joint between TA2A1 and TA3A2.
            let got = frame_after(text, ",ROOT ")
                * frame_after(text, "$ET1_TA1KR=")
                * turn(v)
                * frame_after(text, "$ET1_TA2A1=")
                * frame_after(text, "$ET1_TA3A2=")
                * frame_after(text, "$ET1_TFLA3=")
                * base3;
            let held_part = iso(&held.cell_from_face_plate(v).compose(&part));
            let (d, a) = apart(&got, &held_part);
            worst_held = (worst_held.0.max(d), worst_held.1.max(a));
            let calibrated = iso(&base_from_cell
                .compose(&t.cell_from_face_plate(v))
                .compose(&part));
            worst_calibrated = worst_calibrated.max(apart(&got, &calibrated).0);
        }
        eprintln!(
            "turntable scale error {scale_error}: chain vs held {:.2e} mm / {:.2e} rad; vs calibrated {worst_calibrated:.4} mm (not held: {:?})",
            worst_held.0, worst_held.1, k.not_held
        );
        assert!(
            worst_held.0 < ROUNDING_MM && worst_held.1 < 1e-9,
            "{worst_held:?}"
        );
        if scale_error == 0.0 {
            assert!(k.not_held.is_empty(), "{:?}", k.not_held);
            assert!(worst_calibrated < ROUNDING_MM, "{worst_calibrated}");
            assert!(text.contains("; every calibrated term of the turntable is held"));
        } else {
            let names: Vec<&str> = k.not_held.iter().map(|n| n.term.as_str()).collect();
            assert_eq!(names, ["turntable scale"]);
            let want = 1.5e-4 * SCALE_TURN_DEG.to_radians() * SCALE_RADIUS_MM;
            assert!((k.not_held[0].miss_mm - want).abs() < 1e-12);
            // The part is within 500 mm of the axis: the scale's miss at
            // 500 mm over 180° bounds it.
            assert!(
                worst_calibrated > 0.01 && worst_calibrated <= want,
                "{worst_calibrated} vs {want}"
            );
            assert!(text.contains(
                "the filter corrects it when given this chain as its controller turntable"
            ));
        }
        assert_eq!(held.axis.scale, 1.0);
        assert_eq!(held.axis.zero_offset, t.axis.zero_offset);
        let want = base_from_cell.compose(&t.cell_from_base);
        assert!((held.cell_from_base.p - want.p).norm() < 1e-12);
        // The fixture, measured in the tracker frame: in the robot's base frame.
        let fixture = frame_after(text, "BASE_DATA[2]=");
        let want = iso(&model.cell_to_base(&cell.work_objects[0].pose));
        let (d, a) = apart(&fixture, &want);
        assert!(d < 1e-6 && a < 1e-9, "{d} {a}");
    }
}
