//! A part on a two-axis tilt-rotate positioner, in KRL (a base on the
//! positioner's face plate, `E1`, `E2` of an `E6POS`), RAPID (a `wobjdata`
//! moved by the unit `STN1`, `ufprog FALSE`, `eax_a`, `eax_b`) and Fanuc
//! (`J1`, `J2` of motion group `GP2`). The truth: the YS100 with ~1 mm / 0.1°
//! geometric errors (d6 and θ6 as designed) and effects the kinematic model
//! lacks (`common::track::physical_effects`) 1.6 m beside the positioner of
//! `sim::positioner_example` (axes tilted 0.05° and offset 0.5 mm from their
//! drawing, zero offsets, scale errors and a nod of the rotate axis no rigid
//! model holds, from its physics). Calibrated: the robot on its fixed base
//! (KM, 40 + 30 poses, registered in the tracker frame), the positioner
//! from tracker readings of two reflectors on its plate (50 readings). The
//! part is taught on the plate as a cell does: measured in the cell with
//! both axes at 0 and located on the plate through the calibrated
//! positioner. The controller is the nominal robot with a 250 mm torch
//! tilted 30°, and the drawing's positioner in its world (the robot's base
//! frame): it puts the part at `P_nom(v)·W_f` and solves the target there.
//! 50 targets on the part, each at its own pair of values (none fitted,
//! tilts within ±40°). The filtered program brings the true torch tip to the
//! true, moved part within 1.5× the calibration's validation error (the
//! robot's and the positioner's held-out RMS, in quadrature), and the
//! torch's orientation likewise (the robot's orientation error at poses it
//! never fitted, the positioner's at the held-out pairs); the unfiltered
//! one misses by millimetres.

use super::external::{
    assert_every_target_filtered, assert_figures, assert_positioner_values_kept,
    controller_solution, fanuc_program, krl_program, orientation_rms_deg, rapid_program, Miss,
    Validation, Written,
};
use super::*;
use crate::common::positioner::{self as example, fit_plan, DESIGN_MM, TRACKER_SIGMA_MM};
use crate::common::track::ys100_truth;
use nalgebra::Matrix3;
use robocal_core::calibrate::external::{fit_positioner, PositionerFitRequest};
use robocal_core::model::external::TiltRotate;
use robocal_core::model::orientation::rotation_angle_between;
use robocal_core::program::{
    filter_with, positioner_axis_names, FilterAxes, FilterControl, FilterOutput, PositionerAxes,
};
use robocal_core::sim::positioner::TruePositioner;
use robocal_core::sim::TrueRobot;

/// The positioner cell and its truth.
struct PositionerCell {
    /// Calibrated robot (reflector tool), registered in the tracker frame.
    model: CompensatedModel,
    /// The nominal robot carrying the torch: the controller.
    controller: RobotModel,
    truth: TrueRobot,
    true_positioner: TruePositioner,
    /// The fitted positioner (tracker frame) and the controller's own (its
    /// world: the robot's base frame).
    fitted: TiltRotate,
    nominal_positioner: TiltRotate,
    /// The calibration's validation error: the robot's and the positioner's
    /// held-out RMS in quadrature [mm]; the robot's orientation RMS [deg]
    /// on poses it never fitted and the positioner's at the held-out pairs,
    /// against the truth, in quadrature.
    validation: Validation,
    /// The part's frame on the rotate body at true angles 0 (module docs).
    body: Pose,
    cell: Cell,
    /// Per target: its positioner values [deg] and its pose in the part's
    /// frame.
    targets: Vec<([f64; 2], Pose)>,
    /// The targets' controller joints [deg] and configurations, for flags.
    flags: Vec<(Vec<f64>, Configuration)>,
}

/// The robot's place in the cell (the tracker frame): 1.6 m from the
/// positioner's base, facing it, as its drawing has it.
pub(super) use crate::common::touches::robot_in_cell;

/// The part's true pose in the cell at values `v`: its origin and its axes'
/// tips carried by the true positioner's physics.
pub(super) fn true_part(t: &TruePositioner, body: &Pose, v: [f64; 2]) -> Pose {
    let arm = 0.1;
    let o = t.point(v, &body.p);
    let axis = |k: usize| (t.point(v, &(body.p + body.r.column(k) * arm)) - o) / arm;
    Pose::new(Matrix3::from_columns(&[axis(0), axis(1), axis(2)]), o)
}

/// A target's positioner values (tilt −40…40°, rotate −170…170°) and its
/// pose on the part: within 150 mm of its origin, the torch pointing into
/// it within 20° of its normal.
pub(super) fn draw_on_part(rng: &mut ChaCha8Rng) -> ([f64; 2], Pose) {
    let v = [rng.gen_range(-40.0..40.0), rng.gen_range(-170.0..170.0)];
    let mut t = Pose::from_translation(Vector3::new(
        rng.gen_range(-0.15..0.15),
        rng.gen_range(-0.15..0.15),
        rng.gen_range(0.0..0.05),
    ));
    t.r = rpy_matrix(
        std::f64::consts::PI + rng.gen_range(-0.35..0.35),
        rng.gen_range(-0.35..0.35),
        rng.gen_range(-3.1..3.1),
    );
    (v, t)
}

/// A positioner fitted from its truth's readings, its validation and the
/// part taught on it.
pub(super) struct Fitted {
    /// The fitted positioner, in the frame the truth is read in.
    pub model: TiltRotate,
    /// The reference reflector's RMS [mm] at the 56 held-out pairs of
    /// values, and the taught part's orientation RMS [deg] there, both
    /// against the truth.
    pub validation: Validation,
    /// The part `body` taught on the plate: measured with both axes at 0
    /// and located on the plate through the fitted positioner.
    pub taught: Pose,
}

/// The positioner `truth` fitted from 50 readings of two reflectors from
/// its drawing `nominal` (in the same frame), judged at the held-out pairs,
/// and the part on its rotate body at `body` taught on it.
pub(super) fn fit_and_teach(
    truth: &TruePositioner,
    nominal: TiltRotate,
    body: &Pose,
    rng: &mut ChaCha8Rng,
) -> Fitted {
    let fit = fit_positioner(&PositionerFitRequest {
        nominal,
        reflectors_mm: DESIGN_MM.to_vec(),
        readings: truth.read(&fit_plan(), rng),
        tracker_sigma_mm: TRACKER_SIGMA_MM,
    })
    .unwrap();
    // The positioner's validation: the reference reflector at the 56
    // held-out pairs of values, read by the tracker, against the model.
    let held: Vec<(usize, [f64; 2])> = example::held_out().into_iter().map(|v| (0, v)).collect();
    let on_plate = Vector3::from(fit.reflectors_mm[0]) * 1e-3;
    let errors: Vec<f64> = truth
        .read(&held, rng)
        .iter()
        .map(|r| {
            let got = fit.model.point_in_cell(r.values_deg, &on_plate);
            (got - Vector3::from(r.xyz_mm) * 1e-3).norm() * 1e3
        })
        .collect();
    let rms = |v: &[f64]| (v.iter().map(|e| e * e).sum::<f64>() / v.len() as f64).sqrt();
    // Taught at axes 0: measured in the cell, located on the plate through
    // the calibrated positioner.
    let taught = fit
        .model
        .cell_from_face_plate([0.0, 0.0])
        .inverse()
        .compose(&true_part(truth, body, [0.0, 0.0]));
    // The positioner's orientation error at the held-out pairs: the taught
    // part carried by the fitted positioner against the true, moved part
    // (the nod no rigid model holds is in it).
    let turns: Vec<f64> = example::held_out()
        .iter()
        .map(|v| {
            let got = fit.model.cell_from_face_plate(*v).compose(&taught);
            let want = true_part(truth, body, *v);
            rotation_angle_between(&got.r, &want.r).to_degrees()
        })
        .collect();
    Fitted {
        model: fit.model,
        validation: Validation {
            mm: rms(&errors),
            deg: rms(&turns),
        },
        taught,
    }
}

fn positioner_cell() -> &'static PositionerCell {
    static C: OnceLock<PositionerCell> = OnceLock::new();
    C.get_or_init(|| {
        let mut rng = ChaCha8Rng::seed_from_u64(12);
        let (nominal, mut truth) = ys100_truth(&mut rng);
        truth.effects = crate::common::track::physical_effects();
        truth.model.links[5].d = nominal.links[5].d;
        truth.model.links[5].theta = nominal.links[5].theta;
        truth.tracker_from_base = robot_in_cell();
        let (model, robot_rms_mm) = crate::common::touches::calibrated(&nominal, &truth, &mut rng);
        let true_positioner = example::truth(0.003);
        // The part: 60 mm above the plate, 150 mm from axis 2, turned.
        let body = Pose::new(rpy_matrix(0.0, 0.0, 0.6), Vector3::new(0.12, 0.09, 1.16));
        let fit = fit_and_teach(&true_positioner, example::nominal(), &body, &mut rng);
        // The controller's positioner: the drawing, in its world (the
        // robot's base frame, where the drawing puts the robot).
        let mut nominal_positioner = example::nominal();
        nominal_positioner.cell_from_base = robot_in_cell()
            .inverse()
            .compose(&nominal_positioner.cell_from_base);
        let mut controller = nominal.clone();
        controller.tool = robocal_core::model::Tool {
            p: torch().p,
            rpy: fixed_xyz_angles(&torch().r),
        };
        let cell = Cell {
            tools: vec![torch_tool()],
            work_objects: vec![WorkObject {
                name: "part".into(),
                number: Some(3),
                frame: WorkObjectFrame::FacePlate,
                pose: fit.taught,
            }],
        };
        // The robot's orientation against the truth at poses it never
        // fitted, in the tracker frame (its own generator, so the cell's
        // draws are unchanged).
        let orientation_deg = orientation_rms_deg(
            &model.calibrated,
            &truth,
            30,
            |_| (model.cell_from_base, truth.tracker_from_base),
            &mut ChaCha8Rng::seed_from_u64(99),
        );
        let mut c = PositionerCell {
            model,
            controller,
            truth,
            true_positioner,
            fitted: fit.model,
            nominal_positioner,
            validation: Validation {
                mm: robot_rms_mm.hypot(fit.validation.mm),
                deg: orientation_deg.hypot(fit.validation.deg),
            },
            body,
            cell,
            targets: Vec::new(),
            flags: Vec::new(),
        };
        c.place_targets(&mut rng);
        c
    })
}

impl PositionerCell {
    /// 50 targets on the part (within 150 mm of its origin, the torch
    /// pointing into it within 20° of its normal), each at its own values
    /// (tilt −40…40°, rotate −170…170°, none a fitted pair), kept where the
    /// nominal controller reaches the target's pose with its tool.
    fn place_targets(&mut self, rng: &mut ChaCha8Rng) {
        let ik = AnalyticIk::new(&self.controller).unwrap();
        let mut k = 0usize;
        while self.targets.len() < 50 {
            k += 1;
            assert!(k < 2000, "no reachable targets");
            let (v, t) = draw_on_part(rng);
            let tcp = self.controller_frame(v).compose(&t);
            let found = ik
                .solve(&tcp, None)
                .into_iter()
                .find(|s| s.within_limits)
                .map(|s| s.q.to_vec());
            if let Some(q) = found {
                let deg = self.degrees(&q);
                self.flags.push((deg, ik.configuration(&q).unwrap()));
                self.targets.push((v, t));
            }
        }
    }

    /// The part's frame as the controller computes it at values `v`:
    /// `P_nom(v)·W_f` in its base frame.
    fn controller_frame(&self, v: [f64; 2]) -> Pose {
        self.nominal_positioner
            .cell_from_face_plate(v)
            .compose(&self.cell.work_objects[0].pose)
    }

    /// The true torch tip in the cell frame at joints `q`.
    fn true_tip(&self, q: &[f64]) -> Pose {
        let reflector = tool_pose(&self.truth.model);
        self.truth
            .tracker_from_base
            .compose(&self.truth.true_pose_base(q, None).unwrap())
            .compose(&reflector.inverse())
            .compose(&torch())
    }

    fn degrees(&self, q: &[f64]) -> Vec<f64> {
        self.controller
            .joints_to_controller(q)
            .iter()
            .map(|v| v.to_degrees())
            .collect()
    }

    fn axes(&self) -> FilterAxes<'_> {
        FilterAxes {
            track: None,
            positioner: Some(PositionerAxes {
                nominal: &self.nominal_positioner,
                calibrated: &self.fitted,
                turntable: false,
            }),
            correct_values: false,
        }
    }

    /// Runs a program through the nominal controller composing its
    /// positioner: each target's base-frame pose `P_nom(v)·W_f·T` solved in
    /// closed form on its flags, nearest the previous joints; the distance
    /// [mm] of the true torch tip from the target on the true, moved part,
    /// per target in program order (`None` where the controller has no
    /// solution on the target's flags).
    fn run(&self, language: Language, files: &[ProgramFile]) -> Vec<Option<Miss>> {
        let program = parse(language, files).unwrap();
        let ik = AnalyticIk::new(&self.controller).unwrap();
        assert_eq!(program.sites.len(), self.targets.len());
        let group = robocal_core::program::positioner_group(language);
        let mut previous: Option<Vec<f64>> = None;
        let mut errors = Vec::new();
        for (site, (v, target)) in program.sites.iter().zip(&self.targets) {
            let value = |n: usize| {
                site.axes
                    .iter()
                    .find(|a| a.group == group && a.number == n)
                    .and_then(|a| a.value)
                    .unwrap()
            };
            let programmed = [value(1), value(2)];
            assert!(
                (programmed[0] - v[0]).abs() < 1e-3 && (programmed[1] - v[1]).abs() < 1e-3,
                "{}: {programmed:?} {v:?}",
                site.name
            );
            let tcp = self
                .controller_frame(programmed)
                .compose(&site.pose.unwrap());
            let found = controller_solution(&ik, &self.controller, site, &tcp, previous.as_deref());
            let Some(q) = found else {
                errors.push(None);
                continue;
            };
            let want = true_part(&self.true_positioner, &self.body, programmed).compose(target);
            errors.push(Some(Miss::of(&self.true_tip(&q), &want)));
            previous = Some(q);
        }
        errors
    }
}

/// The cell's targets as the programs write them, the positioner's values
/// in KRL's `E1`, `E2`, RAPID's `eax_a`, `eax_b` and Fanuc's `GP2`.
fn written(c: &PositionerCell) -> Vec<Written<'_>> {
    c.targets
        .iter()
        .zip(&c.flags)
        .map(|(([v1, v2], t), (deg, conf))| Written {
            pose: t,
            deg,
            conf: *conf,
            krl_axes: format!("E1 {v1:.4},E2 {v2:.4},E3 0.0,E4 0.0,E5 0.0,E6 0.0"),
            rapid_axes: format!("[{v1:.4},{v2:.4},9E+09,9E+09,9E+09,9E+09]"),
            fanuc_axes: format!(
                "\r\n   GP2:\r\n\tUF : 3, UT : 1,\r\n\tJ1 = {v1:9.4} deg,\tJ2 = {v2:9.4} deg"
            ),
        })
        .collect()
}

/// KRL with base 3 (the part, on the face plate in the cell file).
fn krl(c: &PositionerCell) -> Vec<ProgramFile> {
    krl_program(
        "turn",
        "$TOOL = TOOL_DATA[1]\r\nBAS(#BASE, 3)\r\n",
        &written(c),
    )
}

/// RAPID with the torch and the part declared in the module, the part a
/// work object the positioner `STN1` moves (`ufprog FALSE`): its object
/// frame on the face plate, its user frame the controller's.
fn rapid(c: &PositionerCell) -> Vec<ProgramFile> {
    rapid_on_plate("Turn", &c.cell.work_objects[0].pose, &written(c))
}

/// A RAPID module `name` declaring the torch and the part, a work object
/// the positioner `STN1` moves (`ufprog FALSE`) whose object frame on the
/// face plate is `on_plate`.
pub(super) fn rapid_on_plate(name: &str, on_plate: &Pose, targets: &[Written]) -> Vec<ProgramFile> {
    use super::rapid::frame;
    let data = format!(
        "  PERS tooldata torch:=[TRUE,{},[10,[0,0,100],[1,0,0,0],0,0,0]];\r\n  \
         TASK PERS wobjdata part:=[FALSE,FALSE,\"STN1\",[[0,0,0],[1,0,0,0]],{}];\r\n",
        frame(&torch()),
        frame(on_plate)
    );
    rapid_program(name, &data, targets)
}

/// Fanuc with user frame 3 (the part, coordinated with the positioner) and
/// the positioner's values in group 2.
fn fanuc(c: &PositionerCell) -> Vec<ProgramFile> {
    fanuc_program("TURN", 3, &written(c))
}

/// `files` filtered through the cell's positioner.
fn filter_on_positioner(
    c: &PositionerCell,
    language: Language,
    files: &[ProgramFile],
) -> FilterOutput {
    filter_with(
        language,
        files,
        &c.cell,
        &c.model,
        &settings(),
        &c.axes(),
        &FilterControl::default(),
    )
    .unwrap()
}

/// The acceptance for one language: all 50 targets filtered at their own
/// values, the values and everything but the targets' numbers kept; run
/// through the controller composing its nominal positioner, the true torch
/// tip within 1.5× the calibration's validation error of the target on the
/// true part (RMS), the unfiltered program millimetres off.
fn assert_on_positioner(language: Language, files: &[ProgramFile]) {
    let c = positioner_cell();
    let out = filter_on_positioner(c, language, files);
    let r = &out.report;
    assert_every_target_filtered(r, 50);
    assert_positioner_values_kept(
        r,
        &positioner_axis_names(language, false),
        c.targets.iter().map(|(v, _)| *v),
    );
    assert_only_targets_changed(language, files, &out.files);
    assert_figures(
        &format!("{language:?} on the positioner"),
        "the calibration's validation rms (the robot's and the positioner's)",
        c.validation,
        c.run(language, &out.files),
        c.run(language, files),
    );
}

#[test]
fn krl_on_a_positioner_reaches_the_moved_part_through_the_calibrated_positioner() {
    assert_on_positioner(Language::Krl, &krl(positioner_cell()));
}

#[test]
fn rapid_on_a_positioner_reaches_the_moved_part_through_the_calibrated_positioner() {
    assert_on_positioner(Language::Rapid, &rapid(positioner_cell()));
}

#[test]
fn fanuc_on_a_positioner_reaches_the_moved_part_through_the_calibrated_positioner() {
    assert_on_positioner(Language::Fanuc, &fanuc(positioner_cell()));
}

/// Without the positioner every target on the plate fails naming the axes
/// (KRL: the work object, its zeros no axis); a target without values in a
/// plate work object fails naming what it lacks; the rest are filtered.
#[test]
fn a_positioner_target_the_cell_cannot_compose_is_refused_naming_it() {
    let c = positioner_cell();
    let files = fanuc(c);
    let fixed = filter(Language::Fanuc, &files, &c.cell, &c.model, &settings()).unwrap();
    assert_eq!(fixed.report.failed, 50);
    let why = fixed.report.targets[0].reason.as_deref().unwrap();
    assert!(
        why.contains("J1 of motion group GP2") && why.contains("does not model"),
        "{why}"
    );
    let files = krl(c);
    let fixed = filter(Language::Krl, &files, &c.cell, &c.model, &settings()).unwrap();
    assert_eq!(fixed.report.failed, 50);
    let why = fixed.report.targets[0].reason.as_deref().unwrap();
    assert!(why.contains("external axis E1"), "{why}");
    // A target that leaves the positioner's values out (a POS, not an E6POS).
    let first = &files[1].text;
    let start = first.find("DECL E6POS XP0=").unwrap();
    let end = start + first[start..].find("\r\n").unwrap();
    let line = &first[start..end];
    let cut = line.find(",E1 ").unwrap();
    let pos = format!("{}}}", &line[..cut]).replace("E6POS", "POS");
    let lacking = vec![
        ProgramFile {
            name: files[0].name.clone(),
            text: files[0].text.clone(),
        },
        ProgramFile {
            name: files[1].name.clone(),
            text: first.replacen(line, &pos, 1),
        },
    ];
    let out = filter_on_positioner(c, Language::Krl, &lacking);
    assert_eq!((out.report.filtered, out.report.failed), (49, 1));
    let why = out.report.targets[0].reason.as_deref().unwrap();
    assert!(
        why.contains("work object part is on the positioner's face plate")
            && why.contains("no value for the positioner's axes"),
        "{why}"
    );
    assert!(out.files[1].text.contains("robocal: not filtered"));
}

/// The report's controller data: in KRL the part as a base coupled to the
/// positioner, its pose on the face plate, which the controller's own
/// positioner carries to the very frame the programs ran in (read back with
/// the export test's reader); Fanuc, whose coordinated frame is not
/// written, leaves the part out and says so at every target.
#[test]
fn the_report_holds_the_plate_work_object_as_a_coupled_base_in_krl() {
    use super::axes_export::{apart, frame_after, iso, ROUNDING_MM};
    let c = positioner_cell();
    let out = filter_on_positioner(c, Language::Krl, &krl(c));
    let data = &out.report.controller_data;
    assert!(
        data.contains("; BASE_DATA[3] part is on the face plate: $BASE=EK(MACHINE_DEF[2].ROOT,MACHINE_DEF[2].MECH_TYPE,BASE_DATA[3])"),
        "{data}"
    );
    let base3 = frame_after(data, "BASE_DATA[3]=");
    for (v, _) in &c.targets {
        let got = iso(&c.nominal_positioner.cell_from_face_plate(*v)) * base3;
        let (d, a) = apart(&got, &iso(&c.controller_frame(*v)));
        assert!(d < ROUNDING_MM && a < 1e-9, "{v:?}: {d} mm, {a} rad");
    }
    let turns = |r: &robocal_core::program::FilterReport| {
        r.targets
            .iter()
            .filter(|t| {
                t.warnings
                    .iter()
                    .any(|w| w.contains("turns with the positioner"))
            })
            .count()
    };
    assert_eq!(turns(&out.report), 0);
    let out = filter_on_positioner(c, Language::Fanuc, &fanuc(c));
    assert_eq!(turns(&out.report), 50);
    assert!(
        !out.report.controller_data.contains("part"),
        "{}",
        out.report.controller_data
    );
}
