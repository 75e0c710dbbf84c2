//! External axes in the filter, composed both as the controller composes
//! them (its nominal models) and as the cell really is (the calibrated
//! ones): the robot's linear track, controller axis 1 (KRL `E1`, RAPID
//! `eax_a`, Fanuc `E1` of `GP1`, `model::external::track`), or a two-axis
//! positioner carrying the work object (KRL `E1`, `E2`, RAPID `eax_a`,
//! `eax_b`, Fanuc `J1`, `J2` of `GP2`, `model::external::positioner`).
//!
//! One rule for both: the robot's own solve runs on the base-frame work
//! object `S` as the cell really is, giving the calibrated joints `q` and,
//! in `S`, the false target `F` with `S·F = FK_nominal(q)·tool` (DESIGN.md,
//! false targets); the controller computes the work object as `S_nom` and,
//! given `T'`, solves `S_nom·T'` on its nominal model, which must be
//! `FK_nominal(q)·tool`: `T' = S_nom⁻¹·S·F` ([`controller_target`]).
//!
//! Track: the controller's world frame is the cell frame both tracks are
//! stated in (the frame the track was measured in, where the controller's
//! nominal rail is placed); the program's work objects are world frames
//! (`$BASE` on `$WORLD`, a `wobjdata`'s user frame, a user frame `UF`). At a
//! target's track value `e` [mm] the controller puts the robot base at
//! `N(e)` (the nominal track), the robot really stands at `B(e)` (the
//! calibrated track): for a work object `W`, `S = B(e)⁻¹·W`,
//! `S_nom = N(e)⁻¹·W`.
//!
//! Positioner: a work object `W_f` stated on the face plate (KRL `BASE_DATA`
//! of a base coupled to the positioner, RAPID's object frame of a `wobjdata`
//! with `ufprog FALSE`, Fanuc's user frame of coordinated motion). At the
//! target's values `v` [deg] the calibrated positioner puts the plate at
//! `P(v)` in the cell frame the robot is registered in (`base_from_cell`
//! the robot's registration), the controller's nominal positioner at
//! `P_nom(v)` in its world frame, which on a fixed base is the robot's base
//! frame: `S = base_from_cell·P(v)·W_f`, `S_nom = P_nom(v)·W_f`.
//!
//! Track and positioner together: the robot rides the track (axis 1) and
//! the part turns on the positioner, its axes then the program's axes 2 and
//! 3 of the robot's group (KRL `E2`, `E3`; RAPID `eax_b`, `eax_c`; Fanuc's
//! group 2 `J1`, `J2` as before). Both models are stated in the cell frame,
//! the controller's world: `S = B(e)⁻¹·P(v)·W_f`,
//! `S_nom = N(e)⁻¹·P_nom(v)·W_f`.
//!
//! The axes' values stay as programmed (the filter moves the target, not
//! the axes) unless the filter is asked to correct them
//! ([`FilterAxes::correct_values`], `corrected_values`): then each value is
//! rewritten to the one at which the real axis stands where the controller
//! believes the programmed one puts it, and the target is composed, as
//! above, at the written values `e'`, `v'`. Any other external axis in use
//! is refused, naming it, as is a track value beyond either track's
//! travel. Units: the programs' mm for
//! track values and degrees for the positioner's, SI poses.

use super::{corrected_values, external_axis_refusal, AxisValue, Language, Site};
use crate::model::external::{LinearTrack, TiltRotate};
use crate::model::Pose;
use std::ops::Range;

/// The robot's linear track in a filter: what the controller computes and
/// what the cell is.
#[derive(Debug, Clone, Copy)]
pub struct TrackAxes<'a> {
    /// The controller's own track (nominal rail, scale 1, no maps), in the
    /// cell frame: where it believes the robot base is.
    pub nominal: &'a LinearTrack,
    /// The calibrated track, in the same frame: where the base really is.
    pub calibrated: &'a LinearTrack,
}

/// The positioner carrying work objects in a filter: what the controller
/// computes and what the cell is.
#[derive(Debug, Clone, Copy)]
pub struct PositionerAxes<'a> {
    /// The controller's own positioner (its drawing's or its own
    /// calibration's axis lines), in the controller's world frame: the
    /// robot's base frame on a fixed base, the cell frame beside a track.
    pub nominal: &'a TiltRotate,
    /// The calibrated positioner, in the cell (tracker) frame the robot's
    /// calibrated model is registered in.
    pub calibrated: &'a TiltRotate,
}

/// The external axes a filter composes through (none by default: every
/// external axis in use is refused).
#[derive(Debug, Clone, Copy, Default)]
pub struct FilterAxes<'a> {
    /// The track carrying the robot, controller axis 1.
    pub track: Option<TrackAxes<'a>>,
    /// The positioner carrying work objects on its face plate, axes 1 and 2
    /// (Fanuc: `J1`, `J2` of motion group 2).
    pub positioner: Option<PositionerAxes<'a>>,
    /// Rewrite the axes' values so the real axes stand where the
    /// controller believes the programmed values put them (the track's
    /// scale, zero and error along the rail; the positioner's zeros and
    /// scales); `false` (the default) keeps them as programmed.
    pub correct_values: bool,
}

impl<'a> FilterAxes<'a> {
    /// The axes of a cell with a track, a positioner, both or neither, each
    /// given as (calibrated, nominal).
    pub fn of_cell(
        track: Option<&'a (LinearTrack, LinearTrack)>,
        positioner: Option<&'a (TiltRotate, TiltRotate)>,
    ) -> Self {
        FilterAxes {
            track: track.map(|(calibrated, nominal)| TrackAxes {
                nominal,
                calibrated,
            }),
            positioner: positioner.map(|(calibrated, nominal)| PositionerAxes {
                nominal,
                calibrated,
            }),
            correct_values: false,
        }
    }

    /// The same axes, their values corrected (`correct`) or kept.
    pub fn correcting_values(self, correct: bool) -> Self {
        FilterAxes {
            correct_values: correct,
            ..self
        }
    }

    /// The program's numbers of the positioner's axes 1 and 2 in
    /// `language`, within its group ([`positioner_group`]): 1 and 2, or 2
    /// and 3 after the track's axis 1 when the robot also rides a track
    /// (Fanuc's group 2 is the positioner's alone: 1 and 2).
    pub fn positioner_numbers(&self, language: Language) -> [usize; 2] {
        positioner_numbers(language, self.track.is_some())
    }
}

fn positioner_numbers(language: Language, on_track: bool) -> [usize; 2] {
    if on_track && positioner_group(language) == 1 {
        [2, 3]
    } else {
        [1, 2]
    }
}

/// The controller's number of the track's axis.
pub const TRACK_AXIS: usize = 1;

/// The name a language gives the track's axis.
pub fn track_axis_name(language: Language) -> &'static str {
    match language {
        Language::Rapid => "eax_a",
        Language::Krl | Language::Fanuc | Language::UrScript => "E1",
    }
}

/// The motion group of the positioner's axes in a language: Fanuc moves a
/// positioner as group 2, KRL and RAPID as the robot's external axes.
pub fn positioner_group(language: Language) -> u32 {
    match language {
        Language::Fanuc => 2,
        Language::Krl | Language::Rapid | Language::UrScript => 1,
    }
}

/// The names a language gives the positioner's axes 1 (tilt) and 2
/// (rotate), with the robot on a track (`on_track`, the positioner's axes
/// after the track's: [`FilterAxes::positioner_numbers`]) or not.
pub fn positioner_axis_names(language: Language, on_track: bool) -> [&'static str; 2] {
    let robot_group = |n: usize| match language {
        Language::Rapid => ["eax_a", "eax_b", "eax_c"][n - 1],
        _ => ["E1", "E2", "E3"][n - 1],
    };
    match language {
        Language::Fanuc => ["J1 of motion group GP2", "J2 of motion group GP2"],
        _ => positioner_numbers(language, on_track).map(robot_group),
    }
}

/// The controller's false target `T' = S_nom⁻¹·S·F` of the false target `F`
/// solved in the base-frame work object `S` as the cell is, the controller
/// computing that work object as `S_nom` (module docs).
pub(super) fn controller_target(s_nom: &Pose, s: &Pose, false_in_s: &Pose) -> Pose {
    s_nom.inverse().compose(s).compose(false_in_s)
}

/// A target's robot base, as the controller holds it and as it is, at the
/// target's track value.
#[derive(Debug, Clone, Copy)]
pub(super) struct OnTrack {
    /// The track value as programmed [mm].
    pub(super) value_mm: f64,
    /// The value written to the program [mm]: the programmed one, or its
    /// correction.
    pub(super) written_mm: f64,
    /// `N(e')`: the base in the cell frame by the controller's nominal
    /// track at the written value.
    pub(super) nominal: Pose,
    /// `B(e')`: the base in the cell frame by the calibrated track.
    pub(super) calibrated: Pose,
}

impl OnTrack {
    /// `S = B(e)⁻¹·W` and `S_nom = N(e)⁻¹·W` of a world-frame work object
    /// `W` (module docs).
    pub(super) fn work_object(&self, world: &Pose) -> (Pose, Pose) {
        self.moved_work_object(world, world)
    }

    /// `S = B(e)⁻¹·W` and `S_nom = N(e)⁻¹·W_nom` of a work object that is
    /// `W` in the world as the cell is and `W_nom` as the controller
    /// computes it (on a positioner's plate: `P(v)·W_f`, `P_nom(v)·W_f`).
    pub(super) fn moved_work_object(&self, world: &Pose, world_nom: &Pose) -> (Pose, Pose) {
        (
            self.calibrated.inverse().compose(world),
            self.nominal.inverse().compose(world_nom),
        )
    }
}

/// A target's positioner face plate, as the controller holds it and as it
/// is, at the target's values.
#[derive(Debug, Clone, Copy)]
pub(super) struct OnPositioner {
    /// The values as programmed, axis 1 and axis 2 [deg].
    pub(super) values_deg: [f64; 2],
    /// The values written to the program [deg]: the programmed ones, or
    /// their correction (the plates below are at these).
    pub(super) written_deg: [f64; 2],
    /// `P_nom(v)`: the plate in the controller's world (the robot's base
    /// frame) by its nominal positioner.
    pub(super) nominal: Pose,
    /// `P(v)`: the plate in the cell frame by the calibrated positioner.
    pub(super) calibrated: Pose,
}

impl OnPositioner {
    /// `S = base_from_cell·P(v)·W_f` and `S_nom = P_nom(v)·W_f` of a work
    /// object `W_f` on the face plate, `base_from_cell` the robot's
    /// registration (module docs).
    pub(super) fn work_object(&self, base_from_cell: &Pose, on_plate: &Pose) -> (Pose, Pose) {
        let (world, world_nom) = self.in_world(on_plate);
        (base_from_cell.compose(&world), world_nom)
    }

    /// `P(v)·W_f` in the cell frame and `P_nom(v)·W_f` in the controller's
    /// world of a work object `W_f` on the face plate.
    pub(super) fn in_world(&self, on_plate: &Pose) -> (Pose, Pose) {
        (
            self.calibrated.compose(on_plate),
            self.nominal.compose(on_plate),
        )
    }
}

/// Where a site's axes put the robot base and the positioner's face plate.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Placement {
    /// The track's two bases at the target's value, on a track.
    pub(super) track: Option<OnTrack>,
    /// The positioner's two face plates, when the target gives its values
    /// (required of a target in a work object on the plate).
    pub(super) positioner: Option<OnPositioner>,
    /// Whether the filter was given a positioner at all.
    pub(super) with_positioner: bool,
}

/// Whether `a` is one of the axes the cell's `axes` compose in `language`.
fn composed(language: Language, axes: &FilterAxes, a: &AxisValue) -> bool {
    let track = axes.track.is_some() && a.group == 1 && a.number == TRACK_AXIS;
    let positioner = axes.positioner.is_some()
        && a.group == positioner_group(language)
        && axes.positioner_numbers(language).contains(&a.number);
    track || positioner
}

/// Where a site's axes put the robot base and the positioner's plate
/// ([`Placement`], empty on a fixed base without axes in use), or why the
/// site is refused (an axis the cell does not model, no track value, a value
/// beyond the travel, one positioner value without the other, a
/// correction beyond the travel). `base_from_cell` is the robot's
/// registration, the controller's world on a fixed base.
pub(super) fn place(
    language: Language,
    site: &Site,
    axes: &FilterAxes,
    base_from_cell: &Pose,
) -> Result<Placement, String> {
    if let Some(other) = site
        .axes
        .iter()
        .find(|a| !composed(language, axes, a) && a.in_use(language))
    {
        return Err(external_axis_refusal(&other.name, &other.text));
    }
    let track = match &axes.track {
        Some(t) => Some(on_track(language, site, t, axes.correct_values)?),
        None => None,
    };
    let positioner = match &axes.positioner {
        Some(p) => {
            // The controller's world: the cell beside a track, else the base.
            let world_from_cell = match axes.track {
                Some(_) => Pose::identity(),
                None => *base_from_cell,
            };
            let correct = axes.correct_values.then_some(&world_from_cell);
            on_positioner(language, site, p, axes.track.is_some(), correct)?
        }
        None => None,
    };
    Ok(Placement {
        track,
        positioner,
        with_positioner: axes.positioner.is_some(),
    })
}

/// The track's bases at a site's value (`correct`: at its correction), or
/// why it has none.
fn on_track(
    language: Language,
    site: &Site,
    track: &TrackAxes,
    correct: bool,
) -> Result<OnTrack, String> {
    let name = track_axis_name(language);
    let given = site.axes.iter().find(|a| a.number == TRACK_AXIS);
    let value_mm = match given {
        None => {
            return Err(format!(
                "the robot rides a track, axis {name}, and the target gives no value for it: not filtered"
            ))
        }
        Some(a) => a.value.ok_or_else(|| {
            format!(
                "the track's axis {} is {}: not filtered",
                a.name,
                if a.text.is_empty() { "not a number" } else { &a.text }
            )
        })?,
    };
    let nominal_at = |e: f64| {
        track.nominal.cell_from_base(e).map_err(|e| {
            format!(
                "the track's axis {name}: value {} mm is beyond the controller's nominal travel, [{}, {}] mm: not filtered",
                e.value_mm, e.lo_mm, e.hi_mm
            )
        })
    };
    // The programmed value within the controller's own travel.
    nominal_at(value_mm)?;
    let written_mm = if correct {
        corrected_values::track_value(track.calibrated, track.nominal, value_mm).map_err(|e| {
            format!(
                "the track's axis {name}: the value correcting {value_mm} mm, {e}: not filtered"
            )
        })?
    } else {
        value_mm
    };
    let calibrated = track
        .calibrated
        .cell_from_base(written_mm)
        .map_err(|e| format!("the track's axis {name}: {e}: not filtered"))?;
    Ok(OnTrack {
        value_mm,
        written_mm,
        nominal: nominal_at(written_mm)?,
        calibrated,
    })
}

/// The positioner's plates at a site's values (its axes after the track's
/// when `on_track`; corrected when given the controller's world,
/// `correct`): `None` when the site gives neither value; refused when it
/// gives one without the other or one that is not a number.
fn on_positioner(
    language: Language,
    site: &Site,
    p: &PositionerAxes,
    on_track: bool,
    correct: Option<&Pose>,
) -> Result<Option<OnPositioner>, String> {
    let group = positioner_group(language);
    let names = positioner_axis_names(language, on_track);
    let numbers = positioner_numbers(language, on_track);
    let given = |k: usize| site.axes.iter().find(|a| a.group == group && a.number == k);
    let values = match (given(numbers[0]), given(numbers[1])) {
        (None, None) => return Ok(None),
        (Some(a), Some(b)) => [a, b].map(|a| a.value.ok_or_else(|| a.clone())),
        (a, _) => {
            let missing = if a.is_none() { names[0] } else { names[1] };
            return Err(format!(
                "the target moves the positioner and gives no value for its axis {missing}: not filtered"
            ));
        }
    };
    let [v1, v2] = values;
    let value = |v: Result<f64, AxisValue>| {
        v.map_err(|a| {
            format!(
                "the positioner's axis {} is {}: not filtered",
                a.name,
                if a.text.is_empty() {
                    "not a number"
                } else {
                    &a.text
                }
            )
        })
    };
    let values_deg = [value(v1)?, value(v2)?];
    let written_deg = match correct {
        None => values_deg,
        Some(world_from_cell) => corrected_values::positioner_values(
            p.calibrated,
            p.nominal,
            world_from_cell,
            values_deg,
        )
        .ok_or_else(|| {
            format!(
                "the positioner's axes {} and {}: no correction of {values_deg:?} (the axes do not turn the plate independently there): not filtered",
                names[0], names[1]
            )
        })?,
    };
    Ok(Some(OnPositioner {
        values_deg,
        written_deg,
        nominal: p.nominal.cell_from_face_plate(written_deg),
        calibrated: p.calibrated.cell_from_face_plate(written_deg),
    }))
}

/// The edits writing a site's corrected values (`at`'s written values) over
/// the programmed ones, or why they cannot be written (a value the parser
/// cannot point at); none when `axes` keeps the values. Lengths with at
/// least 3 decimals, angles with at least 4, or as many as the program
/// wrote.
pub(super) fn written_edits(
    language: Language,
    site: &Site,
    axes: &FilterAxes,
    at: &Placement,
) -> Result<Vec<(Range<usize>, String)>, String> {
    if !axes.correct_values {
        return Ok(Vec::new());
    }
    let mut wanted: Vec<(u32, usize, f64, usize)> = Vec::new();
    if let Some(t) = &at.track {
        wanted.push((1, TRACK_AXIS, t.written_mm, 3));
    }
    if let Some(p) = &at.positioner {
        let numbers = axes.positioner_numbers(language);
        for (number, value) in numbers.into_iter().zip(p.written_deg) {
            wanted.push((positioner_group(language), number, value, 4));
        }
    }
    wanted
        .into_iter()
        .map(|(group, number, value, least)| {
            let a = site
                .axes
                .iter()
                .find(|a| a.group == group && a.number == number)
                .ok_or_else(|| format!("no value of axis {number} to correct: not filtered"))?;
            let slot = a.slot.clone().ok_or_else(|| {
                format!("the value of axis {} cannot be rewritten where the program gives it: not filtered", a.name)
            })?;
            let written = a.text.split_whitespace().next().unwrap_or("");
            let decimals = written.split_once('.').map_or(0, |(_, d)| d.len()).max(least);
            Ok((slot, format!("{:.*}", decimals, value + 0.0)))
        })
        .collect()
}

#[cfg(test)]
mod tests {
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
}
