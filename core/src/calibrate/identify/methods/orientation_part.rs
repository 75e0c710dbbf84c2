//! A compensator's orientation part (`compensate::oriented`): trained,
//! cross-validated and, in `auto`, kept or dropped.
//!
//! The part learns the rotation vector `ω = log(E_sᵀ·R_measured·R_predictedᵀ)`
//! [rad] (registered base frame) of the training poses that measured an
//! orientation, with the position part's network kind and settings. It is
//! trained when at least half of the training poses (and at least 5) measured
//! one; otherwise the report says why ([`OrientationPartStatus`]):
//! `not_measured` when none did (position-only data: there is nothing that
//! could see a correction of the orientation, so none is made, and `predict`
//! calls a production tool's orientation unverified), `too_few_poses`, or
//! `training_failed`.
//!
//! Cross-validation: with `folds` > 0 the part is cross-validated like the
//! position part, on the same seeded fold assignment (`ChaCha8Rng(seed + 1)`
//! over the poses; the same folds whenever every training pose measured an
//! orientation), fold `f` trained from `ChaCha8Rng(seed + 600 + f)` and faded
//! by its fold's support. The held-out error of a pose is `|ω − ω̂|`, the angle
//! left after the correction to first order. `auto` keeps the part of the
//! compensator it chose only when its cross-validated orientation mean is at
//! least `min_gain` (the position part's bar, 5 %) below the base's on the
//! same poses (`not_kept` otherwise, with the figures); a method run on its
//! own keeps it as trained.
//!
//! Inputs whose effect is unseen: the part's inputs are the position part's
//! (`q`, gravity torques, payload), each of which moves the flange's
//! orientation directly; with orientation rows every one is seen, and without
//! them the part is not trained at all, so no input of it can be fitted
//! unseen. The position part's inputs are seen through the measured point's
//! position by construction (its outputs are that position's residual).

use super::trained::{support_of, AppliedCompensator, Trained};
use super::{Base, MethodError};
use crate::calibrate::compensate::select::{Jobs, Parallelism};
use crate::calibrate::compensate::{
    cross_validate, train, CompensatorSpec, OrientationSamples, Sample, TrainError,
};
use crate::calibrate::identify::report::{OrientationCv, OrientationPart, OrientationPartStatus};
use crate::model::calibrated::StoredOrientation;
use crate::model::RobotModel;
use nalgebra::Matrix3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// What the base's model adds up to, for the reasons.
fn base_parts(base: Base) -> &'static str {
    match base {
        Base::Km => "geometry",
        Base::Skcm => "geometry and compliance",
        Base::KmMaps => "geometry and joint maps",
        Base::SkcmMaps => "geometry, compliance and joint maps",
    }
}

/// The orientation part trained on `data`'s orientation residuals
/// (`rotations[i]` of `data[i]`, module docs) about the measurement tool's
/// point, cross-validated when `folds` > 0, and its report entry.
pub(crate) fn train_orientation(
    spec: &CompensatorSpec,
    model: &RobotModel,
    (data, rotations): (&[Sample], &[Option<Matrix3<f64>>]),
    seed: u64,
    folds: usize,
    parallel: Parallelism,
    cancel: &mut dyn FnMut() -> bool,
) -> Result<(Option<StoredOrientation>, OrientationPart), MethodError> {
    let samples = OrientationSamples::of(data, rotations);
    let part = |status, reason: String| OrientationPart {
        status,
        reason,
        cross_validation: None,
    };
    if samples.is_empty() {
        return Ok((
            None,
            part(
                OrientationPartStatus::NotMeasured,
                "no training pose measured an orientation: the compensator corrects the position of the measured point only, the orientation is the base's and a production tool's orientation is unverified".into(),
            ),
        ));
    }
    if samples.len() < 5 || 2 * samples.len() < data.len() {
        return Ok((
            None,
            part(
                OrientationPartStatus::TooFewPoses,
                format!(
                    "{} of {} training poses measured an orientation (at least half and 5 are needed): the compensator corrects the position only",
                    samples.len(),
                    data.len()
                ),
            ),
        ));
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_add(500));
    let network = match train(spec, &samples, &mut rng, &mut |_, _| cancel()) {
        Ok((network, _)) => network,
        Err(TrainError::Cancelled) => return Err(MethodError::Cancelled),
        Err(e) => {
            return Ok((
                None,
                part(
                    OrientationPartStatus::TrainingFailed,
                    format!(
                        "its training failed ({e}): the compensator corrects the position only"
                    ),
                ),
            ))
        }
    };
    let cv = if folds > 0 {
        cross_validate_part(spec, &samples, folds, seed, parallel, cancel)?
    } else {
        None
    };
    let stored = StoredOrientation {
        point_m: model.tool.p.into(),
        network,
    };
    let reason = format!(
        "a second network of the same form learned the orientation residuals (rotation vectors, registered base frame) of the {} poses that measured one, and turns the flange about the measured point{}",
        samples.len(),
        cv.as_ref().map_or(String::new(), |c| format!(
            "; cross-validated ({} folds) {:.4}° mean against the base's {:.4}°",
            c.folds, c.compensated_mean_deg, c.base_mean_deg
        ))
    );
    Ok((
        Some(stored),
        OrientationPart {
            status: OrientationPartStatus::Trained,
            reason,
            cross_validation: cv,
        },
    ))
}

/// The `folds`-fold cross-validation of the orientation part on `samples`
/// (module docs); `None` when a fold's training fails.
fn cross_validate_part(
    spec: &CompensatorSpec,
    samples: &[Sample],
    folds: usize,
    seed: u64,
    parallel: Parallelism,
    cancel: &mut dyn FnMut() -> bool,
) -> Result<Option<OrientationCv>, MethodError> {
    let jobs = Jobs {
        parallel,
        progress: &mut |_, _, _| cancel(),
        cancelled: || TrainError::Cancelled,
    };
    let cv = cross_validate(samples, folds, 0, jobs, |fold, part, report| {
        let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_add(600 + fold as u64));
        let (c, _) = train(spec, part, &mut rng, report)?;
        Ok::<_, TrainError>(c.into_arc_supported(Some(support_of(part))))
    });
    match cv {
        Ok(cv) => Ok(Some(OrientationCv::of(&cv))),
        Err(TrainError::Cancelled) => Err(MethodError::Cancelled),
        Err(_) => Ok(None),
    }
}

/// `auto`'s decision on the chosen compensator's orientation part (module
/// docs): dropped unless its cross-validation lowered the orientation mean
/// by at least `min_gain`. Returns the part's report entry (`None` without
/// orientation measurements) and a note when it was dropped.
pub(crate) fn settle_for_auto(
    applied: &mut AppliedCompensator,
    min_gain: f64,
) -> Option<(OrientationPart, Option<String>)> {
    let t: &mut Trained = &mut applied.trained;
    if t.orientation_part.status == OrientationPartStatus::NotMeasured {
        return None;
    }
    if t.orientation.is_none() {
        return Some((t.orientation_part.clone(), None));
    }
    let name = applied.method.name();
    let cv = t.orientation_part.cross_validation.clone();
    if cv.as_ref().is_some_and(|c| c.helps(min_gain)) {
        return Some((t.orientation_part.clone(), None));
    }
    let reason = match &cv {
        Some(c) => format!(
            "{name}'s orientation part dropped: cross-validated ({} folds) it leaves {:.4}° mean against {:.4}° of its base's {} alone, not {:.0} % lower on held-out poses; the orientation is the base's",
            c.folds,
            c.compensated_mean_deg,
            c.base_mean_deg,
            base_parts(applied.base),
            min_gain * 100.0
        ),
        None => format!(
            "{name}'s orientation part dropped: its cross-validation did not run, so it has shown no gain on held-out poses; the orientation is the base's"
        ),
    };
    t.orientation = None;
    t.orientation_part = OrientationPart {
        status: OrientationPartStatus::NotKept,
        reason: reason.clone(),
        cross_validation: cv,
    };
    Some((t.orientation_part.clone(), Some(reason)))
}

/// The report's `orientation_note` of a compensator on `base` (none
/// without orientation measurements in any set).
pub(crate) fn note(part: &OrientationPart, base: Base, measured: bool) -> Option<String> {
    measured.then(|| match part.status {
        OrientationPartStatus::Trained => "the compensator corrects the orientation too: a second network of the same form learned the orientation residuals (rotation vectors, registered base frame) on the same poses, and turns the flange about the measured point".to_string(),
        _ => format!(
            "the compensator corrects the position only ({}): the orientation errors are those of {} (its {}), unchanged by it",
            match part.status {
                OrientationPartStatus::NotKept => "auto dropped its orientation part: no gain on held-out poses",
                OrientationPartStatus::TrainingFailed => "the orientation part's training failed",
                _ => "too few training poses measured an orientation",
            },
            base.method().name(),
            base_parts(base)
        ),
    })
}
