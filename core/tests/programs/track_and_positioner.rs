//! A robot on a linear track welding a part on a two-axis positioner, in
//! KRL (`E1` the track, `E2`, `E3` the positioner, a base on its face
//! plate), RAPID (`eax_a`, `eax_b`, `eax_c`, a `wobjdata` moved by `STN1`)
//! and Fanuc (`E1` of `GP1`, `J1`, `J2` of `GP2`). The truths are the two
//! cells' (`track.rs`, `positioner.rs`), from their physics: the YS100 with
//! ~1 mm / 0.1° geometric errors on the simulated 4 m track (bent rails, a
//! yawing carriage, a rising rail, a scale error), and beside its rail the
//! example positioner (axes tilted 0.05° and offset 0.5 mm, zero offsets,
//! scale errors, a nod of the rotate axis no rigid model holds), placed
//! where the robot at 2000 mm on the track sees it as the positioner cell's
//! robot does. Calibrated: the robot and its track as in `track.rs`, the
//! positioner from 50 readings of two reflectors in the same cell frame; the
//! part taught on the plate with both axes at 0. The controller: the nominal
//! robot with the torch on the drawing's track, the drawing's positioner in
//! its world (the cell frame): it puts the part at `N(e)⁻¹·P_nom(v)·W_f` in
//! the base and solves there. 50 targets on the part, each at its own track
//! value (1700–2300 mm, none a station) and pair of positioner values (none
//! fitted). The filtered program brings the true torch tip to the true,
//! moved part within 1.5× the calibration's validation error (the robot's
//! and the positioner's, in quadrature; the robot's orientation carried by
//! the fitted track); the unfiltered one misses by millimetres.

use super::external::{
    assert_every_target_filtered, assert_figures, assert_positioner_values_kept,
    controller_solution, fanuc_program, krl_program, rms, Miss, Validation, Written,
};
use super::positioner::{draw_on_part, fit_and_teach, rapid_on_plate, robot_in_cell, true_part};
use super::track::{track_cell, TrackCell};
use super::*;
use crate::common::positioner as example;
use robocal_core::model::external::TiltRotate;
use robocal_core::program::{
    filter_with, positioner_axis_names, positioner_group, track_axis_name, FilterAxes,
    FilterControl, FilterOutput, PositionerAxes, TrackAxes,
};
use robocal_core::sim::positioner::TruePositioner;

/// The track value [mm] at which the robot sees the positioner as the
/// positioner cell's robot does.
const BESIDE_MM: f64 = 2000.0;

/// The cell: the track cell's robot and track, a positioner beside the rail.
struct BothCell {
    track: &'static TrackCell,
    true_positioner: TruePositioner,
    /// The fitted positioner and the controller's own, both in the cell
    /// frame (the controller's world).
    fitted: TiltRotate,
    nominal_positioner: TiltRotate,
    validation: Validation,
    /// The part on the rotate body at true angles 0.
    body: Pose,
    cell: Cell,
    /// Per target: its track value [mm], positioner values [deg] and pose
    /// in the part's frame.
    targets: Vec<(f64, [f64; 2], Pose)>,
    flags: Vec<(Vec<f64>, Configuration)>,
}

fn both_cell() -> &'static BothCell {
    static C: OnceLock<BothCell> = OnceLock::new();
    C.get_or_init(|| {
        let track = track_cell();
        let mut rng = ChaCha8Rng::seed_from_u64(13);
        // The positioner cell's frame carried into the track's: the robot's
        // drawn base at BESIDE_MM where the positioner cell has its robot.
        let into_cell = track
            .nominal_track
            .cell_from_base(BESIDE_MM)
            .unwrap()
            .compose(&robot_in_cell().inverse());
        let mut true_positioner = example::truth(0.003);
        true_positioner.cell_from_base = into_cell.compose(&true_positioner.cell_from_base);
        let mut nominal_positioner = example::nominal();
        nominal_positioner.cell_from_base = into_cell.compose(&nominal_positioner.cell_from_base);
        let body = Pose::new(rpy_matrix(0.0, 0.0, 0.6), Vector3::new(0.12, 0.09, 1.16));
        let fit = fit_and_teach(&true_positioner, nominal_positioner, &body, &mut rng);
        let cell = Cell {
            tools: vec![torch_tool()],
            work_objects: vec![WorkObject {
                name: "part".into(),
                number: Some(3),
                frame: WorkObjectFrame::FacePlate,
                pose: fit.taught,
            }],
        };
        let mut c = BothCell {
            track,
            true_positioner,
            fitted: fit.model,
            nominal_positioner,
            validation: Validation {
                mm: track.validation.mm.hypot(fit.validation.mm),
                deg: track.validation.deg.hypot(fit.validation.deg),
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

impl BothCell {
    /// 50 targets on the part (as `positioner.rs` places them), each at its
    /// own track value within 300 mm of [`BESIDE_MM`] and pair of values,
    /// kept where the nominal controller reaches them with its tool.
    fn place_targets(&mut self, rng: &mut ChaCha8Rng) {
        let ik = AnalyticIk::new(&self.track.controller).unwrap();
        let mut k = 0usize;
        while self.targets.len() < 50 {
            k += 1;
            assert!(k < 4000, "no reachable targets");
            let e = (BESIDE_MM + rng.gen_range(-300.0..300.0)).round();
            let (v, t) = draw_on_part(rng);
            let tcp = self.controller_frame(e, v).compose(&t);
            let found = ik
                .solve(&tcp, None)
                .into_iter()
                .find(|s| s.within_limits)
                .map(|s| s.q.to_vec());
            if let Some(q) = found {
                let deg = self.track.degrees(&q);
                self.flags.push((deg, ik.configuration(&q).unwrap()));
                self.targets.push((e, v, t));
            }
        }
    }

    /// The part's frame as the controller computes it in its base at track
    /// value `e` and positioner values `v`: `N(e)⁻¹·P_nom(v)·W_f`.
    fn controller_frame(&self, e: f64, v: [f64; 2]) -> Pose {
        self.track
            .nominal_track
            .cell_from_base(e)
            .unwrap()
            .inverse()
            .compose(&self.nominal_positioner.cell_from_face_plate(v))
            .compose(&self.cell.work_objects[0].pose)
    }

    fn axes(&self) -> FilterAxes<'_> {
        FilterAxes {
            track: Some(TrackAxes {
                nominal: &self.track.nominal_track,
                calibrated: &self.track.fitted,
            }),
            positioner: Some(PositionerAxes {
                nominal: &self.nominal_positioner,
                calibrated: &self.fitted,
                turntable: false,
            }),
            correct_values: false,
        }
    }

    /// Runs a program through the nominal controller composing its track
    /// and its positioner (closed form on the targets' flags, nearest the
    /// previous joints): per target, how far the true torch is from the
    /// target on the true, moved part (`None` where the controller has no
    /// solution on the target's flags).
    fn run(&self, language: Language, files: &[ProgramFile]) -> Vec<Option<Miss>> {
        let values: Vec<(f64, [f64; 2])> = self.targets.iter().map(|(e, v, _)| (*e, *v)).collect();
        self.run_at(language, files, &values)
    }

    /// [`Self::run`] of a program whose targets carry the axis values
    /// `values` (programmed, or written by a filter correcting them): the
    /// controller composes them, the true track and positioner stand at them.
    fn run_at(
        &self,
        language: Language,
        files: &[ProgramFile],
        values: &[(f64, [f64; 2])],
    ) -> Vec<Option<Miss>> {
        let program = parse(language, files).unwrap();
        let ik = AnalyticIk::new(&self.track.controller).unwrap();
        assert_eq!(program.sites.len(), self.targets.len());
        let (group, numbers) = (
            positioner_group(language),
            self.axes().positioner_numbers(language),
        );
        let mut previous: Option<Vec<f64>> = None;
        let mut errors = Vec::new();
        for ((site, (_, _, target)), (e, v)) in program.sites.iter().zip(&self.targets).zip(values)
        {
            let value = |g: u32, n: usize| {
                site.axes
                    .iter()
                    .find(|a| a.group == g && a.number == n)
                    .and_then(|a| a.value)
                    .unwrap()
            };
            let (programmed_e, programmed) = (
                value(1, 1),
                [value(group, numbers[0]), value(group, numbers[1])],
            );
            assert_eq!(programmed_e, *e, "{}", site.name);
            assert!(
                (programmed[0] - v[0]).abs() < 1e-3 && (programmed[1] - v[1]).abs() < 1e-3,
                "{}: {programmed:?} {v:?}",
                site.name
            );
            let tcp = self
                .controller_frame(programmed_e, programmed)
                .compose(&site.pose.unwrap());
            let found =
                controller_solution(&ik, &self.track.controller, site, &tcp, previous.as_deref());
            let Some(q) = found else {
                errors.push(None);
                continue;
            };
            let want = true_part(&self.true_positioner, &self.body, programmed).compose(target);
            errors.push(Some(Miss::of(&self.track.true_tip(&q, *e), &want)));
            previous = Some(q);
        }
        errors
    }
}

/// The cell's targets as the programs write them: the track's value, then
/// the positioner's.
fn written(c: &BothCell) -> Vec<Written<'_>> {
    c.targets
        .iter()
        .zip(&c.flags)
        .map(|((e, [v1, v2], t), (deg, conf))| Written {
            pose: t,
            deg,
            conf: *conf,
            krl_axes: format!("E1 {e:.3},E2 {v1:.4},E3 {v2:.4},E4 0.0,E5 0.0,E6 0.0"),
            rapid_axes: format!("[{e:.3},{v1:.4},{v2:.4},9E+09,9E+09,9E+09]"),
            fanuc_axes: format!(
                ",\r\n\tE1 = {e:9.3}  mm\r\n   GP2:\r\n\tUF : 3, UT : 1,\r\n\tJ1 = {v1:9.4} deg,\tJ2 = {v2:9.4} deg"
            ),
        })
        .collect()
}

fn krl(c: &BothCell) -> Vec<ProgramFile> {
    krl_program(
        "weld",
        "$TOOL = TOOL_DATA[1]\r\nBAS(#BASE, 3)\r\n",
        &written(c),
    )
}

/// RAPID with the part a work object the positioner `STN1` moves.
fn rapid(c: &BothCell) -> Vec<ProgramFile> {
    rapid_on_plate("Weld", &c.cell.work_objects[0].pose, &written(c))
}

fn fanuc(c: &BothCell) -> Vec<ProgramFile> {
    fanuc_program("WELD", 3, &written(c))
}

fn filter_in_cell(c: &BothCell, language: Language, files: &[ProgramFile]) -> FilterOutput {
    filter_with(
        language,
        files,
        &c.cell,
        &c.track.model,
        &settings(),
        &c.axes(),
        &FilterControl::default(),
    )
    .unwrap()
}

/// The acceptance for one language: all 50 targets filtered at their own
/// values, which are kept; through the controller, the true torch within
/// 1.5× the calibration's validation error of the target on the true,
/// moved part; the unfiltered program millimetres off.
fn assert_in_cell(language: Language, files: &[ProgramFile]) {
    let c = both_cell();
    let out = filter_in_cell(c, language, files);
    let r = &out.report;
    assert_every_target_filtered(r, 50);
    assert_eq!(r.track_axis.as_deref(), Some(track_axis_name(language)));
    assert_positioner_values_kept(
        r,
        &positioner_axis_names(language, true),
        c.targets.iter().map(|(_, v, _)| *v),
    );
    for (t, (e, _, _)) in r.targets.iter().zip(&c.targets) {
        assert_eq!(t.track_mm, Some(*e));
    }
    assert_only_targets_changed(language, files, &out.files);
    assert_figures(
        &format!("{language:?} on the track beside the positioner"),
        "the calibration's validation rms (the robot's and the positioner's)",
        c.validation,
        c.run(language, &out.files),
        c.run(language, files),
    );
}

#[test]
fn krl_on_a_track_reaches_the_part_on_the_positioner() {
    assert_in_cell(Language::Krl, &krl(both_cell()));
}

#[test]
fn rapid_on_a_track_reaches_the_part_on_the_positioner() {
    assert_in_cell(Language::Rapid, &rapid(both_cell()));
}

#[test]
fn fanuc_on_a_track_reaches_the_part_on_the_positioner() {
    assert_in_cell(Language::Fanuc, &fanuc(both_cell()));
}

/// The same 50 targets as a targets file, not a program: each row the
/// target on the taught part in the face plate frame (`W_f·t`, mm and a
/// rotation matrix) with its track value `e1` and positioner values `e2`,
/// `e3`, placed through the fitted track and positioner
/// (`place_on_track_and_positioner`: `B(e)⁻¹·F(v)·T`) and solved as a path
/// by the calibrated robot carrying the torch. The commanded joints, run on
/// the true robot on the true track at each row's value, put the true torch
/// on the target on the true, moved part within 1.5× the calibration's
/// validation error; the nominal controller's own composition of the same
/// targets (the program as written) misses by millimetres.
#[test]
fn targets_on_the_part_solve_at_their_track_and_positioner_values() {
    use robocal_core::solve::cell::CellSolver;
    use robocal_core::solve::external::{
        place_on_track_and_positioner, positioner_columns, target_column_values, TRACK_COLUMN,
    };
    use robocal_core::solve::ik::targets_csv::parse_targets_csv_beside;
    use robocal_core::solve::ik::{SolveOptions, TargetFrame};
    let c = both_cell();
    let on_plate = &c.cell.work_objects[0].pose;
    let mut text = String::from("id,x,y,z,r11,r12,r13,r21,r22,r23,r31,r32,r33,e1,e2,e3\n");
    for (k, (e, v, t)) in c.targets.iter().enumerate() {
        let p = on_plate.compose(t);
        let xyz = p.p * 1e3;
        let r: Vec<String> = (0..3)
            .flat_map(|i| (0..3).map(move |j| (i, j)))
            .map(|(i, j)| format!("{:.12}", p.r[(i, j)]))
            .collect();
        text += &format!(
            "t{k},{:.6},{:.6},{:.6},{},{e},{},{}\n",
            xyz.x,
            xyz.y,
            xyz.z,
            r.join(","),
            v[0],
            v[1]
        );
    }
    let d = Default::default();
    let read = |column: &str| target_column_values(&text, d, column).unwrap().unwrap();
    let [tilt, rotate] = positioner_columns(true);
    let mut csv = parse_targets_csv_beside(&text, d, &[TRACK_COLUMN, tilt, rotate]).unwrap();
    place_on_track_and_positioner(
        &mut csv,
        &read(TRACK_COLUMN),
        &c.track.fitted,
        &read(tilt),
        &read(rotate),
        &c.fitted,
    );
    let cell_solver = CellSolver::for_tool(&c.track.model, Some(&torch_tool()), settings());
    let solver = cell_solver.solver();
    let options = SolveOptions {
        frame: TargetFrame::Base,
        false_target_convention: csv.convention,
        ..SolveOptions::default()
    };
    let results = csv.solve(solver, &options, true);
    let solved: Vec<Option<Miss>> = results
        .iter()
        .zip(&c.targets)
        .map(|(r, (e, v, t))| {
            assert!(r.solution.converged, "{}: {:?}", r.id, r.solution.reason);
            let want = true_part(&c.true_positioner, &c.body, *v).compose(t);
            Some(Miss::of(&c.track.true_tip(&r.solution.q, *e), &want))
        })
        .collect();
    assert_figures(
        "targets solved on the track beside the positioner",
        "the calibration's validation rms (the robot's and the positioner's)",
        c.validation,
        solved,
        c.run(Language::Krl, &krl(c)),
    );
}

/// The acceptance of the corrected axis values in one language: every
/// target filtered, the report saying the values were corrected and giving
/// each written value beside the programmed one; the real axes at the
/// written values move nearer as the controller believes the programmed
/// ones move them (the true base's move from mid-travel at `e'` against
/// the drawing's at `e`; the true part's orientation at `v'` against the
/// drawing's part at `v`) than at the programmed values; and through the
/// controller at
/// the written values, the true torch within 1.5× the calibration's
/// validation error of the target on the true part.
fn assert_corrected_in_cell(language: Language, files: &[ProgramFile]) {
    use robocal_core::model::orientation::rotation_angle_between;
    use robocal_core::program::AxisValuesWritten;
    let c = both_cell();
    let axes = c.axes().correcting_values(true);
    let out = filter_with(
        language,
        files,
        &c.cell,
        &c.track.model,
        &settings(),
        &axes,
        &FilterControl::default(),
    )
    .unwrap();
    let r = &out.report;
    assert_every_target_filtered(r, 50);
    assert_eq!(r.axis_values, Some(AxisValuesWritten::Corrected));
    let on_plate = &c.cell.work_objects[0].pose;
    let (mut base, mut part) = ([Vec::new(), Vec::new()], [Vec::new(), Vec::new()]);
    let mut sideways = [Vec::new(), Vec::new()];
    let mut written = Vec::new();
    for (t, (e, v, _)) in r.targets.iter().zip(&c.targets) {
        // The programmed values, as the program writes them (4 decimals of
        // a degree).
        assert_eq!(t.track_mm, Some(*e));
        let programmed = t.positioner_deg.unwrap();
        assert!((0..2).all(|k| (programmed[k] - v[k]).abs() < 1e-4));
        let (e2, v2) = (
            t.track_written_mm.unwrap(),
            t.positioner_written_deg.unwrap(),
        );
        // The base's move from the middle of the travel, as the controller
        // believes it and as the true track makes it.
        let mid = (c.track.fitted.travel.lo_mm + c.track.fitted.travel.hi_mm) / 2.0;
        let nominal = |x: f64| c.track.nominal_track.cell_from_base(x).unwrap().p;
        let believed = nominal(*e) - nominal(mid);
        let along = (nominal(mid + 1000.0) - nominal(mid)).normalize();
        let intended = c
            .nominal_positioner
            .cell_from_face_plate(programmed)
            .compose(on_plate);
        for (k, (at_e, at_v)) in [(*e, programmed), (e2, v2)].into_iter().enumerate() {
            let real = |x: f64| c.track.true_track.cell_from_base(x).p;
            let off = real(at_e) - real(mid) - believed;
            base[k].push(off.dot(&along) * 1e3);
            sideways[k].push((off - along * off.dot(&along)).norm() * 1e3);
            let turned = true_part(&c.true_positioner, &c.body, at_v).r;
            part[k].push(rotation_angle_between(&turned, &intended.r).to_degrees());
        }
        written.push((e2, v2));
    }
    println!(
        "{language:?} corrected: the true base's move from mid-travel off the controller's, along the rail rms {:.4} mm as programmed, {:.4} mm at the written values (sideways {:.4} and {:.4} mm, no value holds it); the true part's orientation off the controller's, rms {:.4}° as programmed, {:.4}° written",
        rms(&base[0]),
        rms(&base[1]),
        rms(&sideways[0]),
        rms(&sideways[1]),
        rms(&part[0]),
        rms(&part[1])
    );
    assert!(rms(&base[1]) < 0.5 * rms(&base[0]), "{base:?}");
    assert!(rms(&part[1]) < 0.5 * rms(&part[0]), "{part:?}");
    assert_figures(
        &format!("{language:?} on the track beside the positioner, axis values corrected"),
        "the calibration's validation rms (the robot's and the positioner's)",
        c.validation,
        c.run_at(language, &out.files, &written),
        c.run(language, files),
    );
}

#[test]
fn corrected_axis_values_put_the_real_axes_where_the_controller_believes_them() {
    let c = both_cell();
    assert_corrected_in_cell(Language::Krl, &krl(c));
    assert_corrected_in_cell(Language::Rapid, &rapid(c));
    assert_corrected_in_cell(Language::Fanuc, &fanuc(c));
}
