//! The compensator methods (thesis ch. 3–6): a model-based base, then a learned
//! compensator on the residuals it leaves.
//!
//! A compensator method fits its base (KM for `km-rbf`, SKCM for `skcm-nn`,
//! `skcm-iwonn`, `skcm-tlbonn`), then trains a compensator
//! ([`compensate::train`](crate::calibrate::compensate::train)) on the residuals the base
//! leaves on the **training pool**:
//!
//! - Q1, the identification poses, fit the base (eq. 2.3 / 2.8);
//! - Q2, the training poses (rows or sets with role `training`), train the
//!   compensator and are never used by the base fit; without Q2 the
//!   compensator trains on Q1 and is judged by k-fold cross-validation inside
//!   it (`compensate::select`);
//! - Q3, the validation poses, are only predicted.
//!
//! Samples (frames): a pose of session `s` measured at `y` (registered base
//! frame of its session, `registration`) has the residual
//! `E_s⁻¹·y − FK_cal(q + c∘τ)` in the calibrated model's base frame, `E_s` the
//! fit's frame correction of session `s` (identity for session 0); τ are the
//! calibrated model's gravity torques at the commanded joints with the pose's
//! payload [N·m]. The compensated prediction is `E_s·(FK_cal(q + c∘τ) +
//! NN(q, τ))`. Units SI inside, mm in the report.
//!
//! Randomness: the final training draws from `ChaCha8Rng(seed)`, the fold
//! assignment from `ChaCha8Rng(seed + 1)`, fold `f`'s training from
//! `ChaCha8Rng(seed + 2 + f)`, the networks' subsample of a pool larger than
//! `max_network_poses` from `ChaCha8Rng(seed + 1000)`
//! (`CompensatorOptions::seed`): a calibration is reproducible bit for bit.

use super::cache::Cache;
use super::context::{Context, Outcome, Step};
use super::maps::base_fit;
use super::orientation_part::{note, train_orientation};
use super::plan::Planner;
use super::trained::{support_of, AppliedCompensator, Trained};
use super::{Compensated, Method, MethodError, MethodFailure};
use crate::calibrate::compensate::select::{run_jobs, FoldPlan, Jobs};
use crate::calibrate::compensate::{train, Sample, TrainError, TrainReport};
use crate::calibrate::identify::least_squares::Fit;
use crate::calibrate::identify::network::Network;
use crate::calibrate::identify::progress::Fold;
use crate::calibrate::identify::report::{
    predict_compensated, CompensatorSummary, MethodReport, MethodWarning, SetErrors,
    UncertaintyCheck, WarningKind,
};
use crate::measure::Measurement;
use crate::model::calibrated::Compensator;
use crate::model::calibrated::StoredCompensator;
use crate::model::kinematics::{chain, gravity_torques_of};
use crate::model::pose::Pose;
use crate::model::RobotModel;
use nalgebra::Matrix3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::sync::{Arc, Mutex};

/// Training samples of `data` on top of the fitted base (module docs).
pub(crate) fn samples(
    model: &RobotModel,
    frames: &[Pose],
    data: &[Measurement],
) -> Result<Vec<Sample>, MethodFailure> {
    data.iter()
        .enumerate()
        .map(|(i, m)| {
            let (p, _) = predict_compensated(model, None, m)
                .ok_or(MethodFailure::UnpredictableTrainingPose { pose: i + 1 })?;
            let c = chain(model, &m.q)
                .map_err(|cause| MethodFailure::TrainingPose { pose: i + 1, cause })?;
            let e = frames.get(m.session).copied().unwrap_or_default();
            Ok(Sample {
                q: m.q.clone(),
                tau: gravity_torques_of(model, &c, m.payload_mass),
                payload_kg: m.payload_mass,
                residual: e.inverse().transform_point(&m.position) - p,
            })
        })
        .collect()
}

/// Per pose of `data`, `R_measured·R_predictedᵀ` in the base frame of the
/// fitted base (`E_sᵀ·R_measured·R_predictedᵀ`, `compensate::oriented`);
/// `None` for a pose without a measured orientation.
pub(crate) fn rotations(
    model: &RobotModel,
    frames: &[Pose],
    data: &[Measurement],
) -> Vec<Option<Matrix3<f64>>> {
    data.iter()
        .map(|m| {
            let rm = m.orientation?;
            let (_, r) = predict_compensated(model, None, m)?;
            let e = frames.get(m.session).copied().unwrap_or_default();
            Some(e.r.transpose() * rm * r.transpose())
        })
        .collect()
}

fn train_error(e: TrainError) -> MethodError {
    match e {
        TrainError::Cancelled => MethodError::Cancelled,
        e => MethodError::Failed(MethodFailure::Training(e)),
    }
}

/// Trains `network` on the residuals of `base` on the context's training
/// pool, after a `folds`-fold cross-validation and the options' blocked folds
/// (none for `folds` = 0). `progress(stage, epoch, loss)` runs after every
/// epoch / iteration / generation, with stages before the last the
/// cross-validation's trainings and the last (`cv_stages(folds) - 1`) the
/// final training, and returns false to cancel.
pub(crate) fn train_network(
    network: Network,
    base: &Fit,
    ctx: &Context,
    folds: usize,
    progress: &mut dyn FnMut(usize, usize, f64) -> bool,
) -> Result<Trained, MethodError> {
    let spec = network.spec(&ctx.opts.compensator);
    let (pool, _) = ctx.pool();
    let mut data = samples(&base.model, &base.session_frames, pool)?;
    let mut turns = rotations(&base.model, &base.session_frames, pool);
    let cap = ctx.opts.compensator.max_network_poses;
    if !spec.every_pose() && cap > 0 && data.len() > cap {
        let mut rng = ChaCha8Rng::seed_from_u64(ctx.opts.compensator.seed.wrapping_add(1000));
        let keep = rand::seq::index::sample(&mut rng, data.len(), cap).into_vec();
        data = keep.iter().map(|i| data[*i].clone()).collect();
        turns = keep.iter().map(|i| turns[*i]).collect();
    }
    if spec.torque_input() && data.iter().all(|s| s.tau.iter().all(|t| *t == 0.0)) {
        return Err(MethodFailure::NoTorqueToLearn.into());
    }
    let seed = ctx.opts.compensator.seed;
    let last = ctx.opts.compensator.cv_stages(folds) - 1;
    // The folds' trainings and the final one run side by side; the final
    // training is the last job and reports as the last stage.
    let plan =
        (folds > 0).then(|| FoldPlan::draw(&data, folds, ctx.opts.compensator.blocked_folds));
    let cv_jobs = plan.as_ref().map_or(0, FoldPlan::trainings);
    let at = Mutex::new((0usize, 0.0f64));
    let outputs = run_jobs(
        cv_jobs + 1,
        Jobs {
            parallel: ctx.opts.compensator.parallel,
            progress: &mut |j, e, l| progress(if j < cv_jobs { j } else { last }, e, l),
            cancelled: || TrainError::Cancelled,
        },
        |j, report| match &plan {
            Some(plan) if j < cv_jobs => {
                let part = plan.training_set(&data, j);
                let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_add(2 + j as u64));
                let (c, _) = train(&spec, &part, &mut rng, report)?;
                Ok(JobOutput::Fold(
                    c.into_arc_supported(Some(support_of(&part))),
                ))
            }
            _ => {
                let mut rng = ChaCha8Rng::seed_from_u64(seed);
                let (stored, report) = train(&spec, &data, &mut rng, &mut |e, l| {
                    *at.lock().unwrap_or_else(|p| p.into_inner()) = (e, l);
                    report(e, l)
                })?;
                Ok(JobOutput::Final(Box::new((stored, report))))
            }
        },
    )
    .map_err(train_error)?;
    let mut fitted = Vec::with_capacity(cv_jobs);
    let mut last_training = None;
    for o in outputs {
        match o {
            JobOutput::Fold(c) => fitted.push(c),
            JobOutput::Final(f) => last_training = Some(*f),
        }
    }
    let cv = plan.map(|plan| plan.stats(&data, &fitted));
    let (stored, report) = last_training.expect("the final training is the last job");
    let (at_epoch, at_loss) = at.into_inner().unwrap_or_else(|p| p.into_inner());
    let (orientation, orientation_part) = train_orientation(
        &spec,
        &base.model,
        (&data, &turns),
        seed,
        folds,
        ctx.opts.compensator.parallel,
        &mut || progress(last, at_epoch, at_loss),
    )?;
    Ok(Trained {
        stored,
        orientation,
        orientation_part,
        support: support_of(&data),
        report,
        cv,
    })
}

/// What a job of [`train_network`] trained: a fold's compensator or the
/// final one with its report.
enum JobOutput {
    Fold(Arc<dyn Compensator>),
    Final(Box<(StoredCompensator, TrainReport)>),
}

/// `method`'s compensator `network` on the fit `base` and the training
/// pool, with `folds`-fold cross-validation, trained on first use (the
/// cache keeps it, or its failure, for the other methods of the run).
pub(crate) fn trained(
    ctx: &Context,
    cache: &mut Cache,
    method: Method,
    network: Network,
    base: &Fit,
    folds: usize,
    progress: &mut dyn FnMut(usize, usize, f64) -> bool,
) -> Result<Trained, MethodError> {
    if let Some(t) = cache.trained.get(&(method, folds)) {
        return t.clone().map_err(MethodError::Failed);
    }
    let r = match train_network(network, base, ctx, folds, progress) {
        Err(MethodError::Cancelled) => return Err(MethodError::Cancelled),
        Err(MethodError::Failed(f)) => Err(f),
        Ok(t) => Ok(t),
    };
    cache.trained.insert((method, folds), r.clone());
    r.map_err(MethodError::Failed)
}

/// A compensator method: its base (from the cache), then its compensator.
/// `progress(step)` with the step's fraction in [0, 1] of the work planned
/// for it (`plan::Planner`: the base fit unless cached, then its trainings)
/// and the fold it trains.
pub(crate) fn run_compensated(
    ctx: &Context,
    cache: &mut Cache,
    method: Method,
    c: Compensated,
    progress: &mut dyn FnMut(&Step) -> bool,
) -> Result<Outcome, MethodError> {
    let folds = ctx.opts.compensator.cv_folds;
    let mut plan = Planner::from_cache(cache);
    let base_units = plan.base(c.base);
    let train_units = plan.training(ctx, method, folds);
    let total = (base_units + train_units).max(f64::MIN_POSITIVE);
    let max_it = ctx.opts.lm.max_iterations.max(1) as f64;
    let mf = base_fit(ctx, cache, c.base, &mut |it, rms| {
        let f = base_units * (it as f64 / max_it).min(1.0) / total;
        progress(&Step::plain(f, it, Some(rms)))
    })
    .map_err(|e| match e {
        MethodError::Failed(cause) => MethodError::Failed(MethodFailure::BaseFailed {
            base: c.base.method(),
            cause: Box::new(cause),
        }),
        cancelled => cancelled,
    })?;
    let max = c.network.max_epochs(&ctx.opts.compensator) as f64;
    let stages = ctx.opts.compensator.cv_stages(folds);
    let t = trained(
        ctx,
        cache,
        method,
        c.network,
        &mf.fit,
        folds,
        &mut |stage, e, l| {
            let f = (stage as f64 + (e as f64 / max).min(1.0)) / stages as f64;
            progress(&Step {
                fold: Fold::of_stage(stage, stages),
                ..Step::plain((base_units + train_units * f) / total, e, Some(l))
            })
        },
    )?;
    Ok(Outcome {
        fit: mf,
        compensator: Some(AppliedCompensator {
            method,
            base: c.base,
            trained: t,
        }),
        auto: None,
    })
}

/// The base's report turned into the compensated method's: errors on every
/// set through the compensated prediction, the base's next to them, and the
/// compensator's summary. `training` is the Q2 pool (empty: none given).
pub(crate) fn compensate_report(
    report: &mut MethodReport,
    applied: &AppliedCompensator,
    frames: &[Pose],
    ident: &[Measurement],
    training: &[Measurement],
    valid: &[Measurement],
) {
    let trained = &applied.trained;
    let arc = trained
        .stored
        .clone()
        .into_arc_oriented(trained.orientation.clone(), Some(trained.support.clone()));
    let c: Option<&dyn Compensator> = Some(arc.as_ref());
    let model = report.calibrated.clone();
    let base_identification = report.identification.stats.clone();
    let base_validation = report.validation.as_ref().map(|v| v.stats.clone());
    report.identification = SetErrors::of_compensated(&model, c, frames, ident);
    if !valid.is_empty() {
        report.validation = Some(SetErrors::of_compensated(&model, c, frames, valid));
    }
    let base_training = report.training.as_ref().map(|t| t.stats.clone());
    if !training.is_empty() {
        report.training = Some(SetErrors::of_compensated(&model, c, frames, training));
    }
    let uncertainty = report.validation.as_ref().and_then(|v| {
        let u: Option<Vec<f64>> = valid
            .iter()
            .map(|m| arc.uncertainty(&m.q).map(|u| u.compensated_m * 1e3))
            .collect();
        let u = u.filter(|u| u.len() == v.errors_mm.len())?;
        UncertaintyCheck::of(&u, &v.errors_mm)
    });
    let shape = trained.stored.shape();
    report.compensator = Some(CompensatorSummary {
        base: applied.base.method(),
        kind: trained.stored.kind().into(),
        units: shape.units,
        inputs: shape.inputs,
        training: trained.report.clone(),
        trained_on: if training.is_empty() {
            "identification"
        } else {
            "training"
        }
        .into(),
        training_poses: if training.is_empty() {
            ident.len()
        } else {
            training.len()
        },
        cross_validation: trained.cv.clone(),
        base_identification,
        base_validation,
        base_training,
        trained_ranges_deg: trained
            .support
            .ranges_rad
            .iter()
            .map(|r| r.map(f64::to_degrees))
            .collect(),
        fade_deg: trained.support.fade_rad.to_degrees(),
        uncertainty,
        orientation_note: note(
            &trained.orientation_part,
            applied.base,
            ident
                .iter()
                .chain(training)
                .chain(valid)
                .any(|m| m.orientation.is_some()),
        ),
        orientation_part: trained.orientation_part.clone(),
    });
    if let Some(w) = report
        .compensator
        .as_ref()
        .and_then(|c| c.uncertainty.as_ref())
        .and_then(|u| u.warning())
    {
        report.warnings.push(MethodWarning {
            kind: WarningKind::UncertaintyOptimistic,
            joint: None,
            message: w,
        });
    }
    report.stored_compensator = Some(trained.stored.clone());
    report.stored_support = Some(trained.support.clone());
    report.stored_orientation = trained.orientation.clone();
}

/// Errors of the base alone on the pool (the residual norms [mm], and the
/// orientation errors [deg] where the pool measured orientation).
pub(crate) fn base_pool_errors(base: &Fit, pool: &[Measurement]) -> SetErrors {
    SetErrors::of(&base.model, &base.session_frames, pool)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::preset;
    use nalgebra::Vector3;

    /// A sample's residual is what the base leaves in the base frame of
    /// session 0: shifting a session-1 pose by its frame correction gives the
    /// same residual as the session-0 pose.
    #[test]
    fn samples_undo_the_session_frame() {
        let model = preset("ur10").unwrap();
        let q = vec![0.1, -0.7, 1.1, 0.3, -0.4, 0.2];
        let p = crate::model::kinematics::fk(&model, &q).unwrap().p;
        let offset = Vector3::new(1e-4, -2e-4, 3e-4);
        let mut frame = Pose::identity();
        frame.tr_x(0.01);
        frame.rot_z(0.02);
        let m0 = Measurement {
            q: q.clone(),
            position: p + offset,
            orientation: None,
            payload_mass: 0.0,
            session: 0,
            std: None,
        };
        let m1 = Measurement {
            position: frame.transform_point(&(p + offset)),
            session: 1,
            ..m0.clone()
        };
        let s = samples(&model, &[Pose::identity(), frame], &[m0, m1]).unwrap();
        assert!((s[0].residual - offset).norm() < 1e-12);
        assert!((s[1].residual - offset).norm() < 1e-12);
    }
}
