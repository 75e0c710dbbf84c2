//! `auto`: the base (KM or SKCM) with the compensator cross-validation
//! prefers, or the base alone.
//!
//! `auto` runs KM and (when gravity loads a joint) SKCM, cross-validates every
//! candidate compensator of each base on the training pool and keeps, per
//! base, the compensator `compensate::choose` accepts (cross-validated mean at
//! least `min_gain` below the base's, max not above) or the base alone.
//! Between the options (each base with what it kept, and the kept joint maps
//! below) it chooses by the tie rule (`methods::ties`: cross-validated means
//! within `tie_margin` of each other are a tie, broken by the spatially
//! blocked folds, the max, the physics of the base, the fewer fitted
//! quantities), and never delivers an option on the weaker base while one
//! on the better base is there (`auto_choice`). The option chosen is then
//! judged as delivered on spatially blocked regions against its base alone,
//! and vetoed when it extrapolates worse (`methods::veto`,
//! `auto_choice::apply_veto`): `auto` falls to the next option. With
//! fewer than `min_training_poses` training poses it trains nothing and keeps
//! the base, saying so. The joint-map methods among the candidates are options
//! of their own: kept when their cross-validated mean (over the identification
//! and training poses, `identify::joint_maps`) is at least `min_gain` below the
//! geometry's alone on the same folds and their max not above; they then
//! compete with the bases by that cross-validated mean and their blocked
//! folds (`joint_maps::BlockedMaps`). On kept maps the
//! compensators built on them (`km-maps-gp`, `skcm-maps-gp`) are
//! cross-validated on what the maps leave and one is added when `choose`
//! accepts it against the maps alone; the option keeps the maps' mean.
//!
//! Orientation: when the pool measured orientation, `auto` scores it too, and
//! a method that gains position but loses orientation is not chosen. Joint
//! maps are kept only when their cross-validated orientation mean is not
//! above the geometry's alone on the same folds by more than
//! [`ORIENTATION_SLACK`] (relative); and between the options only those whose
//! orientation mean on the pool is within [`ORIENTATION_SLACK`] of the lowest
//! compete by position ([`choose_option`]). A kept compensator's
//! orientation part (`compensate::oriented`) is cross-validated on the same
//! folds as its position part (`methods::orientation_part`) and kept only
//! when its cross-validated orientation mean is at least `min_gain` below
//! the base's on the same poses; the option is then scored by that
//! cross-validated mean, else the part is dropped (the reason says so,
//! `AutoSummary::orientation_part` is `not_kept`) and the option scores its
//! base's (or maps') orientation on the pool.

use super::auto_choice::{apply_veto, choose_among, decide};
use super::auto_tally::{BaseOption, Tally, ORIENTATION_SLACK};
use super::cache::Cache;
use super::compensated::{self, base_pool_errors};
use super::context::{Context, MethodFit, Outcome, Step};
use super::maps::base_fit;
use super::maps::run_maps;
use super::orientation_part::settle_for_auto;
use super::plan::Planner;
use super::trained::AppliedCompensator;
use super::{Base, Compensated, Method, MethodError, Run};
use crate::calibrate::compensate::{choose, Choice, CvStats};
use crate::calibrate::identify::least_squares::Fit;
use crate::calibrate::identify::progress::Fold;
use crate::calibrate::identify::report::{
    AutoCandidate, OrientationPart, OrientationPartStatus, SetErrors,
};

/// The pose-weighted mean of a cross-validation's blocked folds [mm], if
/// they ran.
fn blocked_mean(cv: &CvStats) -> Option<f64> {
    let poses: usize = cv.blocked.iter().map(|f| f.poses).sum();
    (poses > 0).then(|| {
        cv.blocked
            .iter()
            .map(|f| f.compensated_mean_mm * f.poses as f64)
            .sum::<f64>()
            / poses as f64
    })
}

/// The orientation mean of `errors` [deg], if the set measured any.
fn orientation_mean(errors: &SetErrors) -> Option<f64> {
    errors.orientation.as_ref().map(|o| o.mean_deg)
}

/// `auto` (module docs). Without gravity torques (`Context::gravity`) neither
/// SKCM nor the torque-input RBF is tried.
pub(crate) fn run_auto(
    ctx: &Context,
    cache: &mut Cache,
    progress: &mut dyn FnMut(&Step) -> bool,
) -> Result<Outcome, MethodError> {
    let o = &ctx.opts.compensator;
    let gravity = ctx.gravity.as_ref();
    let plan = Planner::from_cache(cache);
    let folds = if o.cv_folds > 0 { o.cv_folds } else { 5 };
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
    let total = plan.clone().auto(ctx).max(f64::MIN_POSITIVE);
    let mut t = Tally {
        progress,
        done: 0.0,
        total,
        plan,
        notes: gravity
            .map(|why| format!("skcm and km-rbf not tried: {why}"))
            .into_iter()
            .collect(),
        candidates: Vec::new(),
        options: Vec::new(),
        geometry_blocked: Vec::new(),
        vetoed: Vec::new(),
    };
    for (base, cands) in bases.iter().zip(&per_base) {
        base_option(ctx, cache, &mut t, *base, cands, folds)?;
    }
    for base in &bases {
        if let Some(method) = maps_candidate(&o.auto_candidates, *base) {
            maps_option(ctx, cache, &mut t, *base, method, folds)?;
        }
    }
    let mut decision = decide(ctx, &t)?;
    if let Some(method) = decision.untried.take() {
        offer(ctx, cache, &mut t, method, folds)?;
        decision = decide(ctx, &t)?;
        decision.untried = None;
    }
    let decision = apply_veto(ctx, cache, &mut t, decision)?;
    choose_among(ctx, t, decision)
}

/// Trains `method`, the counterpart on the better base of an option set
/// aside (`auto_choice`), and adds it as an option when it is kept.
fn offer(
    ctx: &Context,
    cache: &mut Cache,
    t: &mut Tally,
    method: Method,
    folds: usize,
) -> Result<(), MethodError> {
    t.total += 1.0 + on_maps_candidates(ctx, Base::SkcmMaps).len() as f64;
    match method.row().run {
        Run::Maps(base) => maps_option(ctx, cache, t, base, method, folds),
        Run::Compensated(c) if matches!(c.base, Base::Km | Base::Skcm) => {
            let before = t.options.len();
            base_option(ctx, cache, t, c.base, &[(method, c)], folds)?;
            if t.options.len() > before && t.options[before].compensator.is_none() {
                let dropped = t.options.remove(before);
                t.notes.push(format!(
                    "{} offered on {}: {}",
                    method.name(),
                    c.base.method().name(),
                    dropped.reason
                ));
            }
            Ok(())
        }
        _ => Ok(()),
    }
}

/// Fits `base` and, with enough training poses, cross-validates its
/// compensator candidates `cands`; adds the base with the compensator
/// `choose` keeps (or alone) to the options. A failed base is a note.
fn base_option(
    ctx: &Context,
    cache: &mut Cache,
    t: &mut Tally,
    base: Base,
    cands: &[(Method, Compensated)],
    folds: usize,
) -> Result<(), MethodError> {
    let o = &ctx.opts.compensator;
    let (pool, _) = ctx.pool();
    let name = base.method().name();
    let (done, total) = (t.done, t.total);
    let fit_units = t.plan.base(base);
    let max_it = ctx.opts.lm.max_iterations.max(1) as f64;
    let progress = &mut *t.progress;
    let fitted = base_fit(ctx, cache, base, &mut |it, rms| {
        let f = (done + fit_units * (it as f64 / max_it).min(1.0)) / total;
        progress(&Step {
            candidate: Some(base.method()),
            ..Step::plain(f, it, Some(rms))
        })
    });
    t.done += fit_units;
    let spans = candidate_spans(ctx, &mut t.plan, cands, folds);
    let mf = match fitted {
        Ok(mf) => mf,
        Err(MethodError::Cancelled) => return Err(MethodError::Cancelled),
        Err(MethodError::Failed(f)) => {
            t.notes.push(format!("{name} failed: {f}"));
            t.done += spans.units;
            return Ok(());
        }
    };
    let base_errors = base_pool_errors(&mf.fit, pool);
    let base_mean = base_errors.stats.mean_mm;
    let base_max = base_errors.stats.max_mm;
    let orientation_deg = orientation_mean(&base_errors);
    // The base alone is not fitted on a separate training pool: its error
    // there is its error in every held-out region of it.
    let alone_blocked = (!ctx.training.is_empty()).then_some(base_mean);
    if pool.len() < o.min_training_poses {
        t.done += spans.units;
        t.options.push(BaseOption {
            base,
            maps: None,
            fit: mf,
            compensator: None,
            mean_mm: base_mean,
            max_mm: base_max,
            blocked_mm: alone_blocked,
            alone_mm: Some(base_mean),
            orientation_deg,
            orientation_part: None,
            reason: format!(
                "{name}: only {} training poses (at least {} are needed to train and cross-validate a compensator), so the base stays",
                pool.len(),
                o.min_training_poses
            ),
        });
        return Ok(());
    }
    let (choice, picked, settled) = cross_validate_and_choose(
        ctx,
        cache,
        cands,
        &mf.fit,
        folds,
        &mut t.candidates,
        &mut |s| progress(&spans.step(t.done, total, s)),
    )?;
    t.done += spans.units;
    let cv = picked.as_ref().and_then(|a| a.trained.cv.as_ref());
    let mean_mm = cv.map_or(base_mean, |cv| cv.compensated.mean_mm);
    let max_mm = cv.map_or(base_max, |cv| cv.compensated.max_mm);
    let blocked_mm = cv.map_or(alone_blocked, blocked_mean);
    if let Some((_, Some(dropped))) = &settled {
        t.notes.push(dropped.clone());
    }
    t.options.push(BaseOption {
        base,
        maps: None,
        fit: mf,
        compensator: picked,
        mean_mm,
        max_mm,
        blocked_mm,
        alone_mm: Some(base_mean),
        orientation_deg: option_orientation(orientation_deg, &settled),
        orientation_part: settled.map(|s| s.0),
        reason: format!("{name}: {}", choice.reason),
    });
    Ok(())
}

/// Runs the joint-map method `method` on `base`; when its maps are kept
/// (module docs), cross-validates the compensators on them and adds the
/// option. The maps, then the compensators on them, are a unit of the bar
/// each, whether they run or not.
fn maps_option(
    ctx: &Context,
    cache: &mut Cache,
    t: &mut Tally,
    base: Base,
    method: Method,
    folds: usize,
) -> Result<(), MethodError> {
    let o = &ctx.opts.compensator;
    let (pool, _) = ctx.pool();
    let total = t.total;
    let at = t.done;
    let maps_units = t.plan.base(if base == Base::Km {
        Base::KmMaps
    } else {
        Base::SkcmMaps
    });
    let on_maps_at = at + maps_units;
    let spans = candidate_spans(ctx, &mut t.plan, &on_maps_candidates(ctx, base), folds);
    t.done = on_maps_at + spans.units;
    let progress = &mut *t.progress;
    let fit = match run_maps(ctx, cache, base, &mut |f, it, l| {
        progress(&Step {
            candidate: Some(method),
            ..Step::plain((at + maps_units * f) / total, it, l)
        })
    }) {
        Err(MethodError::Cancelled) => return Err(MethodError::Cancelled),
        Err(MethodError::Failed(f)) => {
            t.candidates.push(AutoCandidate {
                method,
                cross_validation: None,
                failed: Some(f.to_string()),
                orientation_cross_validation: None,
            });
            t.notes.push(format!("{} failed: {f}", method.name()));
            return Ok(());
        }
        Ok(out) => out.fit,
    };
    let Some(m) = fit.maps.clone() else {
        return Ok(());
    };
    if let Some(b) = &m.blocked {
        t.geometry_blocked.push((base, b.without_maps_mm));
    }
    t.candidates.push(AutoCandidate {
        method,
        cross_validation: None,
        failed: None,
        orientation_cross_validation: None,
    });
    let (with, without) = (&m.chosen, &m.without_maps);
    let gain = 1.0 - with.cv_mean_mm / without.cv_mean_mm;
    let orientation_loss = match (
        with.cv_orientation_mean_deg,
        without.cv_orientation_mean_deg,
    ) {
        (Some(a), Some(b)) if a > b * (1.0 + ORIENTATION_SLACK) => Some((a, b)),
        _ => None,
    };
    if let (Some((a, b)), true) = (orientation_loss, m.maps.is_some()) {
        t.notes.push(format!(
            "{} not kept: it loses orientation, cross-validated {a:.4}° mean against {b:.4}° without maps (more than {:.0} % above)",
            method.name(),
            ORIENTATION_SLACK * 100.0
        ));
        return Ok(());
    }
    if !(m.maps.is_some() && gain >= o.min_gain && with.cv_max_mm <= without.cv_max_mm) {
        t.notes.push(format!(
            "{} not kept: cross-validated {:.4} / {:.4} mm mean / max against {:.4} / {:.4} without maps (needs {:.0} % lower mean and no higher max)",
            method.name(),
            with.cv_mean_mm,
            with.cv_max_mm,
            without.cv_mean_mm,
            without.cv_max_mm,
            o.min_gain * 100.0
        ));
        return Ok(());
    }
    let on_maps = maps_compensator(ctx, cache, base, &fit, folds, &mut t.candidates, &mut |s| {
        progress(&spans.step(on_maps_at, total, s))
    })?;
    let orientation_deg = orientation_mean(&SetErrors::of(
        &fit.fit.model,
        &fit.fit.session_frames,
        pool,
    ));
    if let Some((_, Some(dropped))) = &on_maps.settled {
        t.notes.push(dropped.clone());
    }
    t.options.push(BaseOption {
        base,
        maps: Some(method),
        fit,
        compensator: on_maps.kept,
        mean_mm: with.cv_mean_mm,
        max_mm: with.cv_max_mm,
        blocked_mm: m.blocked.as_ref().map(|b| b.with_maps_mm),
        alone_mm: None,
        orientation_deg: option_orientation(orientation_deg, &on_maps.settled),
        orientation_part: on_maps.settled.map(|s| s.0),
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
    Ok(())
}

/// What `auto` made of the compensators on a kept joint-map fit.
struct OnMaps {
    kept: Option<AppliedCompensator>,
    settled: Settled,
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
    progress: &mut dyn FnMut(&Step) -> bool,
) -> Result<OnMaps, MethodError> {
    let methods = on_maps_candidates(ctx, base);
    if methods.is_empty() {
        return Ok(OnMaps {
            kept: None,
            settled: None,
            reason: String::new(),
        });
    }
    let (choice, kept, settled) =
        cross_validate_and_choose(ctx, cache, &methods, &fit.fit, folds, candidates, progress)?;
    Ok(OnMaps {
        kept,
        settled,
        reason: format!("on {}: {}; ", base.method().name(), choice.reason),
    })
}

/// The kept compensator's orientation part and the note when `auto`
/// dropped it (`orientation_part::settle_for_auto`).
type Settled = Option<(OrientationPart, Option<String>)>;

/// The orientation mean [deg] `auto` scores an option by: the base's (or
/// maps') on the pool, or the kept orientation part's cross-validated mean.
fn option_orientation(base_deg: Option<f64>, settled: &Settled) -> Option<f64> {
    match settled {
        Some((part, _)) if part.status == OrientationPartStatus::Trained => part
            .cross_validation
            .as_ref()
            .map(|c| c.compensated_mean_deg)
            .or(base_deg),
        _ => base_deg,
    }
}

/// Trains and cross-validates each compensator method on `fit`'s residuals,
/// lists each as an `auto` candidate, and keeps the one `choose` accepts
/// with its orientation part settled (kept only when it lowered the
/// cross-validated orientation mean).
/// `progress(step)` names the candidate and fold, with the fraction of that
/// candidate's training done.
fn cross_validate_and_choose(
    ctx: &Context,
    cache: &mut Cache,
    methods: &[(Method, Compensated)],
    fit: &Fit,
    folds: usize,
    candidates: &mut Vec<AutoCandidate>,
    progress: &mut dyn FnMut(&Step) -> bool,
) -> Result<(Choice, Option<AppliedCompensator>, Settled), MethodError> {
    let o = &ctx.opts.compensator;
    let stages = o.cv_stages(folds);
    let mut cvs: Vec<(String, CvStats)> = Vec::new();
    let mut trained: Vec<AppliedCompensator> = Vec::new();
    for (m, c) in methods {
        let max = c.network.max_epochs(o) as f64;
        let r = compensated::trained(ctx, cache, *m, c.network, fit, folds, &mut |stage, e, l| {
            let f = (stage as f64 + (e as f64 / max).min(1.0)) / stages as f64;
            progress(&Step {
                candidate: Some(*m),
                fold: Fold::of_stage(stage, stages),
                ..Step::plain(f, e, Some(l))
            })
        });
        match r {
            Ok(t) => {
                let cv = t.cv.clone().expect("auto cross-validates");
                candidates.push(AutoCandidate {
                    method: *m,
                    cross_validation: Some(cv.clone()),
                    failed: None,
                    orientation_cross_validation: t.orientation_part.cross_validation.clone(),
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
                orientation_cross_validation: None,
            }),
        }
    }
    let choice = choose(&cvs, o.min_gain);
    let mut picked = choice
        .chosen
        .as_deref()
        .and_then(|chosen| trained.into_iter().find(|a| a.method.name() == chosen));
    let settled = picked.as_mut().and_then(|p| settle_for_auto(p, o.min_gain));
    Ok((choice, picked, settled))
}

/// The units planned for each of `auto`'s candidate compensators, in the
/// order they train.
struct Spans {
    /// Per candidate: the units before it and its own.
    each: Vec<(Method, f64, f64)>,
    units: f64,
}

impl Spans {
    /// A candidate's step (fraction of its own training) as a step of
    /// `auto` (fraction of its planned units), the candidates starting at
    /// `at` units of `total`.
    fn step(&self, at: f64, total: f64, s: &Step) -> Step {
        let (before, units) = self
            .each
            .iter()
            .find(|(m, ..)| Some(*m) == s.candidate)
            .map_or((0.0, 0.0), |(_, b, u)| (*b, *u));
        Step {
            fraction: (at + before + units * s.fraction.clamp(0.0, 1.0)) / total,
            ..*s
        }
    }
}

/// Plans the trainings of `cands` with `folds` folds.
fn candidate_spans(
    ctx: &Context,
    plan: &mut Planner,
    cands: &[(Method, Compensated)],
    folds: usize,
) -> Spans {
    let mut units = 0.0;
    let each = cands
        .iter()
        .map(|(m, _)| {
            let u = plan.training(ctx, *m, folds);
            units += u;
            (*m, units - u, u)
        })
        .collect();
    Spans { each, units }
}

/// The joint-map method on `base` among `auto`'s candidates.
fn maps_candidate(candidates: &[Method], base: Base) -> Option<Method> {
    candidates
        .iter()
        .copied()
        .find(|m| m.row().run == Run::Maps(base))
}
