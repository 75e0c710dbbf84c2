//! Program filtering against simulated truth (issue 21, acceptance): a robot
//! with geometry errors, compliance and payload, measured by a tracker metres
//! away, calibrated (SKCM); a production tool 250 mm long tilted 30°; 50
//! targets in a work object measured in the tracker frame. The filtered
//! program, run through the nominal controller (closed-form IK of the nominal
//! model on the program's configuration flags), brings the true robot's
//! production TCP to the targets.

mod fanuc;
mod krl;
mod rapid;

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use robocal_core::cell::{Cell, Tool, WorkObject, WorkObjectFrame};
use robocal_core::compensate::CompensatedModel;
use robocal_core::identify::pose_selection::choose_d_optimal;
use robocal_core::identify::{calibrate, CalibrationOptions, Method};
use robocal_core::ik::{AnalyticIk, Configuration, IkSettings};
use robocal_core::measure;
use robocal_core::model::orientation::fixed_xyz_angles;
use robocal_core::model::pose::rpy_matrix;
use robocal_core::model::{preset, Pose, RobotModel};
use robocal_core::program::{parse, Language, ProgramFile, Site};
use robocal_core::sim::{
    random_configurations, random_configurations_with, tracker_frame, ys100_table_7_1, PoseFilter,
    TrueRobot,
};
use std::sync::OnceLock;

/// The calibrated cell and the truth with the production tool.
pub struct Fixture {
    /// Calibrated, compensated model (measurement tool).
    pub model: CompensatedModel,
    /// The nominal model with the production tool: the controller.
    pub controller: RobotModel,
    /// The true robot carrying the production tool.
    pub truth: TrueRobot,
    pub payload: f64,
    /// Tool 1 (the torch) and work object 2 (measured in the tracker frame).
    pub cell: Cell,
    /// The work object in the tracker frame (truth).
    pub wobj_cell: Pose,
    /// Joints of the 50 targets (model convention).
    pub joints: Vec<Vec<f64>>,
}

/// The production tool: 250 mm along its axis, tilted 30° about the flange's y.
pub fn torch() -> Pose {
    let r = rpy_matrix(0.0, 30f64.to_radians(), 0.0);
    Pose::new(r, r * Vector3::new(0.0, 0.0, 0.25))
}

pub fn fixture() -> &'static Fixture {
    static F: OnceLock<Fixture> = OnceLock::new();
    F.get_or_init(|| {
        let nominal = preset("ys100").unwrap();
        let payload = nominal.payload.mass;
        let mut truth = TrueRobot::new(ys100_table_7_1());
        truth.noise_mm = 0.01;
        truth.tracker_from_base = tracker_frame(2.0, -1.0, 95.0, [1200.0, -3240.0, 400.0]);
        let mut rng = ChaCha8Rng::seed_from_u64(21);
        let candidates = random_configurations(&nominal, 500, &mut rng);
        let q_id = choose_d_optimal(&nominal, &candidates, 30, payload, true);
        let q_va = random_configurations(&nominal, 30, &mut rng);
        let mut measured = |q: &[Vec<f64>]| {
            let rows = truth.measure(q, Some(payload), None, &mut rng).unwrap();
            measure::to_measurements(&nominal, &rows, payload)
        };
        let (id, va) = (measured(&q_id), measured(&q_va));
        let options = CalibrationOptions {
            methods: vec![Method::Skcm],
            ..Default::default()
        };
        let report = calibrate(&nominal, &id, &va, &options, &|_| true).unwrap();
        let model = CompensatedModel {
            calibrated: report.methods["skcm"].calibrated.clone(),
            nominal: nominal.clone(),
            cell_from_base: report.tracker_to_base.inverse(),
            payload_kg: payload,
            compensator: None,
        };
        let tool = robocal_core::model::Tool {
            p: torch().p,
            rpy: fixed_xyz_angles(&torch().r),
        };
        truth.model.tool = tool.clone();
        let mut controller = nominal.clone();
        controller.tool = tool;
        // A table 1.5 m in front of the robot, turned 20°, measured by the tracker.
        let mut w = Pose::identity();
        w.tr_x(1.5);
        w.tr_y(0.2);
        w.tr_z(0.3);
        w.rot_z(20f64.to_radians());
        let wobj_cell = truth.tracker_from_base.compose(&w);
        let cell = Cell {
            tools: vec![Tool {
                name: "torch".into(),
                number: Some(1),
                tcp: torch(),
            }],
            work_objects: vec![WorkObject {
                name: "table".into(),
                number: Some(2),
                frame: WorkObjectFrame::Measurement,
                pose: wobj_cell,
            }],
        };
        let joints = target_joints(&controller, &mut rng);
        Fixture {
            model,
            controller,
            truth,
            payload,
            cell,
            wobj_cell,
            joints,
        }
    })
}

/// 50 random configurations 5° inside the limits, away from flag boundaries: every
/// controller joint at least 5° from 0 (the
/// calibration moves joints by up to about 1.5°) and |A5| ≥ 10°.
fn target_joints(controller: &RobotModel, rng: &mut ChaCha8Rng) -> Vec<Vec<f64>> {
    let mut out = Vec::new();
    while out.len() < 50 {
        let filter = PoseFilter {
            margin_rad: 5f64.to_radians(),
            ..PoseFilter::default()
        };
        let q = random_configurations_with(controller, 1, &filter, rng).remove(0);
        let deg: Vec<f64> = controller
            .joints_to_controller(&q)
            .iter()
            .map(|v| v.to_degrees())
            .collect();
        let clear = deg.iter().all(|v| v.abs() > 5.0) && deg[4].abs() > 10.0;
        if clear && rng.gen_bool(0.9) {
            out.push(q);
        }
    }
    out
}

impl Fixture {
    /// The true production TCP pose at joints `q`, tracker frame.
    pub fn true_tcp(&self, q: &[f64]) -> Pose {
        self.truth.true_pose(q, Some(self.payload)).unwrap()
    }

    /// Target `i` in the work object: where the true robot puts the torch at `joints[i]`.
    pub fn target(&self, i: usize) -> Pose {
        self.wobj_cell
            .inverse()
            .compose(&self.true_tcp(&self.joints[i]))
    }

    /// Controller joints [deg] and configuration of target `i` (what an OLP writes flags from).
    pub fn flag_input(&self, i: usize) -> (Vec<f64>, Configuration) {
        let q = &self.joints[i];
        let deg = self
            .controller
            .joints_to_controller(q)
            .iter()
            .map(|v| v.to_degrees())
            .collect();
        let ik = AnalyticIk::new(&self.controller).unwrap();
        (deg, ik.configuration(q).unwrap())
    }

    /// The controller's frame of the work object (its base frame, from the registration).
    pub fn wobj_controller(&self) -> Pose {
        self.model.cell_to_base(&self.wobj_cell)
    }

    /// Runs a program through the nominal controller: for each target, the
    /// nominal closed form on the target's flags (nearest the previous joints
    /// when it has none); returns the distance [mm] of the true production TCP
    /// from each target (given as the true target poses, in program order);
    /// `None` where the controller has no solution on the flags.
    pub fn run(
        &self,
        language: Language,
        files: &[ProgramFile],
        truth: &[Pose],
    ) -> Vec<Option<f64>> {
        let program = parse(language, files).unwrap();
        let ik = AnalyticIk::new(&self.controller).unwrap();
        let w = self.wobj_controller();
        let sites: Vec<&Site> = program.sites.iter().filter(|s| s.skip.is_none()).collect();
        assert_eq!(sites.len(), truth.len());
        let mut previous: Option<Vec<f64>> = None;
        let mut errors = Vec::new();
        for (site, want) in sites.iter().zip(truth) {
            let tcp = w.compose(&site.pose.unwrap());
            let q = ik
                .solve(&tcp, previous.as_deref())
                .into_iter()
                .filter(|s| s.within_limits)
                .map(|s| s.q.to_vec())
                .filter(|q| {
                    let deg: Vec<f64> = self
                        .controller
                        .joints_to_controller(q)
                        .iter()
                        .map(|v| v.to_degrees())
                        .collect();
                    site.flags.admits(&deg, ik.configuration(q))
                })
                .min_by(|a, b| {
                    let d = |x: &[f64]| match &previous {
                        Some(p) => x.iter().zip(p).map(|(u, v)| (u - v).abs()).sum::<f64>(),
                        None => 0.0,
                    };
                    d(a).total_cmp(&d(b))
                });
            let Some(q) = q else {
                errors.push(None);
                continue;
            };
            let reached = self.wobj_cell.inverse().compose(&self.true_tcp(&q));
            errors.push(Some((reached.p - want.p).norm() * 1e3));
            previous = Some(q);
        }
        errors
    }
}

/// The mean of the values present, and how many there are.
pub fn mean(v: &[Option<f64>]) -> (f64, usize) {
    let x: Vec<f64> = v.iter().flatten().copied().collect();
    (x.iter().sum::<f64>() / x.len() as f64, x.len())
}

/// `text` with every target value of `sites` in file `file` replaced by `#`.
pub fn masked(text: &str, sites: &[Site], file: usize) -> String {
    let mut ranges: Vec<_> = sites
        .iter()
        .filter(|s| s.file == file)
        .flat_map(|s| s.slots.clone())
        .collect();
    ranges.sort_by_key(|r| r.start);
    let mut out = String::new();
    let mut at = 0;
    for r in ranges {
        out.push_str(&text[at..r.start]);
        out.push('#');
        at = r.end;
    }
    out.push_str(&text[at..]);
    out
}

/// Asserts that `filtered` differs from `original` only in target values.
pub fn assert_only_targets_changed(
    language: Language,
    original: &[ProgramFile],
    filtered: &[ProgramFile],
) {
    let a = parse(language, original).unwrap();
    let b = parse(language, filtered).unwrap();
    assert_eq!(a.sites.len(), b.sites.len());
    for (i, (fa, fb)) in original.iter().zip(filtered).enumerate() {
        assert_eq!(fa.name, fb.name);
        assert_eq!(
            masked(&fa.text, &a.sites, i),
            masked(&fb.text, &b.sites, i),
            "{}",
            fa.name
        );
    }
}

pub fn settings() -> IkSettings {
    IkSettings::default()
}
