//! The joint-map methods (beyond the thesis): KM or SKCM, then per-joint angle
//! error maps fitted jointly with the linearised geometry
//! (`identify::joint_maps`) on the identification and training poses, and the
//! geometry, compliance and session frames refitted by LM on the
//! identification poses with the maps held fixed; `rounds` times. When the
//! cross-validation keeps no map (K = 0 wins) the base's fit stays, and the
//! report says so.
//!
//! Randomness: the spatially blocked folds draw from `ChaCha8Rng(seed + 102)`
//! (`CompensatorOptions::seed`); the cross-validation's folds are dealt by
//! the poses, not the seed (`joint_maps`), so the same poses get the same
//! harmonics and ridge whatever the seed.
//! The veto's region refits ([`base_fit_with`]) hold the harmonics and ridge
//! chosen on all the poses (`MapStructure::Fixed`), so the maps they fit
//! depend on the region's poses alone, not on how the folds were dealt.

use super::cache::Cache;
use super::context::{Context, MethodFit, Outcome};
use super::{Base, MethodError, MethodFailure};
use crate::calibrate::identify::joint_maps::{fit_joint_maps, MapStructure};
use crate::calibrate::identify::least_squares::fit;
use crate::measure::Measurement;

/// The fit of any base: a model-based one from the cache, a joint-map one
/// (`km-maps`, `skcm-maps`) by [`run_maps`] on its model-based base.
pub(crate) fn base_fit(
    ctx: &Context,
    cache: &mut Cache,
    base: Base,
    progress: &mut dyn FnMut(usize, f64) -> bool,
) -> Result<MethodFit, MethodError> {
    base_fit_with(ctx, cache, base, MapStructure::CrossValidated, progress)
}

/// [`base_fit`] with a joint-map base's structure chosen as `structure`
/// says (a model-based base ignores it).
pub(crate) fn base_fit_with(
    ctx: &Context,
    cache: &mut Cache,
    base: Base,
    structure: MapStructure,
    progress: &mut dyn FnMut(usize, f64) -> bool,
) -> Result<MethodFit, MethodError> {
    let inner = match base {
        Base::Km => return cache.km_fit(ctx, progress),
        Base::Skcm => return cache.skcm_fit(ctx, progress),
        Base::KmMaps => Base::Km,
        Base::SkcmMaps => Base::Skcm,
    };
    maps_with(ctx, cache, inner, structure, &mut |_, it, l| {
        progress(it, l.unwrap_or(f64::NAN))
    })
    .map(|o| o.fit)
}

/// The joint-map method on `base` (module docs), computed once per run.
pub(crate) fn run_maps(
    ctx: &Context,
    cache: &mut Cache,
    base: Base,
    progress: &mut dyn FnMut(f64, usize, Option<f64>) -> bool,
) -> Result<Outcome, MethodError> {
    maps_with(ctx, cache, base, MapStructure::CrossValidated, progress)
}

/// The joint maps on `base` with their structure set as `structure` says,
/// computed once per structure and run.
fn maps_with(
    ctx: &Context,
    cache: &mut Cache,
    base: Base,
    structure: MapStructure,
    progress: &mut dyn FnMut(f64, usize, Option<f64>) -> bool,
) -> Result<Outcome, MethodError> {
    if let Some((.., r)) = cache
        .maps
        .iter()
        .find(|(b, s, _)| *b == base && *s == structure)
    {
        return r.clone().map(Outcome::plain).map_err(MethodError::Failed);
    }
    let r = match fit_maps(ctx, cache, base, structure, progress) {
        Err(MethodError::Cancelled) => return Err(MethodError::Cancelled),
        Err(MethodError::Failed(f)) => Err(f),
        Ok(mf) => Ok(mf),
    };
    cache.maps.push((base, structure, r.clone()));
    r.map(Outcome::plain).map_err(MethodError::Failed)
}

fn fit_maps(
    ctx: &Context,
    cache: &mut Cache,
    base: Base,
    structure: MapStructure,
    progress: &mut dyn FnMut(f64, usize, Option<f64>) -> bool,
) -> Result<MethodFit, MethodError> {
    let settings = &ctx.opts.joint_maps;
    let rounds = settings.rounds.max(1);
    let stages = (2 * rounds + 1) as f64;
    let mut mf = base_fit(ctx, cache, base, &mut |it, rms| {
        progress(0.0, it, Some(rms))
    })?;
    let sessions = mf.fit.session_frames.len().max(1);
    let data: Vec<Measurement> = ctx
        .ident
        .iter()
        .chain(ctx.training)
        .filter(|m| m.session < sessions)
        .cloned()
        .collect();
    let w = ctx.opts.lm.orientation_weight;
    for round in 0..rounds {
        let mut plain = mf.fit.model.clone();
        plain.joint_maps = None;
        let stage = (1 + 2 * round) as f64;
        let fitted = fit_joint_maps(
            &plain,
            &mf.fit.session_frames,
            &mf.ids,
            &data,
            w,
            settings,
            structure,
            &mut |done, total| progress((stage + done as f64 / total as f64) / stages, done, None),
        )
        .map_err(MethodFailure::JointMaps)?
        .ok_or(MethodError::Cancelled)?;
        let Some(maps) = fitted.maps.clone() else {
            mf.maps = Some(fitted);
            break;
        };
        plain.joint_maps = Some(maps);
        let refit = fit(
            &plain,
            &mf.ids,
            ctx.ident,
            ctx.sessions,
            &ctx.opts.lm,
            &mut |it, rms| progress((stage + 1.0) / stages, it, Some(rms)),
        )?;
        mf.fit = refit;
        mf.maps = Some(fitted);
    }
    Ok(mf)
}
