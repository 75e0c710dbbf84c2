//! Physical bounds of the numeric fields of a model description, checked in
//! one place ([`super::description::ModelDescription::to_model`]) for every
//! way a model arrives: HTTP, CLI and model files.
//!
//! Units are the description's: millimetres, degrees, kilograms, m/s²,
//! rad/(N·m). The bounds are generous for any industrial arm (the largest
//! reach a few metres, link masses a few tonnes) and keep every product the
//! kinematics and the statics form (lengths × angles, masses × g × lengths ×
//! compliances) far from overflow, so no numerical routine meets an
//! infinite or NaN intermediate from an accepted model.
//!
//! A calibrated model file's learned compensator and its support are
//! checked by [`compensator::check_compensator`] (SI units, as the network
//! computes: rad, kg, N·m in, m out; the bounds of its outputs in
//! [`outputs`]), called by the file's loader (`model/calibrated/file.rs`)
//! for every file and stored version.

use super::error::ModelError;

pub mod compensator;
pub mod outputs;

/// A closed interval `[min, max]` in `unit`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bound {
    /// Lowest value accepted, in `unit`.
    pub min: f64,
    /// Highest value accepted, in `unit`.
    pub max: f64,
    /// The unit messages name (`mm`, `deg`, `kg`, …).
    pub unit: &'static str,
}

/// Link lengths and offsets (a, b, d) [mm]; also the points a model gives
/// in a frame that is re-expressed when it is stored: a standard-DH row's
/// centre of mass and the tool of a standard-DH model (re-expressed in the
/// modified frames), a payload's centre of mass in the flange frame
/// (re-expressed in the tool frame).
pub const LENGTH_MM: Bound = Bound {
    min: -100_000.0,
    max: 100_000.0,
    unit: "mm",
};
/// Centres of mass and the tool of a modified-convention model [mm]: the
/// frames a model is stored in. A standard-DH point p within [`LENGTH_MM`]
/// becomes Tx(a)·Rx(α)·p with a within [`LENGTH_MM`]: at most 2·10⁵ mm in x
/// and √2·10⁵ mm in y and z, inside this bound with room for rounding, so a
/// stored model reads back.
pub const POINT_MM: Bound = Bound {
    min: -300_000.0,
    max: 300_000.0,
    unit: "mm",
};
/// A payload's centre of mass in the tool frame [mm] (the frame it is stored
/// in): one given in the flange frame within [`LENGTH_MM`] becomes
/// Rᵀ·(c − p) for a tool p within [`POINT_MM`], of length at most
/// √3·(10⁵ + 3·10⁵) ≈ 6.9·10⁵ mm, inside this bound.
pub const TOOL_FRAME_POINT_MM: Bound = Bound {
    min: -1_000_000.0,
    max: 1_000_000.0,
    unit: "mm",
};
/// Positive lengths of a closed loop (l3, l4, l5) [mm]; 0 is refused apart.
pub const LOOP_LENGTH_MM: Bound = Bound {
    min: 0.0,
    max: 100_000.0,
    unit: "mm",
};
/// Twists, joint offsets, zero offsets, tool angles, the loop angle ξ [deg].
pub const ANGLE_DEG: Bound = Bound {
    min: -360.0,
    max: 360.0,
    unit: "deg",
};
/// Joint limits [deg]: up to ten turns each way (multi-turn wrists).
pub const LIMIT_DEG: Bound = Bound {
    min: -3600.0,
    max: 3600.0,
    unit: "deg",
};
/// Link and payload masses [kg].
pub const MASS_KG: Bound = Bound {
    min: 0.0,
    max: 10_000.0,
    unit: "kg",
};
/// Payload mass offset identified by `skcm-payload` [kg].
pub const MASS_OFFSET_KG: Bound = Bound {
    min: -10_000.0,
    max: 10_000.0,
    unit: "kg",
};
/// Joint compliance [rad/(N·m)]: 10 turns 0.1 N·m into 1 rad. Far softer
/// than any industrial joint (1e-8–1e-4), yet above what SKCM fits where a
/// joint carries almost no torque (the real WAM's wrist with skcm-payload:
/// about 0.38), so no fitted model is refused when it is loaded back. With
/// the other bounds the deflection stays finite (at most about 1e10 rad).
pub const COMPLIANCE_RAD_PER_NM: Bound = Bound {
    min: 0.0,
    max: 10.0,
    unit: "rad/(N·m)",
};
/// Each gravity component [m/s²] (larger ones are not m/s²).
pub const GRAVITY_MPS2: Bound = Bound {
    min: -100.0,
    max: 100.0,
    unit: "m/s²",
};

/// A learned compensator's weights (the MLP's flat weights in normalised
/// units, the RBF's output weights [m]). Both output layers are solved by
/// least squares (a ridge of 1e-10 of the trace, an SVD cut at 1e-12 of the
/// largest singular value), which lets cancelling weights grow to about
/// 1e5–1e9 times the target; 1e12 leaves room for every trained network
/// and keeps a sum of thousands of such products below 1e20.
pub const NETWORK_WEIGHT: Bound = Bound {
    min: -1e12,
    max: 1e12,
    unit: "(network units)",
};
/// A network's input centre (`input_norm.centre`): joints [rad], their sines
/// and cosines, payload [kg] or gravity torques [N·m]: the largest torque
/// the model bounds allow (10⁴ kg · 100 m/s² · 10² m … per link) is far
/// below it.
pub const INPUT_CENTRE: Bound = Bound {
    min: -1e9,
    max: 1e9,
    unit: "rad, kg or N·m",
};
/// A network's input scale (`input_norm.scale`, 2/(max − min) of the
/// training inputs; 0 ignores a constant input): training keeps a range
/// above 1e-12 of the values, so a real scale stays below about 2e12.
pub const INPUT_SCALE: Bound = Bound {
    min: 0.0,
    max: 1e13,
    unit: "1/(rad, kg or N·m)",
};
/// An MLP's output scale (`output_norm.scale`, 2/(max − min) of the
/// residuals [m]; 1 for a constant output): positive, as the network's
/// output is divided by it.
pub const OUTPUT_SCALE: Bound = Bound {
    min: 0.0,
    max: 1e13,
    unit: "1/m",
};
/// A residual [m]: a compensator's output centre and mean, the RMS it was
/// trained on. A calibrated model that leaves 100 m is no model.
pub const RESIDUAL_M: Bound = Bound {
    min: -100.0,
    max: 100.0,
    unit: "m",
};
/// An RBF's centres (normalised torques, within [−1, 1] when trained) and
/// spread (positive) [normalised units].
pub const RBF_NORMALISED: Bound = Bound {
    min: -1e6,
    max: 1e6,
    unit: "(normalised torque)",
};
/// Joint values a compensator stores [rad]: a GP's inducing configurations,
/// a support's ranges and points. Joint limits are at most ±3600° (62.8 rad).
pub const JOINT_RAD: Bound = Bound {
    min: -1000.0,
    max: 1000.0,
    unit: "rad",
};
/// A distance in joint space [rad]: a support's fade width and radius.
pub const JOINT_DISTANCE_RAD: Bound = Bound {
    min: 0.0,
    max: 10_000.0,
    unit: "rad",
};
/// A GP's inverse length scales `1/ℓ` [1/rad]: ℓ of at least a microradian;
/// 0 ignores the joint; a negative one is no length scale.
pub const INVERSE_LENGTH_SCALE: Bound = Bound {
    min: 0.0,
    max: 1e6,
    unit: "1/rad",
};
/// A GP's signal and noise variances `s²`, `σ²` [m²]: positive, at most a
/// 100 m standard deviation.
pub const GP_VARIANCE_M2: Bound = Bound {
    min: 0.0,
    max: 1e4,
    unit: "m²",
};
/// A GP's weights `α` [1/m] and variance matrix `K_ZZ⁻¹ − σ²·A⁻¹` [1/m²]:
/// they scale as 1/s² times the kernel matrix's condition, far below 1e30
/// for any trained process; with `s² ≤ 1e4` every prediction stays finite.
pub const GP_COEFFICIENT: Bound = Bound {
    min: -1e30,
    max: 1e30,
    unit: "1/m or 1/m²",
};
/// A GP's error scale `κ` (held-out RMS error over the predicted one):
/// positive.
pub const ERROR_SCALE: Bound = Bound {
    min: 0.0,
    max: 1e6,
    unit: "",
};

/// `v` when finite and within `b`; else an error naming the field, the value
/// and the bound.
pub fn check(field: &str, v: f64, b: &Bound) -> Result<f64, ModelError> {
    if v.is_finite() && v >= b.min && v <= b.max {
        Ok(v)
    } else {
        Err(ModelError::InvalidField {
            field: field.to_string(),
            reason: format!(
                "{} is outside the bound [{}, {}] {}",
                show(v),
                show_bound(b.min),
                show_bound(b.max),
                b.unit
            ),
        })
    }
}

/// `v` when finite, above `b.min` (excluded) and at most `b.max`: a
/// quantity that must be positive.
pub fn check_above(field: &str, v: f64, b: &Bound) -> Result<f64, ModelError> {
    if v.is_finite() && v > b.min && v <= b.max {
        Ok(v)
    } else {
        Err(ModelError::InvalidField {
            field: field.to_string(),
            reason: format!(
                "{} is outside the bound ({}, {}] {}",
                show(v),
                show_bound(b.min),
                show_bound(b.max),
                b.unit
            ),
        })
    }
}

/// [`check`] on each value, named `field[i]`.
pub fn check_all(field: &str, v: &[f64], b: &Bound) -> Result<(), ModelError> {
    for (i, x) in v.iter().enumerate() {
        if !(x.is_finite() && *x >= b.min && *x <= b.max) {
            check(&format!("{field}[{i}]"), *x, b)?;
        }
    }
    Ok(())
}

/// At most `max` items in `field`.
pub fn check_count(field: &str, n: usize, max: usize, what: &str) -> Result<(), ModelError> {
    if n <= max {
        Ok(())
    } else {
        Err(ModelError::InvalidField {
            field: field.to_string(),
            reason: format!("{n} {what} is more than the bound {max}"),
        })
    }
}

/// A value as a person reads it: 1e308, not 309 digits.
pub fn show(v: f64) -> String {
    if v.is_finite() && v != 0.0 && !(1e-4..1e6).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// A bound as a person reads it: 1e12, not 13 digits; 100000 as it is.
fn show_bound(v: f64) -> String {
    if v.abs() >= 1e7 {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// [`check`] on each component, named `field[i]`.
pub fn check3(field: &str, v: [f64; 3], b: &Bound) -> Result<[f64; 3], ModelError> {
    for (i, x) in v.iter().enumerate() {
        check(&format!("{field}[{i}]"), *x, b)?;
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::description::ModelDescription;
    use crate::model::RobotModel;

    /// A description from JSON (fields left out take their defaults).
    fn description(v: serde_json::Value) -> ModelDescription {
        serde_json::from_value(v).unwrap()
    }

    /// A standard-DH model with every re-expressed point at the edge of the
    /// bound as given, and the last row's `a` at its own edge: accepted,
    /// and its stored (modified) form reads back, for twists that rotate y
    /// into z and for both signs.
    #[test]
    fn standard_points_at_the_bound_store_a_model_that_reads_back() {
        for alpha in [0.0, 45.0, 90.0, 135.0, 180.0, -60.0, 360.0] {
            for s in [1.0, -1.0] {
                let l = s * LENGTH_MM.max;
                let joint = serde_json::json!({
                    "a_mm": l, "alpha_deg": alpha, "d_mm": l, "com_mm": [l, l, -l],
                });
                let d = description(serde_json::json!({
                    "convention": "standard",
                    "joints": [joint.clone(), joint.clone(), joint],
                    "tool": { "xyz_mm": [l, -l, l], "rpy_deg": [0, 0, 0] },
                    "payload": { "mass_kg": 1, "com_mm": [l, l, l], "com_frame": "flange" },
                }));
                let m = d.to_model().unwrap();
                let stored = ModelDescription::from_model(&m);
                // Re-expressed in the modified frames: a + c_x in x (2e5 at
                // α = 0 for the second joint's row, taking the first's a).
                if alpha == 0.0 {
                    assert!((stored.joints[1].com_mm[0] - 2.0 * l).abs() < 1e-6);
                    assert!((stored.tool.xyz_mm[0] - 2.0 * l).abs() < 1e-6);
                }
                for j in &stored.joints {
                    assert!(j
                        .com_mm
                        .iter()
                        .all(|c| c.abs() <= 2.0 * LENGTH_MM.max + 1e-6));
                }
                let back = RobotModel::from_json(&m.to_json());
                assert!(back.is_ok(), "α {alpha}, sign {s}: {:?}", back.err());
            }
        }
    }

    /// Points are bounded as given: ±1e5 mm in a standard row or the flange
    /// frame, wider in the frames a model is stored in.
    #[test]
    fn points_are_bounded_in_the_frame_they_are_given_in() {
        let model = |convention: &str, com: f64, tool: f64, payload: f64, frame: &str| {
            description(serde_json::json!({
                "convention": convention,
                "joints": [{ "com_mm": [com, 0, 0] }, {}],
                "tool": { "xyz_mm": [0, tool, 0] },
                "payload": { "com_mm": [0, 0, payload], "com_frame": frame },
            }))
            .to_model()
        };
        assert!(model("standard", 1e5, 1e5, 1e5, "flange").is_ok());
        let e = model("standard", 100_001.0, 0.0, 0.0, "tool").unwrap_err();
        assert!(e.to_string().contains("joints[0].com_mm[0]"), "{e}");
        let e = model("standard", 0.0, -100_001.0, 0.0, "tool").unwrap_err();
        assert!(e.to_string().contains("tool.xyz_mm[1]"), "{e}");
        let e = model("modified", 0.0, 0.0, 100_001.0, "flange").unwrap_err();
        assert!(e.to_string().contains("payload.com_mm[2]"), "{e}");
        assert!(model("modified", 3e5, -3e5, 1e6, "tool").is_ok());
        let e = model("modified", 300_001.0, 0.0, 0.0, "tool").unwrap_err();
        assert!(e.to_string().contains("[-300000, 300000] mm"), "{e}");
        let e = model("modified", 0.0, 0.0, -1_000_001.0, "tool").unwrap_err();
        assert!(e.to_string().contains("[-1000000, 1000000] mm"), "{e}");
    }

    #[test]
    fn the_error_names_field_value_and_bound() {
        let e = check("tool.xyz_mm[0]", 1e308, &LENGTH_MM).unwrap_err();
        let s = e.to_string();
        assert!(s.contains("tool.xyz_mm[0]"), "{s}");
        assert!(s.contains(" 1e308 "), "{s}");
        assert!(s.contains("[-100000, 100000] mm"), "{s}");
        assert!(check("x", f64::NAN, &LENGTH_MM).is_err());
        assert!(check("x", f64::INFINITY, &LENGTH_MM).is_err());
        assert!(check("x", -1e-300, &MASS_KG).is_err());
        assert_eq!(check("x", 1e-300, &MASS_KG).unwrap(), 1e-300);
        assert_eq!(check("x", 100_000.0, &LENGTH_MM).unwrap(), 100_000.0);
        assert!(check("x", 100_000.000_1, &LENGTH_MM).is_err());
        assert!(check3("c", [0.0, 1.0, 2e5], &LENGTH_MM)
            .unwrap_err()
            .to_string()
            .contains("c[2]"));
    }
}
