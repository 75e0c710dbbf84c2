//! Measurement plans (core::plan): the predicted standard deviations against
//! those of simulated measurements of the plan, the constraints checked by
//! forward kinematics, the program exports parsed back, and the tracker join.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal_core::calibrate::identify::{calibrate, CalibrationOptions, Method};
use robocal_core::measure::{csv, to_measurements};
use robocal_core::model::kinematics::fk;
use robocal_core::model::{preset, RobotModel};
use robocal_core::plan::{
    join, make_plan, plan_csv, plan_program, read_plan_csv, JoinBy, JoinError, JoinOptions,
    MeasurementPlan, PlanError, PlanSettings, TrackerSight, Units, WorkspaceBox,
};
use robocal_core::program::{parse, Language};
use robocal_core::sim::{perturb_geometry, tracker_frame, ErrorMagnitudes, TrueRobot};
use std::collections::BTreeMap;

/// Plans `poses` poses of `model` with `noise_mm` and the default constraints of these tests.
fn plan_of(model: &RobotModel, poses: usize, candidates: usize, noise_mm: f64) -> MeasurementPlan {
    make_plan(
        model,
        &PlanSettings {
            poses,
            candidates,
            noise_mm,
            seed: 3,
            ..PlanSettings::default()
        },
    )
    .unwrap()
}

/// Empirical standard deviation per parameter of `method` over `trials`
/// simulated measurements of `plan` on `truth` (fresh noise each time).
fn empirical_std(
    nominal: &RobotModel,
    truth: &TrueRobot,
    plan: &MeasurementPlan,
    method: Method,
    trials: usize,
) -> BTreeMap<String, f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(77);
    let opts = CalibrationOptions {
        methods: vec![method],
        ..Default::default()
    };
    let mut values: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    for _ in 0..trials {
        let rows = truth
            .measure(&plan.q, Some(plan.payload_kg), None, &mut rng)
            .unwrap();
        let data = to_measurements(nominal, &rows, plan.payload_kg);
        let report = calibrate(nominal, &data, &[], &opts, &|_| true).unwrap();
        for p in &report.methods[&method].parameters {
            values.entry(p.name.clone()).or_default().push(p.value);
        }
    }
    values
        .into_iter()
        .map(|(k, v)| {
            let n = v.len() as f64;
            let mean = v.iter().sum::<f64>() / n;
            let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
            (k, var.sqrt())
        })
        .collect()
}

/// Every predicted σ of `method` within 2× of the empirical one.
fn check_within_2x(plan: &MeasurementPlan, method: &str, empirical: &BTreeMap<String, f64>) {
    let predicted = plan.predicted.iter().find(|p| p.method == method).unwrap();
    assert!(!predicted.params.is_empty());
    for p in &predicted.params {
        let e = empirical[&p.name];
        let ratio = p.std / e;
        eprintln!(
            "{method} {}: predicted {:.3e} {}, empirical {e:.3e}, ratio {ratio:.2}",
            p.name, p.std, p.unit
        );
        assert!(
            (0.5..=2.0).contains(&ratio),
            "{method} {}: predicted {} {}, empirical {e}",
            p.name,
            p.std,
            p.unit
        );
    }
}

/// A 50-pose plan of the UR5 predicts KM's parameter σ within 2× of the σ
/// that 40 simulated measurements of it (geometry errors, tracker frame
/// metres away, 0.05 mm noise) give.
#[test]
fn km_prediction_matches_simulated_measurements() {
    let nominal = preset("ur5").unwrap();
    let plan = plan_of(&nominal, 50, 400, 0.05);
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let tm = perturb_geometry(&nominal, &ErrorMagnitudes::from_mm_deg(0.5, 0.05), &mut rng);
    let mut truth = TrueRobot::new(tm);
    truth.tracker_from_base = tracker_frame(10.0, -5.0, 30.0, [2500.0, -1000.0, 300.0]);
    truth.noise_mm = 0.05;
    let empirical = empirical_std(&nominal, &truth, &plan, Method::Km, 40);
    check_within_2x(&plan, "km", &empirical);
}

/// With gravity loading the joints (the YS100 and its payload), the plan also
/// predicts SKCM's σ, compliance included, within 2× of 30 simulated
/// measurements of a truth with the thesis's Table 7.1 errors and compliance.
#[test]
fn skcm_prediction_matches_simulated_measurements() {
    let nominal = preset("ys100").unwrap();
    let plan = plan_of(&nominal, 50, 400, 0.02);
    assert!(plan.predicted.iter().any(|p| p.method == "skcm"));
    let mut truth = TrueRobot::new(robocal_core::sim::ys100_table_7_1());
    truth.tracker_from_base = tracker_frame(-4.0, 3.0, 120.0, [3000.0, 1500.0, -200.0]);
    truth.noise_mm = 0.02;
    let empirical = empirical_std(&nominal, &truth, &plan, Method::Skcm, 30);
    check_within_2x(&plan, "skcm", &empirical);
}

/// Every chosen pose lies inside the box and the line-of-sight cone, checked
/// by forward kinematics here; the counts say what each filter let through.
#[test]
fn constraints_are_honoured() {
    let nominal = preset("ur5").unwrap();
    let b = WorkspaceBox {
        min_mm: [-200.0, -600.0, 100.0],
        max_mm: [700.0, 600.0, 900.0],
    };
    let sight = TrackerSight {
        position_mm: [3000.0, 500.0, 400.0],
        axis: [0.0, 0.0, 1.0],
        max_angle_deg: 50.0,
    };
    let settings = PlanSettings {
        poses: 30,
        candidates: 4000,
        workspace: Some(b),
        tracker: Some(sight),
        seed: 9,
        ..PlanSettings::default()
    };
    let plan = make_plan(&nominal, &settings).unwrap();
    let c = plan.counts;
    assert_eq!(c.drawn, 4000);
    assert!(c.reachable >= c.in_box && c.in_box > c.in_sight && c.in_sight >= 30);
    assert!(c.in_box < c.reachable, "the box must reject something here");
    assert_eq!(plan.q.len(), 30);
    for (q, p) in plan.q.iter().zip(&plan.points) {
        let tcp = fk(&nominal, q).unwrap();
        let mm = tcp.p * 1e3;
        for k in 0..3 {
            assert!(mm[k] >= b.min_mm[k] && mm[k] <= b.max_mm[k], "{mm:?}");
        }
        let z = tcp.r.column(2).into_owned();
        let to = nalgebra::Vector3::new(3.0, 0.5, 0.4) - tcp.p;
        let cos = z.dot(&to) / to.norm();
        assert!(
            cos >= 50f64.to_radians().cos() - 1e-12,
            "angle {}",
            cos.acos().to_degrees()
        );
        for (k, link) in nominal.links.iter().enumerate() {
            assert!(q[k] >= link.limits[0] && q[k] <= link.limits[1]);
        }
        // Points carry the controller joints in degrees.
        let back = nominal
            .joints_from_controller(&p.q_deg.iter().map(|d| d.to_radians()).collect::<Vec<_>>());
        for (a, b) in back.iter().zip(q) {
            assert!((a - b).abs() < 1e-12);
        }
    }
    // Too tight a cone: the error says how many passed each filter.
    let tight = PlanSettings {
        tracker: Some(TrackerSight {
            max_angle_deg: 1.0,
            ..sight
        }),
        candidates: 300,
        ..settings
    };
    match make_plan(&nominal, &tight) {
        Err(PlanError::TooFewCandidates { counts, needed }) => {
            assert_eq!((counts.drawn, needed), (300, 30));
            assert!(counts.in_sight < 30 && counts.in_box > counts.in_sight);
        }
        other => panic!("{other:?}"),
    }
}

/// The plan's joint CSV reads back, and its KRL, RAPID, Fanuc and URScript
/// programs parse back (the project's own parsers) to the same joints.
#[test]
fn exports_parse_back_to_the_same_joints() {
    let nominal = preset("ur5").unwrap();
    let plan = plan_of(&nominal, 50, 300, 0.01);
    let back = read_plan_csv(&plan_csv(&plan.points)).unwrap();
    assert_eq!(back, plan.points);
    for language in [
        Language::Krl,
        Language::Rapid,
        Language::Fanuc,
        Language::UrScript,
    ] {
        let files = plan_program(&plan, language, "plan", 2.0).unwrap();
        let text: String = files.iter().map(|f| f.text.as_str()).collect();
        let waits = ["WAIT SEC", "WaitTime", "WAIT", "sleep("]
            .iter()
            .map(|w| text.matches(w).count())
            .max()
            .unwrap();
        assert!(waits >= 50, "{language:?}: {waits} waits");
        let p = parse(language, &files).unwrap();
        assert_eq!(p.joints.len(), 50, "{language:?}");
        for (j, pt) in p.joints.iter().zip(&plan.points) {
            for (a, b) in j.deg.iter().zip(&pt.q_deg) {
                assert!(
                    (a - b).abs() < 1e-4,
                    "{language:?}: {:?} vs {:?}",
                    j.deg,
                    pt.q_deg
                );
            }
        }
    }
}

/// A simulated tracker export joined back by name (shuffled, metres) and by
/// order (millimetres) gives the measurement CSV the calibration reads, with
/// the simulated positions; missing, extra and duplicate points and unclear
/// units are errors.
#[test]
fn tracker_exports_join_back() {
    let nominal = preset("ur5").unwrap();
    let plan = plan_of(&nominal, 12, 200, 0.01);
    let mut truth = TrueRobot::new(nominal.clone());
    truth.tracker_from_base = tracker_frame(0.0, 0.0, 40.0, [2000.0, 300.0, -100.0]);
    let rows = truth
        .measure(&plan.q, None, None, &mut ChaCha8Rng::seed_from_u64(1))
        .unwrap();
    let xyz: Vec<[f64; 3]> = rows.iter().map(|r| r.xyz_mm).collect();
    let check = |joined: &robocal_core::plan::Joined| {
        let text = csv::write(&joined.rows);
        let read = csv::parse(&text).unwrap();
        assert_eq!(read.len(), 12);
        for ((r, p), x) in read.iter().zip(&plan.points).zip(&xyz) {
            assert_eq!(r.q_deg, p.q_deg);
            for (a, b) in r.xyz_mm.iter().zip(x) {
                assert!((a - b).abs() < 1e-6);
            }
        }
    };
    // By name, in metres, shuffled, with `;` and a header unit.
    let mut by_name = String::from("Point;X [m];Y [m];Z [m]\n");
    for i in (0..12).rev() {
        let x = xyz[i];
        by_name += &format!(
            "{};{};{};{}\n",
            plan.points[i].name,
            x[0] / 1e3,
            x[1] / 1e3,
            x[2] / 1e3
        );
    }
    let j = join(&plan.points, &by_name, &JoinOptions::default()).unwrap();
    assert_eq!((j.by, j.units), (JoinBy::Name, Units::M));
    check(&j);
    // By 1-based index, metres detected from the spread.
    let mut by_index = String::from("index,x,y,z\n");
    for (i, x) in xyz.iter().enumerate().rev() {
        by_index += &format!("{},{},{},{}\n", i + 1, x[0] / 1e3, x[1] / 1e3, x[2] / 1e3);
    }
    let j = join(&plan.points, &by_index, &JoinOptions::default()).unwrap();
    assert_eq!((j.by, j.units), (JoinBy::Name, Units::M));
    check(&j);
    // By order, millimetres detected.
    let mut by_order = String::from("x,y,z\n");
    for x in &xyz {
        by_order += &format!("{},{},{}\n", x[0], x[1], x[2]);
    }
    let j = join(&plan.points, &by_order, &JoinOptions::default()).unwrap();
    assert_eq!((j.by, j.units), (JoinBy::Order, Units::Mm));
    check(&j);
    // Errors.
    let opts = JoinOptions::default();
    let short: String = by_order
        .lines()
        .take(12)
        .map(|l| format!("{l}\n"))
        .collect();
    assert_eq!(
        join(&plan.points, &short, &opts).unwrap_err(),
        JoinError::Count {
            plan: 12,
            tracker: 11
        }
    );
    let missing: String = by_name.lines().take(12).map(|l| format!("{l}\n")).collect();
    assert_eq!(
        join(&plan.points, &missing, &opts).unwrap_err(),
        JoinError::Missing(vec!["P1".into()])
    );
    let extra = format!("{by_name}Q7;1;2;3\n");
    assert_eq!(
        join(&plan.points, &extra, &opts).unwrap_err(),
        JoinError::Extra(vec!["Q7".into()])
    );
    let dup = format!("{by_name}P3;1;2;3\n");
    assert_eq!(
        join(&plan.points, &dup, &opts).unwrap_err(),
        JoinError::Duplicate("P3".into())
    );
    let unclear: String = (0..12)
        .map(|i| format!("{},2,3\n", 10.0 + i as f64))
        .collect();
    let r = join(&plan.points, &format!("x,y,z\n{unclear}"), &opts);
    assert!(matches!(r, Err(JoinError::UnitsUnclear { .. })), "{r:?}");
    // Given units override the detection.
    let forced = JoinOptions {
        units: Units::Mm,
        by: JoinBy::Order,
    };
    let j = join(&plan.points, &format!("x,y,z\n{unclear}"), &forced).unwrap();
    assert_eq!(j.rows[0].xyz_mm, [10.0, 2.0, 3.0]);
    assert_eq!(
        join(
            &plan.points,
            &by_order,
            &JoinOptions {
                by: JoinBy::Name,
                ..opts
            }
        )
        .unwrap_err(),
        JoinError::NoNames
    );
}

/// A model whose lengths overflow (a description the service accepts) gives an
/// error naming the cause, not a hang in the factorisation.
#[test]
fn a_model_that_overflows_is_refused() {
    let mut model = preset("ur5").unwrap();
    model.links[1].a = 2e304;
    model.links[0].mass = 1e308;
    let e = make_plan(&model, &PlanSettings::default()).unwrap_err();
    assert!(
        matches!(
            e,
            PlanError::Unidentifiable(_) | PlanError::TooFewCandidates { .. }
        ),
        "{e}"
    );
}
