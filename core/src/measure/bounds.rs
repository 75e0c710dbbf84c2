//! The bounds of every numeric field of a measured pose as it is stored
//! (`MeasuredPose`: millimetres, degrees, kilograms, °C), checked after any
//! unit conversion by every way rows arrive: the measurement CSV reader
//! (`csv/row.rs`, naming line and column) and the service's JSON rows and
//! store (`MeasuredPose::check_bounds`, naming row and field).
//!
//! Why bounds and not only finiteness: a value converted after its check
//! (1e306 m is 1e309 mm, infinite) would be stored as JSON `null` and the
//! record could never be read again; and the fits square the standard
//! deviations and weigh rows by their inverse, so a σ of 1e200 or 1e-300
//! overflows there. The bounds are generous for any tracker and cell:
//! positions within 100 m, joint readings within two turns (beyond is wrong
//! units), σ from ten nanometres to a metre (a microdegree to half a turn),
//! temperatures of a workshop's air or a motor's housing.

use super::MeasuredPose;
use crate::model::bounds::{show, Bound};

/// Controller joint readings [deg]; beyond, the file is in other units
/// (encoder counts, radians declared as degrees).
pub const JOINT_DEG: Bound = Bound {
    min: -720.0,
    max: 720.0,
    unit: "deg",
};
/// Measured positions [mm] (100 m of the tracker).
pub const POSITION_MM: Bound = Bound {
    min: -100_000.0,
    max: 100_000.0,
    unit: "mm",
};
/// Measured orientation angles, fixed-axis XYZ [deg].
pub const ANGLE_DEG: Bound = Bound {
    min: -360.0,
    max: 360.0,
    unit: "deg",
};
/// Standard deviations of a position [mm]: ten nanometres to a metre.
pub const STD_MM: Bound = Bound {
    min: 1e-5,
    max: 1000.0,
    unit: "mm",
};
/// Standard deviations of an orientation angle [deg].
pub const STD_DEG: Bound = Bound {
    min: 1e-6,
    max: 180.0,
    unit: "deg",
};
/// The payload during the measurement [kg].
pub const PAYLOAD_KG: Bound = Bound {
    min: 0.0,
    max: 10_000.0,
    unit: "kg",
};
/// The temperature during the measurement [°C] (the checks' bound too).
pub const TEMPERATURE_C: Bound = Bound {
    min: -100.0,
    max: 200.0,
    unit: "°C",
};

/// External-axis values (`e1…e6`) as the controller shows them [mm or
/// deg]: a 100 m track, or a rotary axis's value within 100000°.
pub const EXTERNAL_VALUE: Bound = Bound {
    min: -100_000.0,
    max: 100_000.0,
    unit: "mm or deg",
};

/// Whether `v` is finite and within `b`.
pub fn within(v: f64, b: &Bound) -> bool {
    v.is_finite() && v >= b.min && v <= b.max
}

/// `[min, max] unit`, as messages state a bound.
pub fn describe(b: &Bound) -> String {
    format!("[{}, {}] {}", show(b.min), show(b.max), b.unit)
}

/// A stored field beyond its bound.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("`{field}` = {} {} is outside the bound {}", show(*value), bound.unit, describe(bound))]
pub struct OutOfBounds {
    /// `q_deg[2]`, `std_mm[0]`, `temperature_c`, …
    pub field: String,
    /// The value stored, in the bound's unit.
    pub value: f64,
    /// The bound it is beyond.
    pub bound: Bound,
}

/// The first value of `values` (named `field[i]`) outside `b`.
fn check_each(field: &str, values: &[f64], b: &Bound) -> Result<(), OutOfBounds> {
    match values.iter().position(|v| !within(*v, b)) {
        None => Ok(()),
        Some(i) => Err(OutOfBounds {
            field: format!("{field}[{i}]"),
            value: values[i],
            bound: *b,
        }),
    }
}

impl MeasuredPose {
    /// Every numeric field within its bound (module docs), the first that
    /// is not named with its value and bound.
    pub fn check_bounds(&self) -> Result<(), OutOfBounds> {
        check_each("q_deg", &self.q_deg, &JOINT_DEG)?;
        check_each("xyz_mm", &self.xyz_mm, &POSITION_MM)?;
        let optional: [(&str, Option<&[f64]>, &Bound); 5] = [
            ("rpy_deg", self.rpy_deg.as_ref().map(|v| &v[..]), &ANGLE_DEG),
            ("std_mm", self.std_mm.as_ref().map(|v| &v[..]), &STD_MM),
            ("std_deg", self.std_deg.as_ref().map(|v| &v[..]), &STD_DEG),
            (
                "payload_kg",
                self.payload_kg.as_ref().map(std::slice::from_ref),
                &PAYLOAD_KG,
            ),
            (
                "temperature_c",
                self.temperature_c.as_ref().map(std::slice::from_ref),
                &TEMPERATURE_C,
            ),
        ];
        for (field, values, b) in optional {
            let Some(values) = values else { continue };
            check_each(field, values, b).map_err(|mut e| {
                if values.len() == 1 {
                    e.field = field.to_string();
                }
                e
            })?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pose() -> MeasuredPose {
        MeasuredPose {
            q_deg: vec![720.0, -720.0],
            xyz_mm: [100_000.0, -100_000.0, 5.0],
            rpy_deg: Some([360.0, -360.0, 0.0]),
            std_mm: Some([1e-5, 1000.0, 0.01]),
            std_deg: Some([1e-6, 180.0, 0.01]),
            payload_kg: Some(10_000.0),
            temperature_c: Some(-100.0),
            set: None,
            session: None,
        }
    }

    #[test]
    fn every_field_at_its_bound_passes_and_beyond_is_named() {
        assert_eq!(pose().check_bounds(), Ok(()));
        type Edit = fn(&mut MeasuredPose);
        let cases: [(&str, Edit); 8] = [
            ("`q_deg[1]` = -720.5 deg", |p| p.q_deg[1] = -720.5),
            ("`xyz_mm[2]` = inf mm", |p| p.xyz_mm[2] = f64::INFINITY),
            ("`rpy_deg[0]` = 360.5 deg", |p| {
                p.rpy_deg = Some([360.5, 0.0, 0.0])
            }),
            ("`std_mm[0]` = inf mm", |p| {
                p.std_mm = Some([f64::INFINITY, 1.0, 1.0])
            }),
            ("`std_mm[1]` = 1e-6 mm", |p| {
                p.std_mm = Some([1.0, 1e-6, 1.0])
            }),
            ("`std_deg[2]` = 181 deg", |p| {
                p.std_deg = Some([1.0, 1.0, 181.0])
            }),
            ("`payload_kg` = -1 kg", |p| p.payload_kg = Some(-1.0)),
            ("`temperature_c` = 200.5 °C", |p| {
                p.temperature_c = Some(200.5)
            }),
        ];
        for (want, edit) in cases {
            let mut p = pose();
            edit(&mut p);
            let e = p.check_bounds().unwrap_err().to_string();
            assert!(e.starts_with(want), "{e} / {want}");
            assert!(e.contains("is outside the bound ["), "{e}");
        }
    }
}
