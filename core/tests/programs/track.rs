//! A robot on a linear track, in KRL (`E1` of an `E6POS`), RAPID (`eax_a`)
//! and Fanuc (`E1` of `GP1`): the truth is the YS100 with ~1 mm / 0.1°
//! geometric errors (d6 and θ6 as designed: a reflector cannot tell them
//! from its own offset) and effects the kinematic model lacks (a reducer's
//! periodic error, links bending: `common::track::physical_effects`) on the simulated 4 m track from its physics
//! (`sim::track::TrueTrack::rail_4m`: rails bent by sines, a carriage
//! yawing and pitching on its blocks, its rail rising 0.1° and its scale off
//! by 0.2 mm/m); calibrated on a fixed base (KM), the track fitted from
//! readings at 11 stations through the calibrated robot. The controller is
//! the nominal robot with the torch, on its drawing's track (a horizontal
//! rail 25° off the cell's x, scale 1, no maps): it places the robot base
//! at `N(e)` and solves the target in that base, as a controller with a
//! track composes it. 50 targets on a part beside the rail, each at its own
//! track value, none of them a station the track was fitted at. The
//! filtered program brings the true torch tip to the true part within 1.5×
//! the robot's validation RMS on a fixed base, and the torch's orientation
//! to the target's within 1.5× the robot's orientation error at poses it
//! never fitted, carried by the fitted track; the unfiltered one misses by
//! millimetres.

use super::external::{
    assert_every_target_filtered, assert_figures, controller_solution, fanuc_program, krl_program,
    orientation_rms_deg, rapid_program, Miss, Validation, Written,
};
use super::*;
use crate::common::track::{calibrated_on_fixed_base, measure_on_track, ys100_truth, STATIONS};
use robocal_core::calibrate::external::track::{fit_track_compensated, DEFAULT_MAX_ORDER};
use robocal_core::measure::external::ExternalAxis;
use robocal_core::model::external::LinearTrack;
use robocal_core::program::{
    filter_with, track_axis_name, FilterAxes, FilterControl, FilterOutput, TrackAxes,
};
use robocal_core::sim::track::TrueTrack;
use robocal_core::sim::TrueRobot;

/// The cell on the track and its truth.
pub(super) struct TrackCell {
    /// Calibrated robot (reflector tool), fixed-base registration unused.
    pub(super) model: CompensatedModel,
    /// The nominal robot carrying the torch: the controller.
    pub(super) controller: RobotModel,
    pub(super) truth: TrueRobot,
    pub(super) true_track: TrueTrack,
    /// The fitted track and the controller's own.
    pub(super) fitted: LinearTrack,
    pub(super) nominal_track: LinearTrack,
    /// The robot's validation error on a fixed base: its tip's RMS [mm] on
    /// the calibration's held-out poses, its orientation's RMS [deg] on
    /// others against the truth.
    pub(super) validation: Validation,
    /// The part's frame in the cell frame (work object 2, measured).
    pub(super) part: Pose,
    pub(super) cell: Cell,
    /// Per target: its track value [mm] and its pose in the part's frame
    /// (where the true torch tip was at the target's joints).
    pub(super) targets: Vec<(f64, Pose)>,
    /// The targets' controller joints [deg] and configurations, for flags.
    pub(super) flags: Vec<(Vec<f64>, Configuration)>,
}

pub(super) fn track_cell() -> &'static TrackCell {
    static C: OnceLock<TrackCell> = OnceLock::new();
    C.get_or_init(|| {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let (nominal, mut truth) = ys100_truth(&mut rng);
        truth.effects = crate::common::track::physical_effects();
        truth.model.links[5].d = nominal.links[5].d;
        truth.model.links[5].theta = nominal.links[5].theta;
        let true_track = TrueTrack::rail_4m();
        let (calibrated, validation_rms_mm) =
            calibrated_on_fixed_base(&nominal, &truth, &true_track, &mut rng);
        let set = measure_on_track(&truth, &nominal, &true_track, &STATIONS, 15, &mut rng);
        let model = CompensatedModel {
            calibrated,
            nominal: nominal.clone(),
            cell_from_base: Pose::identity(),
            payload_kg: nominal.payload.mass,
            compensator: None,
        };
        let fitted = fit_track_compensated(
            &model,
            &set,
            ExternalAxis::E1,
            crate::common::track::TRACKER_SIGMA_MM,
            DEFAULT_MAX_ORDER,
        )
        .unwrap()
        .model;
        // The drawing: the base 350 mm above the carriage and 120 mm beside
        // it, turned 90° about the vertical, as the truth's design.
        let nominal_track = TrueTrack::drawing_4m();
        let mut controller = nominal.clone();
        controller.tool = robocal_core::model::Tool {
            p: torch().p,
            rpy: fixed_xyz_angles(&torch().r),
        };
        let mut on_rail = Pose::from_translation(Vector3::new(2.0, 1.3, -0.2));
        on_rail.rot_z(10f64.to_radians());
        let part = TrueTrack::drawing_rail_4m().compose(&on_rail);
        let cell = Cell {
            tools: vec![torch_tool()],
            work_objects: vec![WorkObject {
                name: "part".into(),
                number: Some(2),
                frame: WorkObjectFrame::Measurement,
                pose: part,
            }],
        };
        // The robot's orientation against the truth at poses it never
        // fitted, six at each of five track values between the stations (its
        // own generator, so the cell's draws are unchanged).
        let orientation_deg = orientation_rms_deg(
            &model.calibrated,
            &truth,
            30,
            |i| {
                let e = 200.0 + 800.0 * (i % 5) as f64;
                (
                    fitted.cell_from_base(e).unwrap(),
                    true_track.cell_from_base(e),
                )
            },
            &mut ChaCha8Rng::seed_from_u64(99),
        );
        let mut c = TrackCell {
            model,
            controller,
            truth,
            true_track,
            fitted,
            nominal_track,
            validation: Validation {
                mm: validation_rms_mm,
                deg: orientation_deg,
            },
            part,
            cell,
            targets: Vec::new(),
            flags: Vec::new(),
        };
        let ik = AnalyticIk::new(&c.controller).unwrap();
        // Values 50, 130, …, 3970 mm: none is a station (multiples of 400).
        for (i, q) in target_joints(&c.controller, &mut rng)
            .into_iter()
            .enumerate()
        {
            let e = 50.0 + 80.0 * i as f64;
            let target = c.part.inverse().compose(&c.true_tip(&q, e));
            let deg = c.degrees(&q);
            c.targets.push((e, target));
            c.flags.push((deg, ik.configuration(&q).unwrap()));
        }
        c
    })
}

impl TrackCell {
    /// The true torch tip in the cell frame at joints `q` and track value `e`.
    pub(super) fn true_tip(&self, q: &[f64], e: f64) -> Pose {
        let reflector = tool_pose(&self.truth.model);
        self.true_track
            .cell_from_base(e)
            .compose(&self.truth.true_pose_base(q, None).unwrap())
            .compose(&reflector.inverse())
            .compose(&torch())
    }

    pub(super) fn degrees(&self, q: &[f64]) -> Vec<f64> {
        self.controller
            .joints_to_controller(q)
            .iter()
            .map(|v| v.to_degrees())
            .collect()
    }

    fn axes(&self) -> FilterAxes<'_> {
        FilterAxes {
            track: Some(TrackAxes {
                nominal: &self.nominal_track,
                calibrated: &self.fitted,
            }),
            positioner: None,
            correct_values: false,
        }
    }

    /// Runs a program through the nominal controller on its track: each
    /// target's base-frame pose `N(e)⁻¹·W·T` solved in closed form on its
    /// flags, nearest the previous joints; the distance [mm] of the true
    /// torch tip from the true target, per target in program order (`None`
    /// where the controller has no solution on the target's flags).
    fn run(&self, language: Language, files: &[ProgramFile]) -> Vec<Option<Miss>> {
        let program = parse(language, files).unwrap();
        let ik = AnalyticIk::new(&self.controller).unwrap();
        assert_eq!(program.sites.len(), self.targets.len());
        let mut previous: Option<Vec<f64>> = None;
        let mut errors = Vec::new();
        for (site, (e, target)) in program.sites.iter().zip(&self.targets) {
            let programmed = site.axes.iter().find(|a| a.number == 1).unwrap();
            assert_eq!(programmed.value, Some(*e), "{}", site.name);
            let base = self.nominal_track.cell_from_base(*e).unwrap();
            let tcp = base
                .inverse()
                .compose(&self.part)
                .compose(&site.pose.unwrap());
            let found = controller_solution(&ik, &self.controller, site, &tcp, previous.as_deref());
            let Some(q) = found else {
                errors.push(None);
                continue;
            };
            let want = self.part.compose(target);
            errors.push(Some(Miss::of(&self.true_tip(&q, *e), &want)));
            previous = Some(q);
        }
        errors
    }
}

/// The cell's targets as the programs write them, `E1` at each one's track
/// value.
fn written(c: &TrackCell) -> Vec<Written<'_>> {
    c.targets
        .iter()
        .zip(&c.flags)
        .map(|((e, t), (deg, conf))| Written {
            pose: t,
            deg,
            conf: *conf,
            krl_axes: format!("E1 {e:.3},E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0"),
            rapid_axes: format!("[{e:.3},9E+09,9E+09,9E+09,9E+09,9E+09]"),
            fanuc_axes: format!(",\r\n\tE1 = {e:9.3}  mm"),
        })
        .collect()
}

fn krl(c: &TrackCell) -> Vec<ProgramFile> {
    krl_program(
        "rail",
        "$TOOL = TOOL_DATA[1]\r\nBAS(#BASE, 2)\r\n",
        &written(c),
    )
}

/// RAPID with the torch and the part declared in the module, the part a
/// fixed user frame in the world (`ufprog TRUE`, no mechanical unit).
fn rapid(c: &TrackCell) -> Vec<ProgramFile> {
    use super::rapid::frame;
    let data = format!(
        "  PERS tooldata torch:=[TRUE,{},[10,[0,0,100],[1,0,0,0],0,0,0]];\r\n  \
         TASK PERS wobjdata part:=[FALSE,TRUE,\"\",{},[[0,0,0],[1,0,0,0]]];\r\n",
        frame(&torch()),
        frame(&c.part)
    );
    rapid_program("Rail", &data, &written(c))
}

fn fanuc(c: &TrackCell) -> Vec<ProgramFile> {
    fanuc_program("RAIL", 2, &written(c))
}

/// `files` filtered through the cell's track.
fn filter_on_track(c: &TrackCell, language: Language, files: &[ProgramFile]) -> FilterOutput {
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
/// track values, the values and everything but the targets' numbers kept;
/// run through the controller on its nominal track, the true torch tip
/// within 1.5× the robot's validation RMS of the true target (RMS), the
/// unfiltered program millimetres off.
fn assert_on_track(language: Language, files: &[ProgramFile]) {
    let c = track_cell();
    let out = filter_on_track(c, language, files);
    let r = &out.report;
    assert_every_target_filtered(r, 50);
    assert_eq!(r.track_axis.as_deref(), Some(track_axis_name(language)));
    for (t, (e, _)) in r.targets.iter().zip(&c.targets) {
        assert_eq!(t.track_mm, Some(*e));
    }
    assert_only_targets_changed(language, files, &out.files);
    assert_figures(
        &format!("{language:?} on the track"),
        "the calibration's validation rms (mm: the robot's on a fixed base; degrees: the robot's carried by the fitted track to values between the stations)",
        c.validation,
        c.run(language, &out.files),
        c.run(language, files),
    );
}

#[test]
fn krl_on_a_track_reaches_the_part_through_the_calibrated_track() {
    assert_on_track(Language::Krl, &krl(track_cell()));
}

#[test]
fn rapid_on_a_track_reaches_the_part_through_the_calibrated_track() {
    assert_on_track(Language::Rapid, &rapid(track_cell()));
}

#[test]
fn fanuc_on_a_track_reaches_the_part_through_the_calibrated_track() {
    assert_on_track(Language::Fanuc, &fanuc(track_cell()));
}

/// Without the track every target with a track value fails naming the
/// axis; with it, a value beyond the travel measured fails naming the
/// travel, and the rest are filtered.
#[test]
fn a_track_value_the_cell_cannot_compose_is_refused_naming_it() {
    let c = track_cell();
    let files = krl(c);
    let fixed = filter(Language::Krl, &files, &c.cell, &c.model, &settings()).unwrap();
    assert_eq!(fixed.report.failed, 50);
    let why = fixed.report.targets[3].reason.as_deref().unwrap();
    assert!(
        why.contains("external axis E1 to 290.000") && why.contains("does not model"),
        "{why}"
    );
    let beyond = vec![
        ProgramFile {
            name: files[0].name.clone(),
            text: files[0].text.clone(),
        },
        ProgramFile {
            name: files[1].name.clone(),
            text: files[1].text.replacen("E1 50.000", "E1 4100.000", 1),
        },
    ];
    let out = filter_on_track(c, Language::Krl, &beyond);
    assert_eq!((out.report.filtered, out.report.failed), (49, 1));
    let why = out.report.targets[0].reason.as_deref().unwrap();
    assert!(
        why.contains("4100 mm is beyond the controller's nominal travel"),
        "{why}"
    );
    assert!(out.files[1].text.contains("robocal: not filtered"));
}
