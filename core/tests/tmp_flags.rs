use nalgebra::Vector3;
use robocal_core::cell::*;
use robocal_core::compensate::CompensatedModel;
use robocal_core::ik::IkSettings;
use robocal_core::model::{pose::rpy_matrix, preset, Pose};
use robocal_core::program::*;

#[test]
fn print_flags() {
    let r = rpy_matrix(0.0, 30f64.to_radians(), 0.0);
    let torch = Pose::new(r, r * Vector3::new(0.0, 0.0, 0.25));
    for (name, wxyz, pts) in [
        (
            "ys100",
            [1.3, -0.6, 0.3],
            [
                [0.0, 0.0, 0.0],
                [100.0, 0.0, 0.0],
                [200.0, 50.0, 0.0],
                [200.0, 150.0, 0.0],
                [100.0, 150.0, 30.0],
                [0.0, 150.0, 0.0],
            ],
        ),
        (
            "ur5",
            [0.45, -0.1, 0.05],
            [
                [0.0, 0.0, 0.0],
                [100.0, 0.0, 0.0],
                [200.0, 50.0, 0.0],
                [200.0, 150.0, 0.0],
                [100.0, 150.0, 30.0],
                [0.0, 150.0, 0.0],
            ],
        ),
    ] {
        let m = CompensatedModel::from_nominal(preset(name).unwrap());
        let cs = CellSolver::new(&m, &torch, IkSettings::default());
        let mut w = Pose::from_translation(Vector3::from(wxyz));
        w.rot_z(20f64.to_radians());
        let wobj = WorkObject {
            name: "t".into(),
            number: None,
            frame: WorkObjectFrame::Base,
            pose: w,
        };
        println!(
            "{name} wobj rotz20 {:?} quat {:?}",
            wxyz,
            robocal_core::model::orientation::rotation_to(
                robocal_core::model::orientation::OrientationConvention::AbbQ1q4,
                &w.r
            )
        );
        for p in pts {
            let t = Pose::new(
                rpy_matrix(std::f64::consts::PI, 0.0, 0.0),
                Vector3::from(p) * 1e-3,
            );
            let sols = cs.nominal_solutions(&wobj, &t);
            for q in sols.iter().take(8) {
                let deg = cs.solver().controller_degrees(q);
                let c = cs.configuration(q).unwrap();
                println!(
                    "  {p:?} {c} deg {:?} S {} T {} cf {:?} fanuc {}",
                    deg.iter().map(|v| v.round()).collect::<Vec<_>>(),
                    kuka_status(&deg, c),
                    kuka_turn(&deg),
                    abb_cf(&deg, c),
                    fanuc_config_text(&fanuc_config(&deg, c))
                );
            }
        }
    }
}
