//! External axes in the filter: the robot's linear track, controller axis 1
//! (KRL `E1`, RAPID `eax_a`, Fanuc `E1` of `GP1`), composed both as the
//! controller composes it (its nominal track) and as the cell really is (the
//! calibrated track, `model::external::track`).
//!
//! Frames: the controller's world frame is the cell frame both tracks are
//! stated in (the frame the track was measured in, where the controller's
//! nominal rail is placed); the program's work objects are world frames
//! (`$BASE` on `$WORLD`, a `wobjdata`'s user frame, a user frame `UF`). At a
//! target's track value `e` [mm] the controller puts the robot base at
//! `N(e)` (the nominal track) and the robot really stands at `B(e)` (the
//! calibrated track). For a target `T` in work object `W` (cell frame):
//! - the robot's own solve runs on the base-frame work object `B(e)⁻¹·W`,
//!   giving the calibrated joints `q` and, in that frame, the false target
//!   `F` with `B(e)⁻¹·W·F = FK_nominal(q)·tool` (DESIGN.md, false targets);
//! - the controller, given `T'` at `e`, solves `N(e)⁻¹·W·T'` on its nominal
//!   model, which must be `FK_nominal(q)·tool`: `T' = W⁻¹·N(e)·B(e)⁻¹·W·F`.
//!
//! The track's value stays as programmed (the filter moves the target, not
//! the carriage). Any other external axis in use is refused, naming it, as
//! is a track value beyond either track's travel. Units: the programs' mm
//! for track values, SI poses.

use super::{external_axis_refusal, Language, Site};
use crate::model::external::LinearTrack;
use crate::model::Pose;

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

/// The external axes a filter composes through (none by default: every
/// external axis in use is refused).
#[derive(Debug, Clone, Copy, Default)]
pub struct FilterAxes<'a> {
    /// The track carrying the robot, controller axis 1.
    pub track: Option<TrackAxes<'a>>,
}

impl<'a> FilterAxes<'a> {
    /// The axes of a robot on a track, when `track` (calibrated, nominal)
    /// is given; none otherwise.
    pub fn of_track(track: Option<&'a (LinearTrack, LinearTrack)>) -> Self {
        FilterAxes {
            track: track.map(|(calibrated, nominal)| TrackAxes {
                nominal,
                calibrated,
            }),
        }
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

/// A target's robot base, as the controller holds it and as it is, at the
/// target's track value.
#[derive(Debug, Clone, Copy)]
pub(super) struct OnTrack {
    /// The track value as programmed [mm].
    pub(super) value_mm: f64,
    /// `N(e)`: the base in the cell frame by the controller's nominal track.
    pub(super) nominal: Pose,
    /// `B(e)`: the base in the cell frame by the calibrated track.
    pub(super) calibrated: Pose,
}

impl OnTrack {
    /// The controller's false target `T' = W⁻¹·N(e)·B(e)⁻¹·W·F` of the false
    /// target `F` solved in the base-frame work object `B(e)⁻¹·W`.
    pub(super) fn controller_target(&self, work_object: &Pose, false_in_base: &Pose) -> Pose {
        work_object
            .inverse()
            .compose(&self.nominal)
            .compose(&self.calibrated.inverse())
            .compose(work_object)
            .compose(false_in_base)
    }
}

/// Where a site's robot base is: `None` on a fixed base (no axis in use,
/// no track), the track's two bases at its value, or why the site is
/// refused (an axis the cell does not model, no track value, a value beyond
/// the travel).
pub(super) fn place(
    language: Language,
    site: &Site,
    axes: &FilterAxes,
) -> Result<Option<OnTrack>, String> {
    let track_number = axes.track.map(|_| TRACK_AXIS);
    if let Some(other) = site
        .axes
        .iter()
        .find(|a| Some(a.number) != track_number && a.in_use(language))
    {
        return Err(external_axis_refusal(&other.name, &other.text));
    }
    let Some(track) = axes.track else {
        return Ok(None);
    };
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
    let nominal = track.nominal.cell_from_base(value_mm).map_err(|e| {
        format!(
            "the track's axis {name}: value {} mm is beyond the controller's nominal travel, [{}, {}] mm: not filtered",
            e.value_mm, e.lo_mm, e.hi_mm
        )
    })?;
    let calibrated = track
        .calibrated
        .cell_from_base(value_mm)
        .map_err(|e| format!("the track's axis {name}: {e}: not filtered"))?;
    Ok(Some(OnTrack {
        value_mm,
        nominal,
        calibrated,
    }))
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
        assert!(place(Language::Krl, &krl, &none).unwrap().is_none());
        // A Fanuc or RAPID axis at 0 is an axis the robot has.
        let why = place(Language::Fanuc, &krl, &none).unwrap_err();
        assert!(why.contains("external axis E1 to 0"), "{why}");
        let krl = site(vec![axis(1, "E1", Some(0.0)), axis(3, "E3", Some(5.0))]);
        let why = place(Language::Krl, &krl, &none).unwrap_err();
        assert!(
            why.contains("E3 to 5") && why.contains("does not model"),
            "{why}"
        );
    }

    #[test]
    fn on_a_track_the_value_places_both_bases_and_other_axes_are_refused() {
        let (nominal, calibrated) = (track(1.0), track(1.0002));
        let axes = FilterAxes {
            track: Some(TrackAxes {
                nominal: &nominal,
                calibrated: &calibrated,
            }),
        };
        let s = site(vec![axis(1, "E1", Some(2000.0)), axis(2, "E2", Some(0.0))]);
        let on = place(Language::Krl, &s, &axes).unwrap().unwrap();
        assert_eq!(on.value_mm, 2000.0);
        // Scale 1.0002: the calibrated base 0.4 mm further along the rail.
        assert!((on.calibrated.p.x - on.nominal.p.x - 0.0004).abs() < 1e-12);
        assert!((on.nominal.p - Vector3::new(2.0, 1.0, 0.0)).norm() < 1e-12);
        // A KRL value of 0 on the track is the track at 0.
        let s = site(vec![axis(1, "E1", Some(0.0))]);
        assert_eq!(
            place(Language::Krl, &s, &axes).unwrap().unwrap().value_mm,
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
            let why = place(Language::Krl, &s, &axes).unwrap_err();
            assert!(why.contains(want), "{why}");
        }
        // The calibrated travel can be shorter than the controller's.
        let mut short = track(1.0);
        short.travel.hi_mm = 3000.0;
        let axes = FilterAxes {
            track: Some(TrackAxes {
                nominal: &nominal,
                calibrated: &short,
            }),
        };
        let why = place(
            Language::Krl,
            &site(vec![axis(1, "E1", Some(3500.0))]),
            &axes,
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
            nominal: n,
            calibrated: b,
        };
        let t = on.controller_target(&w, &f);
        let controller = n.inverse().compose(&w).compose(&t);
        let truth = b.inverse().compose(&w).compose(&f);
        assert!((controller.p - truth.p).norm() < 1e-12);
        assert!((controller.r - truth.r).norm() < 1e-12);
    }
}
