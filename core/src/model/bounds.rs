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

use super::description::ModelError;

/// A closed interval `[min, max]` in `unit`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bound {
    pub min: f64,
    pub max: f64,
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
                b.min,
                b.max,
                b.unit
            ),
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
