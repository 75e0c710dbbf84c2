use super::*;
use crate::compensate::{synthetic_calibration, SyntheticErrors};
use crate::kinematics::fk;
use crate::model::orientation::rotation_angle_between;
use crate::model::pose::rpy_matrix;
use crate::model::preset;
use nalgebra::Vector3;

/// A 250 mm tool tilted 30° about the flange's y axis.
fn torch() -> Pose {
    let r = rpy_matrix(0.0, 30f64.to_radians(), 0.0);
    Pose::new(r, r * Vector3::new(0.0, 0.0, 0.25))
}

fn fixture() -> (CompensatedModel, WorkObject) {
    let nominal = preset("ys100").unwrap();
    let model = synthetic_calibration(&nominal, &SyntheticErrors::typical(1e-6), 4);
    let mut w = Pose::identity();
    w.tr_x(1.9);
    w.tr_y(-3.0);
    w.rot_z(0.4);
    let wobj = WorkObject {
        name: "table".into(),
        number: Some(2),
        frame: WorkObjectFrame::Measurement,
        pose: model.cell_from_base.compose(&w),
    };
    (model, wobj)
}

#[test]
fn the_tool_goes_on_the_calibrated_and_the_nominal_flange() {
    let (model, _) = fixture();
    let flange = with_tool(&model, &Pose::identity());
    let m = with_tool(&model, &torch());
    let q = [0.3, 1.2, -0.3, 0.5, 0.8, -0.6];
    let want = fk(&flange.calibrated, &q).unwrap().compose(&torch());
    let got = fk(&m.calibrated, &q).unwrap();
    assert!((got.p - want.p).norm() < 1e-12);
    assert!(rotation_angle_between(&got.r, &want.r) < 1e-12);
    let want = fk(&flange.nominal, &q).unwrap().compose(&torch());
    assert!((m.false_target(&q).unwrap().p - want.p).norm() < 1e-12);
}

#[test]
fn a_target_in_a_measured_work_object_is_reached_by_the_calibrated_model() {
    let (model, wobj) = fixture();
    let solver = CellSolver::new(&model, &torch(), IkSettings::default());
    let q_true = [0.2, 1.4, -0.2, 0.4, 0.9, 0.3];
    let m = with_tool(&model, &torch());
    // The target: where the calibrated model puts the torch, in the work object.
    let target = wobj.pose.inverse().compose(&m.predict(&q_true).unwrap());
    let branch = solver.configuration(&q_true);
    let s = solver.solve(&wobj, &target, &CellOptions { branch, seed: None });
    assert!(s.solution.converged, "{:?}", s.solution.reason);
    let dq = s.solution.q.iter().zip(q_true).map(|(a, b)| (a - b).abs());
    assert!(dq.fold(0.0, f64::max) < 1e-7);
    // The false target: the nominal torch pose in the controller's work object.
    let w_base = model.cell_to_base(&wobj.pose);
    let ft = s.false_target.unwrap();
    let want = w_base
        .inverse()
        .compose(&fk(&m.nominal, &s.solution.q).unwrap());
    assert!((ft.p - want.p).norm() < 1e-12);
    // The nominal controller sends the false target back to the same joints.
    let sols = solver.nominal_solutions(
        &WorkObject {
            pose: w_base,
            frame: WorkObjectFrame::Base,
            ..wobj
        },
        &ft,
    );
    assert!(sols.iter().any(|q| q
        .iter()
        .zip(&s.solution.q)
        .all(|(a, b)| (a - b).abs() < 1e-8)));
}

#[test]
fn tools_and_work_objects_by_name_and_number() {
    let (_, wobj) = fixture();
    let cell = Cell {
        tools: vec![Tool {
            name: "torch".into(),
            number: Some(3),
            tcp: torch(),
        }],
        work_objects: vec![wobj],
    };
    assert_eq!(cell.tool(&CellRef::Number(3)).unwrap().name, "torch");
    assert_eq!(
        cell.tool(&CellRef::Name("TORCH".into())).unwrap().number,
        Some(3)
    );
    assert_eq!(
        cell.tool(&CellRef::Number(1)),
        Err(CellError::UnknownTool(CellRef::Number(1)))
    );
    assert_eq!(cell.work_object(&CellRef::Number(2)).unwrap().name, "table");
    assert_eq!(
        cell.work_object(&CellRef::Number(0)).unwrap().pose,
        Pose::identity()
    );
    assert!(cell.work_object(&CellRef::Name("fixture".into())).is_err());
}
