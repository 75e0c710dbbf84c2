use super::*;
use crate::model::kinematics::fk;
use crate::model::orientation::rotation_angle_between;
use crate::model::pose::rpy_matrix;
use crate::model::preset;
use crate::sim::{synthetic_calibration, SyntheticErrors};
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
            load: None,
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

/// A work object on the positioner's face plate has no pose in the base
/// frame without the positioner's values: the lookup every command but the
/// program filter uses refuses it, naming it; `any_work_object` gives it;
/// the controller export refuses the cell, naming it.
#[test]
fn a_work_object_on_the_face_plate_is_refused_where_no_positioner_places_it() {
    let (model, table) = fixture();
    let part = WorkObject {
        name: "part".into(),
        number: Some(3),
        frame: WorkObjectFrame::FacePlate,
        pose: Pose::from_translation(Vector3::new(0.1, 0.0, 0.06)),
    };
    let cell = Cell {
        tools: Vec::new(),
        work_objects: vec![table, part.clone()],
    };
    assert_eq!(
        cell.work_object(&CellRef::Number(3)),
        Err(CellError::OnFacePlate("part".into()))
    );
    assert_eq!(
        cell.any_work_object(&CellRef::Name("PART".into())),
        Ok(part)
    );
    assert_eq!(cell.work_object(&CellRef::Number(2)).unwrap().name, "table");
    let why = crate::program::controller::export_cell(
        crate::program::Language::Krl,
        &cell,
        &model,
        &Default::default(),
    )
    .unwrap_err();
    assert!(
        why.to_string()
            .contains("work object `part` is on the positioner's face plate"),
        "{why}"
    );
}

/// The torques of the payload alone (the model's links massless), computed
/// here from the flange pose: `τ_i = z_i·((c − o_i) × m g)`.
fn payload_torques(
    model: &crate::model::RobotModel,
    q: &[f64],
    c_flange: &Vector3<f64>,
    m: f64,
) -> Vec<f64> {
    let ch = crate::model::kinematics::chain(model, q).unwrap();
    let n = model.dof();
    let c = ch.links[n - 1].frame.transform_point(c_flange);
    (0..n)
        .map(|k| {
            let f = &ch.links[k].frame;
            f.z_axis().dot(&(c - f.p).cross(&(model.gravity * m)))
        })
        .collect()
}

#[test]
fn the_payload_stays_on_the_flange_whatever_the_tool() {
    let (mut model, _) = fixture();
    for l in model.calibrated.links.iter_mut() {
        l.mass = 0.0;
    }
    // The preset's payload (110 kg, 250 mm out along the flange axis),
    // where the calibrated model's tool puts it.
    let c_flange = crate::model::kinematics::chain::tool_pose(&model.calibrated)
        .transform_point(&model.calibrated.payload.com);
    assert!((c_flange - Vector3::new(0.0, 0.0, 0.25)).norm() < 0.01);
    let q = [0.3, 1.2, -0.3, 0.5, 0.8, -0.6];
    let want = payload_torques(&model.calibrated, &q, &c_flange, 110.0);
    for tcp in [Pose::identity(), torch()] {
        let m = with_tool(&model, &tcp);
        let got = m.torques_at(&q, 110.0).unwrap();
        for (g, w) in got.iter().zip(&want) {
            assert!(
                (g - w).abs() < 1e-9 * (1.0 + w.abs()),
                "{got:?} vs {want:?}"
            );
        }
    }
    // A tool's own load (stated in the flange frame) replaces the model's.
    let load = Load {
        mass_kg: 20.0,
        com: Vector3::new(0.05, 0.0, 0.1),
        inertia_kgm2: None,
    };
    let m = with_tool_load(&model, &torch(), Some(&load));
    assert_eq!(m.payload_kg, 20.0);
    let want = payload_torques(&model.calibrated, &q, &load.com, 20.0);
    let got = m.torques_at(&q, m.payload_kg).unwrap();
    for (g, w) in got.iter().zip(&want) {
        assert!(
            (g - w).abs() < 1e-9 * (1.0 + w.abs()),
            "{got:?} vs {want:?}"
        );
    }
}

#[test]
fn a_load_in_the_tool_frame_is_converted_once_to_the_flange() {
    let d = LoadDescription {
        mass_kg: 12.0,
        com_mm: [0.0, 0.0, -100.0],
        frame: LoadFrame::Tool,
        inertia_kgm2: None,
    };
    // 100 mm back from the torch's tip along its axis: 150 mm along it from
    // the flange, tilted 30° about y.
    let l = d.to_load(&torch()).unwrap();
    let want = Vector3::new(0.15 * 0.5, 0.0, 0.15 * 3f64.sqrt() / 2.0);
    assert!((l.com - want).norm() < 1e-15, "{:?}", l.com);
    let flange = LoadDescription {
        frame: LoadFrame::Flange,
        ..d.clone()
    };
    assert_eq!(
        flange.to_load(&torch()).unwrap().com,
        Vector3::new(0.0, 0.0, -0.1)
    );
    let bad = LoadDescription { mass_kg: -1.0, ..d };
    assert!(bad.to_load(&torch()).unwrap_err().contains("mass_kg"));
}

#[test]
fn the_solver_takes_the_tool_and_solves_as_a_model_carrying_it() {
    let (model, _) = fixture();
    let load = Load {
        mass_kg: 20.0,
        com: Vector3::new(0.05, 0.0, 0.1),
        inertia_kgm2: None,
    };
    let tool = TcpTool {
        tcp: torch(),
        load: Some(load),
    };
    // By hand: the torch on both flanges, the load's centre of mass in the
    // torch frame, its mass the declared payload.
    let mut by_hand = model.clone();
    let rpy = crate::model::orientation::fixed_xyz_angles(&torch().r);
    let com = torch().inverse().transform_point(&load.com);
    for m in [&mut by_hand.calibrated, &mut by_hand.nominal] {
        m.tool.p = torch().p;
        m.tool.rpy = rpy;
        m.payload.mass = 20.0;
        m.payload.com = com;
    }
    by_hand.payload_kg = 20.0;
    let reference = IkSolver::new(by_hand.clone(), IkSettings::default());
    let solver = IkSolver::with_tool(&model, Some(&tool), IkSettings::default());
    assert_eq!(solver.tool(), Some(&tool));
    assert_eq!(reference.tool(), None);
    let cell = CellSolver::for_tool(
        &model,
        Some(&Tool {
            name: "torch".into(),
            number: Some(1),
            tcp: torch(),
            load: Some(load),
        }),
        IkSettings::default(),
    );
    assert_eq!(cell.solver().tool(), Some(&tool));
    for q in [
        [0.2, 1.4, -0.2, 0.4, 0.9, 0.3],
        [-0.5, 1.1, 0.1, -0.7, 1.2, 1.0],
        [0.9, 1.6, -0.4, 0.2, 0.6, -0.8],
    ] {
        let target = by_hand.predict_base(&q).unwrap();
        let opts = SolveOptions {
            frame: TargetFrame::Base,
            ..SolveOptions::default()
        };
        let want = reference.solve(&target, &opts);
        assert!(want.converged, "{:?}", want.reason);
        let got = [
            solver.solve(&target, &opts),
            cell.solver().solve(&target, &opts),
        ];
        for got in got {
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&got.q), bits(&want.q));
        }
    }
}
