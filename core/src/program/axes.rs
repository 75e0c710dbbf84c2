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
//! Turntable: a one-axis turntable is the positioner whose axis 1 stands
//! still at 0 (`Turntable::as_tilt_rotate`, [`FilterAxes::turntable`]): the
//! program gives one value, its first positioner axis (KRL `E1`, RAPID
//! `eax_a`, Fanuc `J1` of `GP2`; `E2`, `eax_b` beside a track), composed at
//! `[0, v]`; a second positioner axis in use is refused, as any axis the
//! cell does not model. Its value is corrected as a positioner's are, axis 2
//! alone (`corrected_values::turntable_value`).
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
    /// A one-axis turntable (both models its `as_tilt_rotate`): the program
    /// gives axis 2's value alone, axis 1 stands at 0 (module docs).
    pub turntable: bool,
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
                turntable: false,
            }),
            correct_values: false,
        }
    }

    /// The same axes, the positioner a one-axis turntable (its models
    /// `Turntable::as_tilt_rotate`'s): one program value, axis 2's.
    pub fn turntable(self) -> Self {
        FilterAxes {
            positioner: self.positioner.map(|p| PositionerAxes {
                turntable: true,
                ..p
            }),
            ..self
        }
    }

    /// The program's numbers of the positioner's axes in use: both of
    /// [`Self::positioner_numbers`], or a turntable's first alone.
    pub fn plate_numbers(&self, language: Language) -> Vec<usize> {
        let n = self.positioner_numbers(language);
        match self.positioner {
            Some(p) if p.turntable => vec![n[0]],
            _ => n.to_vec(),
        }
    }

    /// The names of the positioner's axes in use in `language` (a
    /// turntable's one), as the report gives them.
    pub fn plate_axis_names(&self, language: Language) -> Vec<&'static str> {
        let names = positioner_axis_names(language, self.track.is_some());
        match self.positioner {
            Some(p) if p.turntable => vec![names[0]],
            _ => names.to_vec(),
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
        && axes.plate_numbers(language).contains(&a.number);
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
            if p.turntable {
                on_turntable(language, site, p, axes.track.is_some(), correct)?
            } else {
                on_positioner(language, site, p, axes.track.is_some(), correct)?
            }
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

/// The turntable's plates at a site's value (its axis after the track's
/// when `on_track`; corrected when given the controller's world,
/// `correct`): `None` when the site gives none; refused when it is not a
/// number.
fn on_turntable(
    language: Language,
    site: &Site,
    p: &PositionerAxes,
    on_track: bool,
    correct: Option<&Pose>,
) -> Result<Option<OnPositioner>, String> {
    let group = positioner_group(language);
    let number = positioner_numbers(language, on_track)[0];
    let Some(a) = site
        .axes
        .iter()
        .find(|a| a.group == group && a.number == number)
    else {
        return Ok(None);
    };
    let v = a.value.ok_or_else(|| {
        format!(
            "the turntable's axis {} is {}: not filtered",
            a.name,
            if a.text.is_empty() {
                "not a number"
            } else {
                &a.text
            }
        )
    })?;
    let values_deg = [0.0, v];
    let written_deg = match correct {
        None => values_deg,
        Some(world_from_cell) => {
            let w = corrected_values::turntable_value(p.calibrated, p.nominal, world_from_cell, v)
                .ok_or_else(|| {
                    format!(
                        "the turntable's axis {}: no correction of {v}°: not filtered",
                        a.name
                    )
                })?;
            [0.0, w]
        }
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
        let numbers = axes.plate_numbers(language);
        // A turntable writes axis 2's value alone.
        let values = &p.written_deg[2 - numbers.len()..];
        for (number, value) in numbers.into_iter().zip(values) {
            wanted.push((positioner_group(language), number, *value, 4));
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
#[path = "axes_tests.rs"]
mod tests;
