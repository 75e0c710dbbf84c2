//! The compensator methods of the pipeline (seed ch. 3–6) and `auto`.
//!
//! A compensator method fits its model-based base (KM for `km-rbf`, SKCM for
//! `skcm-nn`, `skcm-iwonn`, `skcm-tlbonn`), then trains a compensator
//! ([`compensate::train`](crate::compensate::train)) on the residuals the base
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
//! `ChaCha8Rng(seed + 2 + f)` (`CompensatorOptions::seed`): a calibration is
//! reproducible bit for bit.
//!
//! `auto` runs KM and (when gravity loads a joint) SKCM, cross-validates every
//! candidate compensator of each base on the training pool and keeps, per
//! base, the compensator `compensate::choose` accepts (cross-validated mean at
//! least `min_gain` below the base's, max not above) or the base alone; between
//! the bases it takes the lower cross-validated mean on the training pool. With
//! fewer than `min_training_poses` training poses it trains nothing and keeps
//! the base, saying so.

use super::least_squares::Fit;
use super::methods::{Context, MethodError, MethodFit};
use super::options::{CalibrationOptions, Method};
use super::report::{
    predict_compensated, AutoCandidate, AutoSummary, CompensatorSummary, MethodReport, SetErrors,
};
use crate::compensate::{
    choose, cross_validate, train, Compensator, CvStats, Sample, StoredCompensator, TrainError,
    TrainReport,
};
use crate::kinematics::{chain, gravity_torques_of};
use crate::measure::Measurement;
use crate::model::pose::Pose;
use crate::model::RobotModel;
use crate::stats::ErrorStats;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::collections::BTreeMap;
use std::sync::Arc;

/// A trained compensator with its training report and cross-validation.
#[derive(Clone)]
pub(crate) struct Trained {
    pub stored: StoredCompensator,
    pub report: TrainReport,
    pub cv: Option<CvStats>,
}

/// Training samples of `data` on top of the fitted base (module docs).
pub(crate) fn samples(
    model: &RobotModel,
    frames: &[Pose],
    data: &[Measurement],
) -> Result<Vec<Sample>, String> {
    data.iter()
        .enumerate()
        .map(|(i, m)| {
            let p = predict_compensated(model, None, m)
                .ok_or_else(|| format!("the base model cannot predict training pose {}", i + 1))?;
            let c = chain(model, &m.q).map_err(|e| format!("training pose {}: {e}", i + 1))?;
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

fn train_error(e: TrainError) -> MethodError {
    match e {
        TrainError::Cancelled => MethodError::Cancelled,
        TrainError::Data(s) => MethodError::Failed(s),
    }
}

/// Trains `method`'s compensator on the residuals of `base` on `pool`, after a
/// `folds`-fold cross-validation (none for `folds` = 0). `progress(stage,
/// epoch, loss)` runs after every epoch / iteration / generation, with stage
/// `0..folds` the cross-validation folds and `folds` the final training, and
/// returns false to cancel.
pub(crate) fn train_method(
    method: Method,
    base: &Fit,
    pool: &[Measurement],
    opts: &CalibrationOptions,
    folds: usize,
    progress: &mut dyn FnMut(usize, usize, f64) -> bool,
) -> Result<Trained, MethodError> {
    let spec = opts
        .compensator
        .spec(method)
        .ok_or_else(|| MethodError::Failed(format!("{} has no compensator", method.name())))?;
    let data = samples(&base.model, &base.session_frames, pool).map_err(MethodError::Failed)?;
    if method == Method::KmRbf && data.iter().all(|s| s.tau.iter().all(|t| *t == 0.0)) {
        return Err(MethodError::Failed(
            "the model has no masses, so every gravity torque is zero and the torque-input RBF has nothing to learn from; use skcm-nn or km".into(),
        ));
    }
    let seed = opts.compensator.seed;
    let cv = if folds > 0 {
        let mut fold_rng = ChaCha8Rng::seed_from_u64(seed.wrapping_add(1));
        let mut stage = 0usize;
        let cv = cross_validate(&data, folds, &mut fold_rng, |part| {
            let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_add(2 + stage as u64));
            let s = stage;
            stage += 1;
            let (c, _) = train(&spec, part, &mut rng, &mut |e, l| progress(s, e, l))?;
            Ok::<_, TrainError>(c.into_arc() as Arc<dyn Compensator>)
        })
        .map_err(train_error)?;
        Some(cv)
    } else {
        None
    };
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (stored, report) =
        train(&spec, &data, &mut rng, &mut |e, l| progress(folds, e, l)).map_err(train_error)?;
    Ok(Trained { stored, report, cv })
}

/// Describes the network's inputs.
fn inputs_of(c: &StoredCompensator) -> (String, usize, String) {
    match c {
        StoredCompensator::Mlp(m) => {
            let mut s = String::from("q");
            if m.features.sin_cos {
                s.push_str(", sin q, cos q");
            }
            if m.features.payload {
                s.push_str(", payload mass");
            }
            ("mlp".into(), m.hidden, s)
        }
        StoredCompensator::Rbf(r) => ("rbf".into(), r.units(), "gravity torques".into()),
    }
}

/// The base's report turned into the compensated method's: errors on every
/// set through the compensated prediction, the base's next to them, and the
/// compensator's summary. `training` is the Q2 pool (empty: none given).
pub(crate) fn compensate_report(
    report: &mut MethodReport,
    base: Method,
    frames: &[Pose],
    trained: &Trained,
    ident: &[Measurement],
    training: &[Measurement],
    valid: &[Measurement],
) {
    let arc = trained.stored.clone().into_arc();
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
    let (kind, units, inputs) = inputs_of(&trained.stored);
    report.compensator = Some(CompensatorSummary {
        base,
        kind,
        units,
        inputs,
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
    });
    report.stored_compensator = Some(trained.stored.clone());
}

/// Error statistics of the base alone on the pool [mm] (the residual norms).
pub(crate) fn base_pool_stats(base: &Fit, pool: &[Measurement]) -> ErrorStats {
    SetErrors::of(&base.model, &base.session_frames, pool).stats
}

/// Fits and trained compensators shared by the methods of one run: a base or
/// a compensator needed by several methods is computed once (a failure too).
#[derive(Default)]
pub(crate) struct Cache {
    pub km: Option<Fit>,
    pub skcm: Option<Result<MethodFit, String>>,
    trained: BTreeMap<(Method, usize), Result<Trained, String>>,
}

impl Cache {
    /// The fit of a base method (`km` or `skcm`), computed on first use.
    pub fn base_fit(
        &mut self,
        ctx: &Context,
        base: Method,
        progress: &mut dyn FnMut(usize, f64) -> bool,
    ) -> Result<MethodFit, MethodError> {
        match base {
            Method::Km => {
                if self.km.is_none() {
                    self.km = Some(ctx.km(progress)?);
                }
                Ok(MethodFit {
                    fit: self.km.clone().expect("set above"),
                    ids: ctx.kept_geo.clone(),
                    tlbo: None,
                    not_identified: vec![],
                })
            }
            _ => {
                if self.skcm.is_none() {
                    match ctx.skcm(progress) {
                        Ok(mf) => self.skcm = Some(Ok(mf)),
                        Err(MethodError::Failed(s)) => self.skcm = Some(Err(s)),
                        Err(MethodError::Cancelled) => return Err(MethodError::Cancelled),
                    }
                }
                self.skcm
                    .clone()
                    .expect("set above")
                    .map_err(MethodError::Failed)
            }
        }
    }

    /// `method`'s compensator on `base` and `pool` with `folds`-fold
    /// cross-validation, trained on first use.
    pub fn trained(
        &mut self,
        ctx: &Context,
        method: Method,
        base: &Fit,
        pool: &[Measurement],
        folds: usize,
        progress: &mut dyn FnMut(usize, usize, f64) -> bool,
    ) -> Result<Trained, MethodError> {
        if let Some(t) = self.trained.get(&(method, folds)) {
            return t.clone().map_err(MethodError::Failed);
        }
        match train_method(method, base, pool, ctx.opts, folds, progress) {
            Err(MethodError::Cancelled) => Err(MethodError::Cancelled),
            r => {
                let r = r.map_err(|e| match e {
                    MethodError::Failed(s) => s,
                    MethodError::Cancelled => unreachable!(),
                });
                self.trained.insert((method, folds), r.clone());
                r.map_err(MethodError::Failed)
            }
        }
    }
}

/// What a compensator method or `auto` delivers before it is reported.
pub(crate) struct Hybrid {
    pub base: MethodFit,
    /// The compensator on top, with its base method.
    pub compensator: Option<(Method, Trained)>,
    pub auto: Option<AutoSummary>,
}

/// A compensator method: its base (from the cache), then its compensator.
/// `progress(fraction, iteration, loss)` with `fraction` in [0, 1].
pub(crate) fn run_compensated(
    ctx: &Context,
    cache: &mut Cache,
    method: Method,
    pool: &[Measurement],
    progress: &mut dyn FnMut(f64, usize, Option<f64>) -> bool,
) -> Result<Hybrid, MethodError> {
    let base = method.base().expect("a compensator method");
    let mf = cache
        .base_fit(ctx, base, &mut |it, rms| progress(0.0, it, Some(rms)))
        .map_err(|e| match e {
            MethodError::Failed(s) => {
                MethodError::Failed(format!("its base method {} failed: {s}", base.name()))
            }
            c => c,
        })?;
    let folds = ctx.opts.compensator.cv_folds;
    let max = ctx.opts.compensator.max_epochs(method) as f64;
    let stages = (folds + 1) as f64;
    let t = cache.trained(ctx, method, &mf.fit, pool, folds, &mut |stage, e, l| {
        let f = (stage as f64 + (e as f64 / max).min(1.0)) / stages;
        progress(0.05 + 0.95 * f, e, Some(l))
    })?;
    Ok(Hybrid {
        base: mf,
        compensator: Some((method, t)),
        auto: None,
    })
}

/// One base as `auto` weighs it: (base, its fit, the compensator `choose`
/// kept, cross-validated mean on the pool [mm], why).
type AutoOption = (Method, MethodFit, Option<(Method, Trained)>, f64, String);

/// `auto` (module docs). `gravity` is why no joint is loaded, if so (then
/// neither SKCM nor the torque-input RBF is tried).
pub(crate) fn run_auto(
    ctx: &Context,
    cache: &mut Cache,
    pool: &[Measurement],
    pool_name: &str,
    gravity: Option<&str>,
    progress: &mut dyn FnMut(f64, usize, Option<f64>) -> bool,
) -> Result<Hybrid, MethodError> {
    let o = &ctx.opts.compensator;
    let folds = if o.cv_folds > 0 { o.cv_folds } else { 5 };
    let enough = pool.len() >= o.min_training_poses;
    let bases: Vec<Method> = if gravity.is_some() {
        vec![Method::Km]
    } else {
        vec![Method::Km, Method::Skcm]
    };
    let per_base: Vec<Vec<Method>> = bases
        .iter()
        .map(|b| {
            o.auto_candidates
                .iter()
                .copied()
                .filter(|m| m.base() == Some(*b) && (gravity.is_none() || !m.uses_torques()))
                .collect()
        })
        .collect();
    let total = per_base.iter().map(Vec::len).sum::<usize>().max(1) as f64;
    let max_stages = (folds + 1) as f64;
    let mut done = 0.0;
    let mut notes: Vec<String> = Vec::new();
    if let Some(why) = gravity {
        notes.push(format!("skcm and km-rbf not tried: {why}"));
    }
    let mut candidates = Vec::new();
    let mut options: Vec<AutoOption> = Vec::new();
    for (base, cands) in bases.iter().zip(&per_base) {
        let mf = match cache.base_fit(ctx, *base, &mut |it, rms| {
            progress(done / total, it, Some(rms))
        }) {
            Ok(mf) => mf,
            Err(MethodError::Cancelled) => return Err(MethodError::Cancelled),
            Err(MethodError::Failed(s)) => {
                notes.push(format!("{} failed: {s}", base.name()));
                done += cands.len() as f64;
                continue;
            }
        };
        let base_mean = base_pool_stats(&mf.fit, pool).mean_mm;
        if !enough {
            options.push((
                *base,
                mf,
                None,
                base_mean,
                format!(
                    "{}: only {} training poses (at least {} are needed to train and cross-validate a compensator), so the base stays",
                    base.name(),
                    pool.len(),
                    o.min_training_poses
                ),
            ));
            continue;
        }
        let mut cvs: Vec<(String, CvStats)> = Vec::new();
        let mut trained: Vec<(Method, Trained)> = Vec::new();
        for m in cands {
            let max = o.max_epochs(*m) as f64;
            let at = done;
            let r = cache.trained(ctx, *m, &mf.fit, pool, folds, &mut |stage, e, l| {
                let f = (stage as f64 + (e as f64 / max).min(1.0)) / max_stages;
                progress((at + f) / total, e, Some(l))
            });
            done += 1.0;
            match r {
                Ok(t) => {
                    let cv = t.cv.clone().expect("auto cross-validates");
                    candidates.push(AutoCandidate {
                        method: *m,
                        cross_validation: Some(cv.clone()),
                        failed: None,
                    });
                    cvs.push((m.name().to_string(), cv));
                    trained.push((*m, t));
                }
                Err(MethodError::Cancelled) => return Err(MethodError::Cancelled),
                Err(MethodError::Failed(s)) => candidates.push(AutoCandidate {
                    method: *m,
                    cross_validation: None,
                    failed: Some(s),
                }),
            }
        }
        let choice = choose(&cvs, o.min_gain);
        let picked = choice
            .chosen
            .as_deref()
            .and_then(|name| trained.into_iter().find(|(m, _)| m.name() == name));
        let mean = picked
            .as_ref()
            .and_then(|(_, t)| t.cv.as_ref())
            .map_or(base_mean, |cv| cv.compensated.mean_mm);
        options.push((
            *base,
            mf,
            picked,
            mean,
            format!("{}: {}", base.name(), choice.reason),
        ));
    }
    let best = options
        .iter()
        .enumerate()
        .min_by(|a, b| a.1 .3.total_cmp(&b.1 .3))
        .map(|(i, _)| i)
        .ok_or_else(|| {
            MethodError::Failed(format!("no base method succeeded: {}", notes.join("; ")))
        })?;
    let reasons: Vec<String> = options.iter().map(|o| o.4.clone()).collect();
    let (base, mf, picked, mean, _) = options.swap_remove(best);
    let chosen = picked.as_ref().map_or(base, |(m, _)| *m);
    let mut reason = format!(
        "{}: the lowest {} mean on the {pool_name} poses ({mean:.4} mm) — {}",
        chosen.name(),
        if picked.is_some() || enough {
            "cross-validated"
        } else {
            "residual"
        },
        reasons.join("; ")
    );
    if !notes.is_empty() {
        reason.push_str(&format!("; {}", notes.join("; ")));
    }
    Ok(Hybrid {
        base: mf,
        compensator: picked,
        auto: Some(AutoSummary {
            chosen,
            reason,
            candidates,
        }),
    })
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
        let p = crate::kinematics::fk(&model, &q).unwrap().p;
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
