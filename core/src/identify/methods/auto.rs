//! `auto`: the base (KM or SKCM) with the compensator cross-validation
//! prefers, or the base alone.
//!
//! `auto` runs KM and (when gravity loads a joint) SKCM, cross-validates every
//! candidate compensator of each base on the training pool and keeps, per
//! base, the compensator `compensate::choose` accepts (cross-validated mean at
//! least `min_gain` below the base's, max not above) or the base alone; between
//! the bases it takes the lower cross-validated mean on the training pool. With
//! fewer than `min_training_poses` training poses it trains nothing and keeps
//! the base, saying so. The joint-map methods among the candidates are options
//! of their own: kept when their cross-validated mean (over the identification
//! and training poses, `identify::joint_maps`) is at least `min_gain` below the
//! geometry's alone on the same folds and their max not above; they then
//! compete with the bases by that cross-validated mean. On kept maps the
//! compensators built on them (`km-maps-gp`, `skcm-maps-gp`) are
//! cross-validated on what the maps leave and one is added when `choose`
//! accepts it against the maps alone; the option keeps the maps' mean.

use super::compensated::base_pool_stats;
use super::maps::run_maps;
use super::run::{AppliedCompensator, Cache, Context, MethodFit, Outcome};
use super::{Base, Compensated, Method, MethodError, MethodFailure, Run};
use crate::compensate::{choose, Choice, CvStats};
use crate::identify::least_squares::Fit;
use crate::identify::report::{AutoCandidate, AutoSummary};

/// One base as `auto` weighs it.
struct BaseOption {
    base: Base,
    /// The joint-map method whose fit this is, if any.
    maps: Option<Method>,
    fit: MethodFit,
    /// The compensator `choose` kept, if any.
    compensator: Option<AppliedCompensator>,
    /// Cross-validated mean on the pool [mm] (the base's residual mean when
    /// nothing was trained).
    mean_mm: f64,
    reason: String,
}

/// `auto` (module docs). Without gravity torques (`Context::gravity`) neither
/// SKCM nor the torque-input RBF is tried.
pub(crate) fn run_auto(
    ctx: &Context,
    cache: &mut Cache,
    progress: &mut dyn FnMut(f64, usize, Option<f64>) -> bool,
) -> Result<Outcome, MethodError> {
    let o = &ctx.opts.compensator;
    let (pool, pool_name) = ctx.pool();
    let gravity = ctx.gravity.as_ref();
    let folds = if o.cv_folds > 0 { o.cv_folds } else { 5 };
    let enough = pool.len() >= o.min_training_poses;
    let bases: Vec<Base> = if gravity.is_some() {
        vec![Base::Km]
    } else {
        vec![Base::Km, Base::Skcm]
    };
    let per_base: Vec<Vec<(Method, Compensated)>> = bases
        .iter()
        .map(|b| {
            o.auto_candidates
                .iter()
                .filter_map(|m| Some((*m, m.compensated()?)))
                .filter(|(m, c)| c.base == *b && (gravity.is_none() || !m.uses_torques()))
                .collect()
        })
        .collect();
    let maps_runs = bases
        .iter()
        .filter(|b| maps_candidate(&o.auto_candidates, **b).is_some())
        .count();
    let maps_compensators = o
        .auto_candidates
        .iter()
        .filter(|m| {
            m.compensated()
                .is_some_and(|c| matches!(c.base, Base::KmMaps | Base::SkcmMaps))
        })
        .count();
    let total = (per_base.iter().map(Vec::len).sum::<usize>() + maps_runs + maps_compensators)
        .max(1) as f64;
    let mut done = 0.0;
    let mut notes: Vec<String> = Vec::new();
    if let Some(why) = gravity {
        notes.push(format!("skcm and km-rbf not tried: {why}"));
    }
    let mut candidates = Vec::new();
    let mut options: Vec<BaseOption> = Vec::new();
    for (base, cands) in bases.iter().zip(&per_base) {
        let name = base.method().name();
        let mf = match cache.base_fit(ctx, *base, &mut |it, rms| {
            progress(done / total, it, Some(rms))
        }) {
            Ok(mf) => mf,
            Err(MethodError::Cancelled) => return Err(MethodError::Cancelled),
            Err(MethodError::Failed(f)) => {
                notes.push(format!("{name} failed: {f}"));
                done += cands.len() as f64;
                continue;
            }
        };
        let base_mean = base_pool_stats(&mf.fit, pool).mean_mm;
        if !enough {
            options.push(BaseOption {
                base: *base,
                maps: None,
                fit: mf,
                compensator: None,
                mean_mm: base_mean,
                reason: format!(
                    "{name}: only {} training poses (at least {} are needed to train and cross-validate a compensator), so the base stays",
                    pool.len(),
                    o.min_training_poses
                ),
            });
            continue;
        }
        let done0 = done;
        let (choice, picked) = cross_validate_and_choose(
            ctx,
            cache,
            cands,
            &mf.fit,
            folds,
            &mut candidates,
            &mut |x, e, l| progress((done0 + x) / total, e, l),
        )?;
        done += cands.len() as f64;
        let mean_mm = picked
            .as_ref()
            .and_then(|a| a.trained.cv.as_ref())
            .map_or(base_mean, |cv| cv.compensated.mean_mm);
        options.push(BaseOption {
            base: *base,
            maps: None,
            fit: mf,
            compensator: picked,
            mean_mm,
            reason: format!("{name}: {}", choice.reason),
        });
    }
    for base in &bases {
        let Some(method) = maps_candidate(&o.auto_candidates, *base) else {
            continue;
        };
        // The maps, then the compensators on them: a unit of the bar each,
        // whether they run or not.
        let (at, span) = (done / total, 1.0 / total);
        let on_maps_at = done + 1.0;
        done += 1.0 + on_maps_candidates(ctx, *base).len() as f64;
        let outcome = run_maps(ctx, cache, *base, &mut |f, it, l| {
            progress(at + span * f, it, l)
        });
        match outcome {
            Err(MethodError::Cancelled) => return Err(MethodError::Cancelled),
            Err(MethodError::Failed(f)) => {
                candidates.push(AutoCandidate {
                    method,
                    cross_validation: None,
                    failed: Some(f.to_string()),
                });
                notes.push(format!("{} failed: {f}", method.name()));
            }
            Ok(out) => {
                let fit = out.fit;
                let Some(m) = fit.maps.clone() else { continue };
                candidates.push(AutoCandidate {
                    method,
                    cross_validation: None,
                    failed: None,
                });
                let (with, without) = (&m.chosen, &m.without_maps);
                let gain = 1.0 - with.cv_mean_mm / without.cv_mean_mm;
                if m.maps.is_some() && gain >= o.min_gain && with.cv_max_mm <= without.cv_max_mm {
                    let on_maps = maps_compensator(
                        ctx,
                        cache,
                        *base,
                        &fit,
                        folds,
                        &mut candidates,
                        &mut |f, e, l| progress((on_maps_at + f) / total, e, l),
                    )?;
                    options.push(BaseOption {
                        base: *base,
                        maps: Some(method),
                        fit,
                        compensator: on_maps.kept,
                        mean_mm: with.cv_mean_mm,
                        reason: format!("{}{}", on_maps.reason, format_args!(
                            "{}: {} harmonics cross-validated over {} poses at {:.4} / {:.4} mm mean / max against {:.4} / {:.4} without maps",
                            method.name(),
                            with.harmonics,
                            m.poses,
                            with.cv_mean_mm,
                            with.cv_max_mm,
                            without.cv_mean_mm,
                            without.cv_max_mm
                        )),
                    });
                } else {
                    notes.push(format!(
                        "{} not kept: cross-validated {:.4} / {:.4} mm mean / max against {:.4} / {:.4} without maps (needs {:.0} % lower mean and no higher max)",
                        method.name(),
                        with.cv_mean_mm,
                        with.cv_max_mm,
                        without.cv_mean_mm,
                        without.cv_max_mm,
                        o.min_gain * 100.0
                    ));
                }
            }
        }
    }
    let best = options
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.mean_mm.total_cmp(&b.1.mean_mm))
        .map(|(i, _)| i)
        .ok_or_else(|| MethodFailure::NoBaseSucceeded {
            notes: notes.clone(),
        })?;
    let reasons: Vec<String> = options.iter().map(|o| o.reason.clone()).collect();
    let best = options.swap_remove(best);
    let chosen = match (&best.compensator, best.maps) {
        (Some(a), _) => a.method,
        (None, Some(m)) => m,
        (None, None) => best.base.method(),
    };
    let mut reason = format!(
        "{}: the lowest {} mean on the {pool_name} poses ({:.4} mm) — {}",
        chosen.name(),
        if best.compensator.is_some() || best.maps.is_some() || enough {
            "cross-validated"
        } else {
            "residual"
        },
        best.mean_mm,
        reasons.join("; ")
    );
    if !notes.is_empty() {
        reason.push_str(&format!("; {}", notes.join("; ")));
    }
    Ok(Outcome {
        fit: best.fit,
        compensator: best.compensator,
        auto: Some(AutoSummary {
            chosen,
            reason,
            candidates,
        }),
    })
}

/// What `auto` made of the compensators on a kept joint-map fit.
struct OnMaps {
    kept: Option<AppliedCompensator>,
    /// The choice, as a prefix of the maps' reason (empty: none tried).
    reason: String,
}

/// The candidate compensators on the joint-map fit of `base`.
fn on_maps_candidates(ctx: &Context, base: Base) -> Vec<(Method, Compensated)> {
    let on = if base == Base::Km {
        Base::KmMaps
    } else {
        Base::SkcmMaps
    };
    ctx.opts
        .compensator
        .auto_candidates
        .iter()
        .filter_map(|m| Some((*m, m.compensated()?)))
        .filter(|(_, c)| c.base == on)
        .collect()
}

/// Cross-validates the candidate compensators on the joint-map fit of `base`
/// (their residuals) and keeps the one `choose` accepts against the maps
/// alone on the same pool. The option keeps the maps' own cross-validated
/// mean for the comparison with the other bases.
fn maps_compensator(
    ctx: &Context,
    cache: &mut Cache,
    base: Base,
    fit: &MethodFit,
    folds: usize,
    candidates: &mut Vec<AutoCandidate>,
    progress: &mut dyn FnMut(f64, usize, Option<f64>) -> bool,
) -> Result<OnMaps, MethodError> {
    let methods = on_maps_candidates(ctx, base);
    if methods.is_empty() {
        return Ok(OnMaps {
            kept: None,
            reason: String::new(),
        });
    }
    let (choice, kept) =
        cross_validate_and_choose(ctx, cache, &methods, &fit.fit, folds, candidates, progress)?;
    Ok(OnMaps {
        kept,
        reason: format!("on {}: {}; ", base.method().name(), choice.reason),
    })
}

/// Trains and cross-validates each compensator method on `fit`'s residuals,
/// lists each as an `auto` candidate, and keeps the one `choose` accepts.
/// `progress(x, epoch, loss)` with `x` in methods done (fractional).
fn cross_validate_and_choose(
    ctx: &Context,
    cache: &mut Cache,
    methods: &[(Method, Compensated)],
    fit: &Fit,
    folds: usize,
    candidates: &mut Vec<AutoCandidate>,
    progress: &mut dyn FnMut(f64, usize, Option<f64>) -> bool,
) -> Result<(Choice, Option<AppliedCompensator>), MethodError> {
    let o = &ctx.opts.compensator;
    let stages = o.cv_stages(folds) as f64;
    let mut cvs: Vec<(String, CvStats)> = Vec::new();
    let mut trained: Vec<AppliedCompensator> = Vec::new();
    for (i, (m, c)) in methods.iter().enumerate() {
        let max = o.max_epochs(c.network) as f64;
        let r = cache.trained(ctx, *m, c.network, fit, folds, &mut |stage, e, l| {
            let f = (stage as f64 + (e as f64 / max).min(1.0)) / stages;
            progress(i as f64 + f, e, Some(l))
        });
        match r {
            Ok(t) => {
                let cv = t.cv.clone().expect("auto cross-validates");
                candidates.push(AutoCandidate {
                    method: *m,
                    cross_validation: Some(cv.clone()),
                    failed: None,
                });
                cvs.push((m.name().to_string(), cv));
                trained.push(AppliedCompensator {
                    method: *m,
                    base: c.base,
                    trained: t,
                });
            }
            Err(MethodError::Cancelled) => return Err(MethodError::Cancelled),
            Err(MethodError::Failed(f)) => candidates.push(AutoCandidate {
                method: *m,
                cross_validation: None,
                failed: Some(f.to_string()),
            }),
        }
    }
    let choice = choose(&cvs, o.min_gain);
    let picked = choice
        .chosen
        .as_deref()
        .and_then(|chosen| trained.into_iter().find(|a| a.method.name() == chosen));
    Ok((choice, picked))
}

/// The joint-map method on `base` among `auto`'s candidates.
fn maps_candidate(candidates: &[Method], base: Base) -> Option<Method> {
    candidates
        .iter()
        .copied()
        .find(|m| m.row().run == Run::Maps(base))
}
