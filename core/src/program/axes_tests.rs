//! Tests of `axes`: closed forms of the track's and the positioner's
//! composition, the axes refused and the values corrected.
use super::*;
use crate::model::external::Travel;
use crate::model::orientation::OrientationConvention;
use crate::program::{AxisValue, Flags, FrameSpec};
use nalgebra::{Matrix3, Vector3};

fn site(axes: Vec<AxisValue>) -> Site {
    Site {
        file: 0,
        line: 1,
        name: "p".into(),
        pose: Some(Pose::identity()),
        flags: Flags::Nearest,
        tool: FrameSpec::Unset,
        load: None,
        work_object: FrameSpec::Unset,
        slots: Vec::new(),
        convention: OrientationConvention::KukaAbc,
        unit_m: 1e-3,
        decimals: [3, 3],
        mark_at: 0..0,
        after_joints: None,
        skip: None,
        refuse: None,
        axes,
        stationary_tool: false,
    }
}

fn axis(number: usize, name: &str, value: Option<f64>) -> AxisValue {
    AxisValue {
        number,
        name: name.into(),
        value,
        text: value.map_or("v".into(), |v| format!("{v}")),
        slot: None,
        group: 1,
    }
}

fn track(scale: f64) -> LinearTrack {
    let mut t = LinearTrack::nominal(
        Vector3::x(),
        Vector3::new(0.0, 1.0, 0.0),
        0.0,
        Matrix3::identity(),
        Travel {
            lo_mm: 0.0,
            hi_mm: 4000.0,
        },
    );
    t.scale = scale;
    t
}

#[test]
fn without_a_track_an_axis_in_use_is_refused_and_krl_zeros_are_none() {
    let none = FilterAxes::default();
    let krl = site(vec![axis(1, "E1", Some(0.0)), axis(2, "E2", Some(0.0))]);
    assert!(place(Language::Krl, &krl, &none, &Pose::identity())
        .unwrap()
        .track
        .is_none());
    // A Fanuc or RAPID axis at 0 is an axis the robot has.
    let why = place(Language::Fanuc, &krl, &none, &Pose::identity()).unwrap_err();
    assert!(why.contains("external axis E1 to 0"), "{why}");
    let krl = site(vec![axis(1, "E1", Some(0.0)), axis(3, "E3", Some(5.0))]);
    let why = place(Language::Krl, &krl, &none, &Pose::identity()).unwrap_err();
    assert!(
        why.contains("E3 to 5") && why.contains("does not model"),
        "{why}"
    );
}

#[test]
fn on_a_track_the_value_places_both_bases_and_other_axes_are_refused() {
    let (nominal, calibrated) = (track(1.0), track(1.0002));
    let axes = FilterAxes {
        correct_values: false,
        track: Some(TrackAxes {
            nominal: &nominal,
            calibrated: &calibrated,
        }),
        positioner: None,
    };
    let s = site(vec![axis(1, "E1", Some(2000.0)), axis(2, "E2", Some(0.0))]);
    let on = place(Language::Krl, &s, &axes, &Pose::identity())
        .unwrap()
        .track
        .unwrap();
    assert_eq!(on.value_mm, 2000.0);
    // Scale 1.0002: the calibrated base 0.4 mm further along the rail.
    assert!((on.calibrated.p.x - on.nominal.p.x - 0.0004).abs() < 1e-12);
    assert!((on.nominal.p - Vector3::new(2.0, 1.0, 0.0)).norm() < 1e-12);
    // A KRL value of 0 on the track is the track at 0.
    let s = site(vec![axis(1, "E1", Some(0.0))]);
    assert_eq!(
        place(Language::Krl, &s, &axes, &Pose::identity())
            .unwrap()
            .track
            .unwrap()
            .value_mm,
        0.0
    );
    let cases = [
        (site(vec![]), "gives no value"),
        (site(vec![axis(1, "E1", None)]), "E1 is v"),
        (
            site(vec![axis(1, "E1", Some(4100.0))]),
            "4100 mm is beyond the controller's nominal travel",
        ),
        (
            site(vec![axis(1, "E1", Some(100.0)), axis(2, "E2", Some(1.0))]),
            "external axis E2 to 1",
        ),
    ];
    for (s, want) in cases {
        let why = place(Language::Krl, &s, &axes, &Pose::identity()).unwrap_err();
        assert!(why.contains(want), "{why}");
    }
    // The calibrated travel can be shorter than the controller's.
    let mut short = track(1.0);
    short.travel.hi_mm = 3000.0;
    let axes = FilterAxes {
        correct_values: false,
        track: Some(TrackAxes {
            nominal: &nominal,
            calibrated: &short,
        }),
        positioner: None,
    };
    let why = place(
        Language::Krl,
        &site(vec![axis(1, "E1", Some(3500.0))]),
        &axes,
        &Pose::identity(),
    )
    .unwrap_err();
    assert!(why.contains("outside the travel measured"), "{why}");
}

#[test]
fn the_controller_target_brings_the_nominal_base_where_the_true_one_is_solved() {
    // Any W, N, B, F: the controller's N⁻¹·W·T' equals B⁻¹·W·F.
    let mut w = Pose::from_translation(Vector3::new(1.0, 2.0, 0.3));
    w.rot_z(0.4);
    let mut n = Pose::from_translation(Vector3::new(2.0, 1.0, 0.0));
    n.rot_z(0.1);
    let mut b = Pose::from_translation(Vector3::new(2.0003, 1.0001, -0.0002));
    b.rot_z(0.1001);
    let mut f = Pose::from_translation(Vector3::new(0.1, -0.2, 0.05));
    f.rot_z(-0.7);
    let on = OnTrack {
        value_mm: 0.0,
        written_mm: 0.0,
        nominal: n,
        calibrated: b,
    };
    let (s, s_nom) = on.work_object(&w);
    let t = controller_target(&s_nom, &s, &f);
    let controller = n.inverse().compose(&w).compose(&t);
    let truth = b.inverse().compose(&w).compose(&f);
    assert!((controller.p - truth.p).norm() < 1e-12);
    assert!((controller.r - truth.r).norm() < 1e-12);
}

fn turntable(zero_deg: f64) -> TiltRotate {
    use crate::model::external::RotaryAxis;
    TiltRotate {
        cell_from_base: Pose::from_translation(Vector3::new(1.5, 0.0, 0.0)),
        tilt: RotaryAxis::new(Vector3::x(), Vector3::zeros(), 0.0, 1.0),
        rotate: RotaryAxis::new(Vector3::z(), Vector3::zeros(), zero_deg.to_radians(), 1.0),
        face_plate: Pose::from_translation(Vector3::new(0.0, 0.0, 0.5)),
    }
}

/// Closed form: a turntable whose calibrated zero is 1° off the
/// controller's, turned to 90°: the plate 90° round by the controller,
/// 91° by the cell; a part 1 m from the axis on the plate is 17.45 mm
/// from where the controller puts it.
#[test]
fn on_a_positioner_its_values_turn_both_plates_and_a_lone_value_is_refused() {
    let (nominal, calibrated) = (turntable(0.0), turntable(1.0));
    let axes = FilterAxes {
        correct_values: false,
        track: None,
        positioner: Some(PositionerAxes {
            nominal: &nominal,
            calibrated: &calibrated,
            turntable: false,
        }),
    };
    let s = site(vec![axis(1, "E1", Some(0.0)), axis(2, "E2", Some(90.0))]);
    let on = place(Language::Krl, &s, &axes, &Pose::identity())
        .unwrap()
        .positioner
        .unwrap();
    assert_eq!(on.values_deg, [0.0, 90.0]);
    let part = Pose::from_translation(Vector3::new(1.0, 0.0, 0.0));
    let (real, controller) = on.work_object(&Pose::identity(), &part);
    assert!((controller.p - Vector3::new(1.5, 1.0, 0.5)).norm() < 1e-12);
    let one = 1f64.to_radians();
    let want = Vector3::new(1.5 - one.sin(), one.cos(), 0.5);
    assert!((real.p - want).norm() < 1e-12, "{}", real.p);
    // Fanuc: the positioner is motion group 2; GP1's E1 is not its axis.
    let gp2 = |n: usize, v: f64| AxisValue {
        group: 2,
        ..axis(n, &format!("J{n} of motion group GP2"), Some(v))
    };
    let s = site(vec![gp2(1, 0.0), gp2(2, 90.0)]);
    let on = place(Language::Fanuc, &s, &axes, &Pose::identity())
        .unwrap()
        .positioner
        .unwrap();
    assert_eq!(on.values_deg, [0.0, 90.0]);
    // No value: no plate (a target in a fixed work object).
    assert!(
        place(Language::Krl, &site(vec![]), &axes, &Pose::identity())
            .unwrap()
            .positioner
            .is_none()
    );
    let cases = [
        (
            Language::Krl,
            site(vec![axis(2, "E2", Some(5.0))]),
            "no value for its axis E1",
        ),
        (
            Language::Rapid,
            site(vec![axis(1, "eax_a", Some(5.0))]),
            "no value for its axis eax_b",
        ),
        (
            Language::Fanuc,
            site(vec![gp2(1, 5.0), gp2(3, 1.0)]),
            "external axis J3 of motion group GP2 to 1",
        ),
        (
            Language::Fanuc,
            site(vec![gp2(1, 5.0), gp2(2, 1.0), axis(1, "E1", Some(3.0))]),
            "external axis E1 to 3",
        ),
        (
            Language::Krl,
            site(vec![axis(1, "E1", Some(5.0)), axis(2, "E2", None)]),
            "axis E2 is v",
        ),
    ];
    for (language, s, want) in cases {
        let why = place(language, &s, &axes, &Pose::identity()).unwrap_err();
        assert!(why.contains(want), "{language:?}: {why}");
    }
}

/// Closed form, a robot on a track beside the turntable: the track's
/// scale 1.0002 puts the real base 0.4 mm further along the rail at
/// 2000 mm, the zero 1° turns the real part; the positioner's axes are
/// then the program's second and third.
#[test]
fn on_a_track_beside_a_positioner_both_compose_and_its_axes_follow_the_track() {
    let (nominal, calibrated) = (turntable(0.0), turntable(1.0));
    let (rail, real_rail) = (track(1.0), track(1.0002));
    let axes = FilterAxes {
        correct_values: false,
        track: Some(TrackAxes {
            nominal: &rail,
            calibrated: &real_rail,
        }),
        positioner: Some(PositionerAxes {
            nominal: &nominal,
            calibrated: &calibrated,
            turntable: false,
        }),
    };
    assert_eq!(axes.positioner_numbers(Language::Krl), [2, 3]);
    assert_eq!(axes.positioner_numbers(Language::Fanuc), [1, 2]);
    assert_eq!(
        positioner_axis_names(Language::Rapid, true),
        ["eax_b", "eax_c"]
    );
    let s = site(vec![
        axis(1, "E1", Some(2000.0)),
        axis(2, "E2", Some(0.0)),
        axis(3, "E3", Some(90.0)),
    ]);
    let at = place(Language::Krl, &s, &axes, &Pose::identity()).unwrap();
    let (on_track, on_plate) = (at.track.unwrap(), at.positioner.unwrap());
    assert_eq!(
        (on_track.value_mm, on_plate.values_deg),
        (2000.0, [0.0, 90.0])
    );
    let part = Pose::from_translation(Vector3::new(1.0, 0.0, 0.0));
    let (world, world_nom) = on_plate.in_world(&part);
    let (s, s_nom) = on_track.moved_work_object(&world, &world_nom);
    let one = 1f64.to_radians();
    let real_part = Vector3::new(1.5 - one.sin(), one.cos(), 0.5);
    // The part in the real base: where the real base sees the real part.
    let seen = real_part - Vector3::new(2.0004, 1.0, 0.0);
    assert!((s.p - seen).norm() < 1e-12, "{}", s.p);
    let seen_nom = Vector3::new(1.5, 1.0, 0.5) - Vector3::new(2.0, 1.0, 0.0);
    assert!((s_nom.p - seen_nom).norm() < 1e-12, "{}", s_nom.p);
    let cases = [
        (
            site(vec![axis(1, "E1", Some(100.0)), axis(2, "E2", Some(5.0))]),
            "no value for its axis E3",
        ),
        (
            site(vec![axis(2, "E2", Some(5.0)), axis(3, "E3", Some(5.0))]),
            "gives no value for it",
        ),
        (
            site(vec![
                axis(1, "E1", Some(100.0)),
                axis(2, "E2", Some(5.0)),
                axis(3, "E3", Some(5.0)),
                axis(4, "E4", Some(1.0)),
            ]),
            "external axis E4 to 1",
        ),
    ];
    for (s, want) in cases {
        let why = place(Language::Krl, &s, &axes, &Pose::identity()).unwrap_err();
        assert!(why.contains(want), "{why}");
    }
}

/// Corrected on request: the track's scale of 1.0002 undone from
/// mid-travel (2000 mm) and the turntable's 1° zero undone, composed at
/// the written values and written in place of the programmed ones with
/// the program's decimals (at least 3 for mm, 4 for degrees); a value
/// the parser cannot point at refuses the target, naming the axis.
#[test]
fn corrected_values_are_composed_and_written_in_place() {
    let (nominal, calibrated) = (turntable(0.0), turntable(1.0));
    let (rail, real_rail) = (track(1.0), track(1.0002));
    let axes = FilterAxes::of_cell(None, None);
    let pair = (calibrated, nominal);
    let rails = (real_rail, rail);
    let axes = FilterAxes {
        track: FilterAxes::of_cell(Some(&rails), None).track,
        positioner: FilterAxes::of_cell(None, Some(&pair)).positioner,
        ..axes
    }
    .correcting_values(true);
    let slotted = |n: usize, name: &str, v: f64, text: &str, at: usize| AxisValue {
        text: text.into(),
        slot: Some(at..at + text.len()),
        ..axis(n, name, Some(v))
    };
    let s = site(vec![
        slotted(1, "E1", 3000.0, "3000.0", 10),
        slotted(2, "E2", 0.0, "0", 30),
        slotted(3, "E3", 90.0, "90.00000", 40),
    ]);
    let at = place(Language::Krl, &s, &axes, &Pose::identity()).unwrap();
    let (t, p) = (at.track.unwrap(), at.positioner.unwrap());
    let e = ((2000.0 + 1000.0 / 1.0002) * 1e3_f64).round() / 1e3;
    assert_eq!((t.value_mm, t.written_mm), (3000.0, e));
    assert_eq!((p.values_deg, p.written_deg), ([0.0, 90.0], [0.0, 89.0]));
    // Composed at the written values: the real plate at 89° + 1°.
    let real = p.calibrated.compose(&Pose::from_translation(Vector3::x()));
    assert!(
        (real.p - Vector3::new(1.5, 1.0, 0.5)).norm() < 1e-9,
        "{}",
        real.p
    );
    let edits = written_edits(Language::Krl, &s, &axes, &at).unwrap();
    assert_eq!(
        edits,
        vec![
            (10..16, format!("{e:.3}")),
            (30..31, "0.0000".to_string()),
            (40..48, "89.00000".to_string()),
        ]
    );
    let mut unslotted = s.clone();
    unslotted.axes[2].slot = None;
    let why = written_edits(Language::Krl, &unslotted, &axes, &at).unwrap_err();
    assert!(why.contains("axis E3 cannot be rewritten"), "{why}");
    let kept = axes.correcting_values(false);
    assert!(written_edits(Language::Krl, &s, &kept, &at)
        .unwrap()
        .is_empty());
}
