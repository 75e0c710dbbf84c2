//! Program filtering against simulated truth (issues 21 and 31, acceptance):
//! a robot with geometry errors, compliance and a payload fixed to its flange
//! (`truth::FlangeTruth`, its own gravity computation), measured by a tracker
//! about 4 m away, calibrated (SKCM); a production tool 250 mm long tilted
//! 30°; 50 targets in a work object measured in the tracker frame. The
//! filtered program, run through the nominal controller (closed-form IK of
//! the nominal model on the program's configuration flags), brings the true
//! robot's production TCP to the targets.

#[path = "../common/mod.rs"]
mod common;

mod accounting;
mod axes_export;
mod examples;
mod export;
mod external;
mod fanuc;
mod krl;
mod motions;
mod positioner;
mod rapid;
mod stationary;
mod track;
mod track_and_positioner;
mod truth;
mod turntable;
mod urscript;

use truth::FlangeTruth;

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use robocal_core::calibrate::identify::{calibrate, CalibrationOptions, Method};
use robocal_core::measure;
use robocal_core::model::calibrated::CompensatedModel;
use robocal_core::model::kinematics::chain::tool_pose;
use robocal_core::model::orientation::fixed_xyz_angles;
use robocal_core::model::pose::rpy_matrix;
use robocal_core::model::{preset, Pose, RobotModel};
use robocal_core::plan::pose_selection::choose_d_optimal;
use robocal_core::program::{filter, parse, Language, ProgramFile, Site, TargetStatus};
use robocal_core::sim::{
    perturb_geometry, random_configurations, random_configurations_with, tracker_frame,
    ys100_table_7_1, ErrorMagnitudes, PoseFilter,
};
use robocal_core::solve::cell::{Cell, Load, Tool, WorkObject, WorkObjectFrame};
use robocal_core::solve::ik::{AnalyticIk, Configuration, IkSettings};
use std::sync::OnceLock;

/// The calibrated cell and the truth with the production tool.
pub struct Fixture {
    /// Calibrated, compensated model (measurement tool).
    pub model: CompensatedModel,
    /// The nominal model with the production tool: the controller.
    pub controller: RobotModel,
    /// The true robot carrying the production tool.
    pub truth: FlangeTruth,
    pub payload: f64,
    /// Tool 1 (the torch) and work object 2 (measured in the tracker frame).
    pub cell: Cell,
    /// The work object in the tracker frame (truth).
    pub wobj_cell: Pose,
    /// Joints of the 50 targets (model convention).
    pub joints: Vec<Vec<f64>>,
}

/// Tool 1, the torch, without a stated load.
pub fn torch_tool() -> Tool {
    Tool {
        name: "torch".into(),
        number: Some(1),
        tcp: torch(),
        load: None,
    }
}

/// The production tool: 250 mm along its axis, tilted 30° about the flange's y.
pub fn torch() -> Pose {
    let r = rpy_matrix(0.0, 30f64.to_radians(), 0.0);
    Pose::new(r, r * Vector3::new(0.0, 0.0, 0.25))
}

/// The YS100 of thesis Table 7.1 (geometry errors, compliance, 110 kg payload)
/// measured by a tracker 3.4 m away; the table 1.5 m in front of the robot.
pub fn fixture() -> &'static Fixture {
    static F: OnceLock<Fixture> = OnceLock::new();
    F.get_or_init(|| {
        // The preset states its 110 kg payload 250 mm out along the flange axis.
        let nominal = preset("ys100").unwrap();
        let model = ys100_table_7_1();
        let reflector = tool_pose(&model);
        let tracker = tracker_frame(2.0, -1.0, 95.0, [1200.0, -3800.0, 400.0]);
        let mut truth = FlangeTruth::new(model, reflector, tracker);
        truth.payload_kg = 110.0;
        truth.payload_com = Vector3::new(0.0, 0.0, 0.25);
        build(nominal, truth, [1.5, 0.2, 0.3], 21, false)
    })
}

/// A UR5 with a reflector 150 mm off the flange, ±1 mm / ±0.1° geometry
/// errors (but for d6 and θ6, which the reflector absorbs: see docs/design.md),
/// joint compliance and a 3 kg payload 60 mm out on the flange, measured by
/// a tracker 2.5 m away.
pub fn fixture_ur5() -> &'static Fixture {
    static F: OnceLock<Fixture> = OnceLock::new();
    F.get_or_init(|| {
        let mut nominal = preset("ur5").unwrap();
        nominal.tool.p = Vector3::new(0.06, 0.04, 0.12);
        nominal.payload.mass = 3.0;
        // Stated in the reflector's frame, as a model file without `com_frame` reads.
        nominal.payload.com = Vector3::new(-0.06, -0.04, -0.06);
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let mut model =
            perturb_geometry(&nominal, &ErrorMagnitudes::from_mm_deg(1.0, 0.1), &mut rng);
        model.links[5].d = nominal.links[5].d;
        model.links[5].theta = nominal.links[5].theta;
        for k in 1..4 {
            model.links[k].compliance = 4e-6;
        }
        let reflector = tool_pose(&model);
        let tracker = tracker_frame(1.0, 0.5, -60.0, [-800.0, 2300.0, -200.0]);
        let mut truth = FlangeTruth::new(model, reflector, tracker);
        truth.payload_kg = 3.0;
        truth.payload_com = Vector3::new(0.0, 0.0, 0.06);
        build(nominal, truth, [0.45, -0.1, 0.05], 22, true)
    })
}

/// Measures and calibrates (SKCM) `truth` against `nominal`, then puts the
/// torch on both; the table at `table_m` in the truth's base frame, turned 20°.
/// `walk`: the targets are a path from the home joints (as a robot without
/// configuration flags needs: its controller takes the solution nearest the
/// current joints), else independent configurations.
fn build(
    nominal: RobotModel,
    mut truth: FlangeTruth,
    table_m: [f64; 3],
    seed: u64,
    walk: bool,
) -> Fixture {
    let payload = nominal.payload.mass;
    truth.noise_mm = 0.01;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let candidates = random_configurations(&nominal, 500, &mut rng);
    let q_id = choose_d_optimal(&nominal, &candidates, 30, payload, true);
    let q_va = random_configurations(&nominal, 30, &mut rng);
    let mut measured = |q: &[Vec<f64>]| {
        let rows = truth.measure(q, &mut rng);
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
    truth.tool = torch();
    let mut controller = nominal.clone();
    controller.tool = tool;
    let mut w = Pose::from_translation(Vector3::from(table_m));
    w.rot_z(20f64.to_radians());
    let wobj_cell = truth.tracker_from_base.compose(&w);
    let cell = Cell {
        tools: vec![torch_tool()],
        work_objects: vec![WorkObject {
            name: "table".into(),
            number: Some(2),
            frame: WorkObjectFrame::Measurement,
            pose: wobj_cell,
        }],
    };
    let joints = if walk {
        target_walk(&controller, &mut rng)
    } else {
        target_joints(&controller, &mut rng)
    };
    Fixture {
        model,
        controller,
        truth,
        payload,
        cell,
        wobj_cell,
        joints,
    }
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

/// The home joints of the URScript program [rad].
pub const UR_HOME: [f64; 6] = [0.0, -1.6, 1.6, 0.0, 1.6, 0.0];

/// 50 configurations from `UR_HOME` in random steps of up to 15° per joint,
/// each the nominal closed form's solution nearest the one before, with
/// |q3|, |q5| ≥ 10° (away from the stretched elbow and the wrist singularity),
/// all in the branch of `UR_HOME` with a 5° margin on every joint.
fn target_walk(controller: &RobotModel, rng: &mut ChaCha8Rng) -> Vec<Vec<f64>> {
    let ik = AnalyticIk::new(controller).unwrap();
    let mut out: Vec<Vec<f64>> = Vec::new();
    let mut q = UR_HOME.to_vec();
    while out.len() < 50 {
        let next: Vec<f64> = q
            .iter()
            .map(|v| v + rng.gen_range(-15f64..15.0).to_radians())
            .collect();
        let tcp = robocal_core::model::kinematics::fk(controller, &next).unwrap();
        let clear = next[2].abs() > 0.17 && next[4].abs() > 0.17 && tcp.p.z > 0.05;
        let d = |a: &[f64]| a.iter().zip(&q).map(|(x, y)| (x - y).abs()).sum::<f64>();
        let nearest = ik
            .solve(&tcp, Some(&q))
            .into_iter()
            .filter(|s| s.within_limits)
            .min_by(|a, b| d(&a.q).total_cmp(&d(&b.q)));
        let own = nearest.is_some_and(|s| s.q.iter().zip(&next).all(|(a, b)| (a - b).abs() < 1e-6));
        // One branch throughout, 5° from any other (its boundaries are the
        // singularities): no singular configuration crossed or approached.
        let home = ik.configuration(&UR_HOME);
        let branch = (0..13).all(|k| {
            let mut p = next.clone();
            if k > 0 {
                p[(k - 1) / 2] += if k % 2 == 0 { 0.087 } else { -0.087 };
            }
            ik.configuration(&p) == home
        });
        if clear && own && branch && controller.within_limits(&next, 0.0) {
            out.push(next.clone());
            q = next;
        }
    }
    out
}

impl Fixture {
    /// The true production TCP pose at joints `q`, tracker frame.
    pub fn true_tcp(&self, q: &[f64]) -> Pose {
        self.truth.tcp(q)
    }

    /// The true load: the payload on the flange.
    pub fn true_load(&self) -> Load {
        Load {
            mass_kg: self.truth.payload_kg,
            com: self.truth.payload_com,
            inertia_kgm2: None,
        }
    }

    /// The fixture's cell with the true load on the torch.
    pub fn cell_with_load(&self) -> Cell {
        let mut cell = self.cell.clone();
        cell.tools[0].load = Some(self.true_load());
        cell
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
            if let Some(j) = &site.after_joints {
                let rad: Vec<f64> = j.iter().map(|v| v.to_radians()).collect();
                previous = Some(self.controller.joints_from_controller(&rad));
            }
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

/// Issues 21 and 31's acceptance for one language: all 50 targets of `files`
/// are filtered; run through the nominal controller, the filtered program
/// brings the true robot's production TCP within 0.03 mm mean and 0.15 mm
/// max of the targets and the unfiltered one more than 1 mm off; only the
/// target bytes changed.
pub fn assert_filter_reaches_targets(
    f: &Fixture,
    language: Language,
    label: &str,
    files: &[ProgramFile],
    cell: &Cell,
) {
    let out = filter(language, files, cell, &f.model, &settings()).unwrap();
    let r = &out.report;
    assert_eq!(
        (r.filtered, r.failed, r.skipped),
        (50, 0, 0),
        "{:?}",
        r.targets
    );
    assert!(r.targets.iter().all(|t| t.status == TargetStatus::Filtered));
    // The sites come in the order the program runs them: the truth in that order.
    let truth: Vec<Pose> = (0..50).map(|i| f.target(i)).collect();
    let errors = f.run(language, &out.files, &truth);
    let (filtered, n) = mean(&errors);
    let max = errors.iter().flatten().fold(0.0f64, |a, b| a.max(*b));
    let (nominal, n0) = mean(&f.run(language, files, &truth));
    eprintln!("{label}: true TCP from the targets: filtered mean {filtered:.4} mm, max {max:.4} mm ({n}); unfiltered mean {nominal:.3} mm ({n0})");
    assert_eq!(n, 50);
    assert!(filtered < 0.03, "filtered {filtered} mm");
    assert!(max <= 0.15, "filtered max {max} mm");
    assert!(nominal > 1.0, "unfiltered {nominal} mm");
    assert_only_targets_changed(language, files, &out.files);
}

pub fn settings() -> IkSettings {
    IkSettings::default()
}
