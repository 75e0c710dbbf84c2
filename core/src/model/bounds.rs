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

/// Link lengths and offsets (a, b, d), tool offset, centres of mass [mm].
pub const LENGTH_MM: Bound = Bound {
    min: -100_000.0,
    max: 100_000.0,
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
/// the other bounds the deflection stays finite (at most about 1e9 rad).
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
