//! Whether a positioner's readings can give a fit worth storing, and whether
//! the fit is what they explain, judged before anything is stored.
//!
//! Before the fit, each axis needs a sweep: one reflector read at
//! ≥ [`MIN_ANGLES`] distinct values of the axis with the other held (three
//! fix a circle, a fourth shows whether it is one), spanning
//! ≥ [`MIN_SPAN_DEG`] (the scale shows as an angle error growing with the
//! angle turned; over a short span it hides in the zero offset and the
//! noise), on a circle of radius ≥ [`MIN_RADIUS_MM`] (a reflector on the
//! axis barely moves and shows neither the line nor the angle).
//!
//! After it, the residuals against the tracker's noise σ per coordinate, as
//! the cell's tool and work-object fits judge theirs: RMS of the 3-D
//! residuals ≤ [`RMS_FACTOR`]·√3·σ (nine times the variance the noise
//! explains: χ² beyond any chance for the ≥ 8 readings of a fit) and every
//! single residual ≤ [`MAX_FACTOR`]·√3·σ (χ²(3) of 75, p < 1e-15: a wrong
//! reading, named). Effects the model lacks (an axis's wobble, a reflector
//! knocked, a positioner that moved) show there.

use super::outcome::{FitLimits, RefusalReason};
use super::refusal::Refusal;

/// Fewest distinct values of an axis in its sweep.
pub const MIN_ANGLES: usize = 4;
/// Smallest span of an axis's sweep [deg].
pub const MIN_SPAN_DEG: f64 = 90.0;
/// Smallest radius of a reflector's circle about the axis it turned about [mm].
pub const MIN_RADIUS_MM: f64 = 20.0;
/// RMS bound in units of the expected 3-D RMS, √3·σ.
pub const RMS_FACTOR: f64 = 3.0;
/// Bound of one residual in units of √3·σ.
pub const MAX_FACTOR: f64 = 5.0;
/// Largest condition number of the column-scaled normal matrix.
pub const MAX_CONDITION: f64 = 1e12;

impl FitLimits {
    /// The bounds for a tracker of noise `sigma_mm` per coordinate.
    pub fn of(sigma_mm: f64) -> Self {
        FitLimits {
            sigma_mm,
            rms_mm: RMS_FACTOR * 3f64.sqrt() * sigma_mm,
            max_mm: MAX_FACTOR * 3f64.sqrt() * sigma_mm,
        }
    }
}

/// `x` is a number no larger than `limit` (NaN is not).
pub fn within(x: f64, limit: f64) -> bool {
    x <= limit
}

/// RMS and largest of `v`.
pub fn rms_max(v: &[f64]) -> (f64, f64) {
    if v.is_empty() {
        return (0.0, 0.0);
    }
    let rms = (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();
    (rms, v.iter().copied().fold(0.0, f64::max))
}

/// The first of the residuals [mm] beyond `limits`: the RMS, then the worst
/// reading (1-based row).
pub fn check_residuals<F>(
    residual_mm: &[f64],
    limits: &FitLimits,
) -> Result<(), Refusal<RefusalReason, F>> {
    let (rms, max) = rms_max(residual_mm);
    if !within(rms, limits.rms_mm) {
        return Err(Refusal::new(
            RefusalReason::ResidualsTooLarge,
            format!(
                "the readings do not follow one rigid positioner: residuals rms {rms:.4} mm (max {max:.4} mm), \
                 beyond the tracker's noise (rms at most {:.4} mm: {RMS_FACTOR}·√3 σ of {:.4} mm per axis); \
                 check that the reflectors stayed in their nests, the positioner and the tracker did not move, \
                 and the axis values belong to the readings",
                limits.rms_mm, limits.sigma_mm
            ),
        )
        .figures(rms, limits.rms_mm));
    }
    if let Some((i, r)) = residual_mm
        .iter()
        .enumerate()
        .find(|(_, r)| !within(**r, limits.max_mm))
    {
        return Err(Refusal::new(
            RefusalReason::ResidualOutlier,
            format!(
                "reading {}: its residual of {r:.4} mm is beyond the tracker's noise (at most {:.4} mm: \
                 {MAX_FACTOR}·√3 σ of {:.4} mm per axis); measure it again or leave it out",
                i + 1,
                limits.max_mm,
                limits.sigma_mm
            ),
        )
        .at_row(i + 1)
        .figures(*r, limits.max_mm));
    }
    Ok(())
}

/// The inputs every face-plate fit checks before fitting: reflectors given
/// and finite, σ positive, each reading finite (`readings[i]`: its
/// reflector and whether its values are finite) and naming a given
/// reflector, every reflector read; `zero` names the zero reflector 0
/// defines (`axis 2's`, `the axis's`).
pub fn check_reflector_inputs<F>(
    reflectors_mm: &[[f64; 3]],
    sigma_mm: f64,
    readings: &[(usize, bool)],
    zero: &str,
) -> Result<(), Refusal<RefusalReason, F>> {
    if reflectors_mm.is_empty() {
        return Err(Refusal::new(
            RefusalReason::UnknownReflector,
            "no reflectors: give the design position on the face plate of each reflector read"
                .into(),
        ));
    }
    if !(sigma_mm > 0.0 && sigma_mm.is_finite()) {
        return Err(Refusal::new(
            RefusalReason::NotFinite,
            format!("the tracker's noise σ is {sigma_mm} mm; give a positive number"),
        ));
    }
    if reflectors_mm.iter().flatten().any(|v| !v.is_finite()) {
        return Err(Refusal::new(
            RefusalReason::NotFinite,
            "a reflector's design position is not finite".into(),
        ));
    }
    for (i, &(reflector, finite)) in readings.iter().enumerate() {
        if !finite {
            return Err(Refusal::new(
                RefusalReason::NotFinite,
                format!("reading {}: a value is not finite", i + 1),
            )
            .at_row(i + 1));
        }
        if reflector >= reflectors_mm.len() {
            return Err(Refusal::new(
                RefusalReason::UnknownReflector,
                format!(
                    "reading {} names reflector {reflector}, but {} reflector(s) are given",
                    i + 1,
                    reflectors_mm.len()
                ),
            )
            .at_row(i + 1));
        }
    }
    if let Some(k) = (0..reflectors_mm.len()).find(|k| !readings.iter().any(|r| r.0 == *k)) {
        let what = if k == 0 {
            format!("reflector 0, the reference that defines {zero} zero, has no readings; read it, or list a reflector that was read first")
        } else {
            format!("reflector {k} is given but has no readings; leave it out")
        };
        return Err(Refusal::new(RefusalReason::UnknownReflector, what));
    }
    Ok(())
}
