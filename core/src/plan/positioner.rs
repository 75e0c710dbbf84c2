//! A measurement plan for a tilt-rotate positioner: the axis values at
//! which each reflector on the face plate is read, what the positioner fit
//! (`calibrate::external::fit`) reads, and the σ of every parameter those
//! readings predict.
//!
//! The fit starts from one circle per axis (a reflector read while one axis
//! turns and the other is held), so the plan is two sweeps: axis 2 (rotate)
//! over its travel with axis 1 held at the value of its travel nearest 0,
//! and axis 1 (tilt) over its travel with axis 2 held likewise, each at
//! evenly spaced values (the circle's fit and the scale's error, which grows
//! with the angle turned, want the whole span; the judgement's rules, at
//! least 4 values over at least 90° and every reflector 20 mm or more from
//! each axis, are checked here first). Every reflector is read at every
//! value: one tracker file per reflector.
//!
//! Predicted σ: `σ²·(JᵀJ)⁻¹` of the fit's own Jacobian
//! (`calibrate::external::problem::jacobian`) at the nominal positioner,
//! column-scaled as the fit's, reported as the fit reports its σ (per axis
//! the direction [deg], the line's position [mm], the zero offset [deg],
//! the scale; per reflector its position [mm]). Frames: reflectors in the
//! face plate frame [mm]; axis values in the controller's degrees.

use super::settings::PlanError;
use super::{evenly, PlanPoint};
use crate::calibrate::external::fit::{axis_sigma, reflector_sigmas, variances};
use crate::calibrate::external::judge::{MAX_CONDITION, MIN_ANGLES, MIN_RADIUS_MM, MIN_SPAN_DEG};
use crate::calibrate::external::outcome::{Axis, AxisSigma};
use crate::calibrate::external::problem::{jacobian, Gauge, Row, State};
use crate::calibrate::external::readings::PositionerColumns;
use crate::measure::external::{ExternalAxis, ExternalValues};
use crate::model::external::TiltRotate;
use crate::program::Language;
use nalgebra::Vector3;

/// How a positioner's plan is made.
#[derive(Debug, Clone, PartialEq)]
pub struct PositionerPlanSettings {
    /// The reflectors' design positions on the face plate [mm, face plate
    /// frame]; the first is the reference (its azimuth defines axis 2's zero).
    pub reflectors_mm: Vec<[f64; 3]>,
    /// Axis 1's (tilt) lowest and highest value swept [deg].
    pub tilt_deg: [f64; 2],
    /// Values of axis 1's sweep, evenly over `tilt_deg`.
    pub tilt_values: usize,
    /// Axis 2's (rotate) lowest and highest value swept [deg].
    pub rotate_deg: [f64; 2],
    /// Values of axis 2's sweep, evenly over `rotate_deg`.
    pub rotate_values: usize,
    /// The measurement files' columns of the two axes.
    pub columns: PositionerColumns,
    /// Tracker noise, standard deviation per coordinate [mm].
    pub noise_mm: f64,
}

impl Default for PositionerPlanSettings {
    /// The sweeps of the positioner's acceptance test: axis 1 at 13 values
    /// over −90…90°, axis 2 at 12 over −165…165°; columns `e1`, `e2`.
    fn default() -> Self {
        PositionerPlanSettings {
            reflectors_mm: Vec::new(),
            tilt_deg: [-90.0, 90.0],
            tilt_values: 13,
            rotate_deg: [-165.0, 165.0],
            rotate_values: 12,
            columns: PositionerColumns {
                tilt: ExternalAxis::E1,
                rotate: ExternalAxis::E2,
            },
            noise_mm: 0.01,
        }
    }
}

/// A positioner's plan.
#[derive(Debug, Clone, PartialEq)]
pub struct PositionerPlan {
    /// The values to read every reflector at: axis 2's sweep, then axis 1's
    /// (no robot joints; `external` holds both axes' values [deg]).
    pub points: Vec<PlanPoint>,
    /// The same values, `[tilt, rotate]` [deg].
    pub values_deg: Vec<[f64; 2]>,
    /// Axis 1's value held while axis 2 sweeps [deg].
    pub tilt_held_deg: f64,
    /// Axis 2's value held while axis 1 sweeps [deg].
    pub rotate_held_deg: f64,
    /// Predicted σ of each axis's parameters.
    pub sigma: [AxisSigma; 2],
    /// Predicted σ of each reflector's position [mm].
    pub reflector_sigma_mm: Vec<f64>,
    /// The column-scaled normal matrix's condition number.
    pub condition: f64,
    /// Tracker noise the prediction assumes [mm].
    pub noise_mm: f64,
}

/// Whether a program in `language` carries the plan's columns as the
/// filter reads them: Fanuc writes motion group 2's axes in column order
/// (`program::axes_only`), and the filter takes the tilt for `J1` and the
/// rotate for `J2`, so the tilt's column must come first.
pub fn program_columns(columns: &PositionerColumns, language: Language) -> Result<(), PlanError> {
    if language == Language::Fanuc && columns.tilt > columns.rotate {
        return Err(PlanError::Setting(format!(
            "a Fanuc program writes motion group 2's J1, J2 in column order, and the tilt is J1: give the tilt a column before the rotate's (tilt `{}`, rotate `{}`)",
            columns.tilt, columns.rotate
        )));
    }
    Ok(())
}

/// Refuses a face plate's plan without reflectors, with a reflector's
/// position that is not finite numbers of at most 100 000 mm, or a tracker
/// noise that is not a positive number of mm.
pub(super) fn check_reflectors_and_noise(
    reflectors_mm: &[[f64; 3]],
    noise_mm: f64,
) -> Result<(), PlanError> {
    if reflectors_mm.is_empty() {
        return Err(PlanError::Setting(
            "give the reflectors' design positions on the face plate (the first is the reference)"
                .into(),
        ));
    }
    if reflectors_mm
        .iter()
        .any(|r| r.iter().any(|v| !(v.is_finite() && v.abs() <= 100_000.0)))
    {
        return Err(PlanError::Setting(
            "a reflector's position: finite numbers of at most 100 000 mm".into(),
        ));
    }
    if !(noise_mm.is_finite() && noise_mm > 0.0) {
        return Err(PlanError::Setting(format!(
            "the tracker noise must be a positive number of mm, got {noise_mm}"
        )));
    }
    Ok(())
}

/// Refuses a sweep the fit would refuse: its range, span and count
/// (`calibrate::external::judge`).
pub(super) fn check_sweep(name: &str, range: [f64; 2], values: usize) -> Result<(), PlanError> {
    let [lo, hi] = range;
    if !(lo.is_finite() && hi.is_finite() && lo < hi && lo >= -360.0 && hi <= 360.0) {
        return Err(PlanError::Setting(format!(
            "{name}'s sweep: its lowest value must be below its highest, within ±360°, got {lo} .. {hi}"
        )));
    }
    if hi - lo < MIN_SPAN_DEG {
        return Err(PlanError::Setting(format!(
            "{name}'s sweep spans {}°; the fit needs at least {MIN_SPAN_DEG}° (a scale's error grows with the angle turned)",
            hi - lo
        )));
    }
    if values < MIN_ANGLES {
        return Err(PlanError::Setting(format!(
            "{name}'s sweep has {values} values; the fit needs at least {MIN_ANGLES} (3 fix a circle, a fourth shows whether it is one)"
        )));
    }
    Ok(())
}

/// Refuses a reflector nearer than the judgement's radius to either axis at
/// the sweeps' held values.
fn check_radii(
    nominal: &TiltRotate,
    s: &PositionerPlanSettings,
    held: [f64; 2],
) -> Result<(), PlanError> {
    for (k, r) in s.reflectors_mm.iter().enumerate() {
        // At the held values, in the base frame (a turn about an axis keeps
        // the distance from it).
        let p = nominal
            .base_from_face_plate(held)
            .transform_point(&(Vector3::from(*r) * 1e-3));
        for (axis, line) in [
            ("axis 2", nominal.rotate_line(held[0])),
            ("axis 1", nominal.tilt_line()),
        ] {
            let mm = line.distance_of(&p) * 1e3;
            if mm.is_nan() || mm < MIN_RADIUS_MM {
                return Err(PlanError::Setting(format!(
                    "reflector {} is {mm:.1} mm from {axis}; the fit needs at least {MIN_RADIUS_MM} mm (its circle fixes the axis's line)",
                    k + 1
                )));
            }
        }
    }
    Ok(())
}

/// Makes the plan for `nominal`.
pub fn make_positioner_plan(
    nominal: &TiltRotate,
    s: &PositionerPlanSettings,
) -> Result<PositionerPlan, PlanError> {
    check_reflectors_and_noise(&s.reflectors_mm, s.noise_mm)?;
    if s.columns.tilt == s.columns.rotate {
        return Err(PlanError::Setting(format!(
            "one column, {}, for both axes",
            s.columns.tilt
        )));
    }
    check_sweep("axis 1 (tilt)", s.tilt_deg, s.tilt_values)?;
    check_sweep("axis 2 (rotate)", s.rotate_deg, s.rotate_values)?;
    let held = [
        0.0f64.clamp(s.tilt_deg[0], s.tilt_deg[1]),
        0.0f64.clamp(s.rotate_deg[0], s.rotate_deg[1]),
    ];
    check_radii(nominal, s, held)?;
    let values_deg: Vec<[f64; 2]> = evenly(s.rotate_deg, s.rotate_values, 4)
        .into_iter()
        .map(|r| [held[0], r])
        .chain(
            evenly(s.tilt_deg, s.tilt_values, 4)
                .into_iter()
                .map(|t| [t, held[1]]),
        )
        .collect();
    let gauge = Gauge::new(nominal, Vector3::from(s.reflectors_mm[0]) * 1e-3);
    let state = State {
        tilt: nominal.tilt,
        rotate: nominal.rotate,
        gamma: nominal
            .tilt
            .direction
            .dot(&nominal.rotate.direction)
            .clamp(-1.0, 1.0)
            .asin(),
        reference: [0.0, 0.0],
        others: s.reflectors_mm[1..]
            .iter()
            .map(|r| Vector3::from(*r) * 1e-3)
            .collect(),
    };
    let rows: Vec<Row> = (0..s.reflectors_mm.len())
        .flat_map(|k| {
            values_deg.iter().map(move |v| Row {
                reflector: k,
                values: v.map(f64::to_radians),
                x: Vector3::zeros(),
            })
        })
        .collect();
    let (var, condition) = variances(
        &jacobian(&gauge, &state, &rows),
        (s.noise_mm * 1e-3).powi(2),
    );
    if condition.is_nan() || condition > MAX_CONDITION {
        return Err(PlanError::Unidentifiable(format!(
            "the sweeps leave the positioner's parameters undetermined (condition number {condition:.1e}, at most {MAX_CONDITION:.0e}); put the reflectors away from the axes"
        )));
    }
    let points = values_deg
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let mut external = ExternalValues::default();
            external.0[s.columns.tilt.index()] = Some(v[0]);
            external.0[s.columns.rotate.index()] = Some(v[1]);
            PlanPoint {
                name: format!("P{}", i + 1),
                q_deg: Vec::new(),
                external,
            }
        })
        .collect();
    Ok(PositionerPlan {
        points,
        values_deg,
        tilt_held_deg: held[0],
        rotate_held_deg: held[1],
        sigma: [
            axis_sigma(Axis::Tilt, &var, 0),
            axis_sigma(Axis::Rotate, &var, 6),
        ],
        reflector_sigma_mm: reflector_sigmas(&state, &var),
        condition,
        noise_mm: s.noise_mm,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::positioner_example::{nominal, sweeps, DESIGN_MM};

    /// The default plan is the acceptance test's sweeps.
    #[test]
    fn the_default_sweeps_are_the_acceptance_tests() {
        let plan = make_positioner_plan(
            &nominal(),
            &PositionerPlanSettings {
                reflectors_mm: DESIGN_MM.to_vec(),
                ..PositionerPlanSettings::default()
            },
        )
        .unwrap();
        assert_eq!(plan.values_deg, sweeps());
        assert_eq!(plan.points[0].external.get(ExternalAxis::E1), Some(0.0));
        assert_eq!(plan.points[0].external.get(ExternalAxis::E2), Some(-165.0));
    }

    #[test]
    fn sweeps_the_fit_would_refuse_are_refused_first() {
        let plan = |f: &dyn Fn(&mut PositionerPlanSettings)| {
            let mut s = PositionerPlanSettings {
                reflectors_mm: DESIGN_MM.to_vec(),
                ..PositionerPlanSettings::default()
            };
            f(&mut s);
            make_positioner_plan(&nominal(), &s)
                .unwrap_err()
                .to_string()
        };
        assert!(plan(&|s| s.tilt_deg = [-30.0, 30.0]).contains("spans 60°"));
        assert!(plan(&|s| s.rotate_values = 3).contains("has 3 values"));
        assert!(plan(&|s| s.reflectors_mm[1] = [5.0, 0.0, 20.0])
            .contains("reflector 2 is 5.0 mm from axis 2"));
        assert!(plan(&|s| s.reflectors_mm.clear()).contains("design positions"));
        assert!(plan(&|s| s.columns.rotate = ExternalAxis::E1).contains("both axes"));
    }
}
