//! A measurement plan for a one-axis turntable: the values of its axis at
//! which each reflector on the face plate is read, what the turntable fit
//! (`calibrate::external::turntable`) reads, and the σ of every parameter
//! those readings predict.
//!
//! One sweep: the axis over its travel at evenly spaced values (the
//! circle's fit and the scale's error, which grows with the angle turned,
//! want the whole span), every reflector read at every value, one tracker
//! file per reflector. The fit's rules, at least 4 values over at least 90°
//! and every reflector 20 mm or more from the axis, are checked here first.
//!
//! Predicted σ: `σ²·(JᵀJ)⁻¹` of the fit's own Jacobian
//! (`calibrate::external::turntable::problem::jacobian`) at the nominal
//! turntable, column-scaled as the fit's, reported as the fit reports its σ
//! (the direction [deg], the line's position [mm], the zero offset [deg],
//! the scale; per reflector its position [mm]). Frames: reflectors in the
//! face plate frame [mm]; values in the controller's degrees.

use super::positioner::{check_reflectors_and_noise, check_sweep};
use super::settings::PlanError;
use super::{evenly, PlanPoint};
use crate::calibrate::external::fit::variances;
use crate::calibrate::external::judge::{MAX_CONDITION, MIN_RADIUS_MM};
use crate::calibrate::external::outcome::AxisSigma;
use crate::calibrate::external::turntable::fit::{axis_sigma, reflector_sigmas};
use crate::calibrate::external::turntable::problem::{jacobian, Gauge, Row, State};
use crate::measure::external::{ExternalAxis, ExternalValues};
use crate::model::external::Turntable;
use crate::model::Pose;
use nalgebra::Vector3;

/// How a turntable's plan is made.
#[derive(Debug, Clone, PartialEq)]
pub struct TurntablePlanSettings {
    /// The reflectors' design positions on the face plate [mm, face plate
    /// frame]; the first is the reference.
    pub reflectors_mm: Vec<[f64; 3]>,
    /// The sweep's lowest and highest value [deg].
    pub travel_deg: [f64; 2],
    /// Values of the sweep, evenly over `travel_deg`.
    pub values: usize,
    /// The measurement files' column of the axis.
    pub column: ExternalAxis,
    /// Tracker noise, standard deviation per coordinate [mm].
    pub noise_mm: f64,
}

impl Default for TurntablePlanSettings {
    /// The sweep of the turntable's acceptance test: 12 values over
    /// −165…165°, column `e1`.
    fn default() -> Self {
        TurntablePlanSettings {
            reflectors_mm: Vec::new(),
            travel_deg: [-165.0, 165.0],
            values: 12,
            column: ExternalAxis::E1,
            noise_mm: 0.01,
        }
    }
}

/// A turntable's plan.
#[derive(Debug, Clone, PartialEq)]
pub struct TurntablePlan {
    /// The values to read every reflector at (no robot joints; `external`
    /// holds the axis's value [deg] in the plan's column).
    pub points: Vec<PlanPoint>,
    /// The same values [deg].
    pub values_deg: Vec<f64>,
    /// Predicted σ of the axis's parameters.
    pub sigma: AxisSigma,
    /// Predicted σ of each reflector's position [mm].
    pub reflector_sigma_mm: Vec<f64>,
    /// The column-scaled normal matrix's condition number.
    pub condition: f64,
    /// Tracker noise the prediction assumes [mm].
    pub noise_mm: f64,
}

/// Refuses settings the fit would refuse, or that are not numbers.
fn check(nominal: &Turntable, s: &TurntablePlanSettings) -> Result<(), PlanError> {
    check_reflectors_and_noise(&s.reflectors_mm, s.noise_mm)?;
    check_sweep("the turntable", s.travel_deg, s.values)?;
    // In the base frame at value 0 (a turn about the axis keeps the
    // distance from it).
    let line = nominal.axis.line_in(&Pose::identity());
    for (k, r) in s.reflectors_mm.iter().enumerate() {
        let p = nominal
            .base_from_face_plate(0.0)
            .transform_point(&(Vector3::from(*r) * 1e-3));
        let mm = line.distance_of(&p) * 1e3;
        if mm.is_nan() || mm < MIN_RADIUS_MM {
            return Err(PlanError::Setting(format!(
                "reflector {} is {mm:.1} mm from the axis; the fit needs at least {MIN_RADIUS_MM} mm (its circle fixes the axis's line)",
                k + 1
            )));
        }
    }
    Ok(())
}

/// Makes the plan for `nominal`.
pub fn make_turntable_plan(
    nominal: &Turntable,
    s: &TurntablePlanSettings,
) -> Result<TurntablePlan, PlanError> {
    check(nominal, s)?;
    let values_deg = evenly(s.travel_deg, s.values, 4);
    let gauge = Gauge::new(nominal, Vector3::from(s.reflectors_mm[0]) * 1e-3);
    let state = State {
        axis: nominal.axis,
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
                value: v.to_radians(),
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
            "the sweep leaves the turntable's parameters undetermined (condition number {condition:.1e}, at most {MAX_CONDITION:.0e}); put the reflectors away from the axis"
        )));
    }
    let points = values_deg
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let mut external = ExternalValues::default();
            external.0[s.column.index()] = Some(*v);
            PlanPoint {
                name: format!("P{}", i + 1),
                q_deg: Vec::new(),
                external,
            }
        })
        .collect();
    Ok(TurntablePlan {
        points,
        values_deg,
        sigma: axis_sigma(&var),
        reflector_sigma_mm: reflector_sigmas(&state, &var),
        condition,
        noise_mm: s.noise_mm,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::turntable_example::{nominal, sweep, DESIGN_MM};

    /// The default plan is the acceptance test's sweep.
    #[test]
    fn the_default_sweep_is_the_acceptance_tests() {
        let plan = make_turntable_plan(
            &nominal(),
            &TurntablePlanSettings {
                reflectors_mm: DESIGN_MM.to_vec(),
                ..TurntablePlanSettings::default()
            },
        )
        .unwrap();
        assert_eq!(plan.values_deg, sweep());
        assert_eq!(plan.points[0].external.get(ExternalAxis::E1), Some(-165.0));
        assert_eq!(plan.points.len(), 12);
    }

    #[test]
    fn sweeps_the_fit_would_refuse_are_refused_first() {
        let plan = |f: &dyn Fn(&mut TurntablePlanSettings)| {
            let mut s = TurntablePlanSettings {
                reflectors_mm: DESIGN_MM.to_vec(),
                ..TurntablePlanSettings::default()
            };
            f(&mut s);
            make_turntable_plan(&nominal(), &s).unwrap_err().to_string()
        };
        assert!(plan(&|s| s.travel_deg = [-30.0, 30.0]).contains("spans 60°"));
        assert!(plan(&|s| s.values = 3).contains("has 3 values"));
        assert!(plan(&|s| s.reflectors_mm[1] = [5.0, 0.0, 20.0])
            .contains("reflector 2 is 5.0 mm from the axis"));
        assert!(plan(&|s| s.reflectors_mm.clear()).contains("design positions"));
        assert!(plan(&|s| s.noise_mm = 0.0).contains("tracker noise"));
    }
}
