//! `auto`'s options judged as delivered on spatially blocked regions, for
//! the veto (`methods::veto`).
//!
//! The identification and training poses together are split into regions of
//! joint space (`compensate::blocked_fold_assignment`: k-means of the joint
//! vectors, each joint scaled by its range; `CompensatorOptions::
//! blocked_folds` regions, drawn from `ChaCha8Rng(seed + 103)`). For each
//! region the option is refitted as `auto` would deliver it from the other
//! poses: the base (KM or SKCM) by LM on the remaining identification poses;
//! its joint maps, when it has them, cross-validated again over the
//! harmonics up to the count `auto` chose with its ridge (`joint_maps`,
//! K = 0 still competing, the maps' own blocked folds skipped); its compensator, when it has one, trained without
//! cross-validation on the residuals of the remaining training pool (the
//! identification poses without one) with its support, so it fades beyond
//! the joint ranges it saw (`trained::support_of`). The region's poses are
//! then predicted by that model (`report::predict_compensated`), each once,
//! in the registered base frame with the refit's session frames; the figures
//! are their position errors [mm]. A region that leaves too few poses to
//! refit on is not held out.

use super::cache::Cache;
use super::context::Context;
use super::maps::base_fit;
use super::veto::BlockedFigures;
use super::{compensated, Base, Method, MethodError};
use crate::calibrate::compensate::blocked_fold_assignment;
use crate::calibrate::identify::network::Network;
use crate::calibrate::identify::options::CalibrationOptions;
use crate::calibrate::identify::report::SetErrors;
use crate::measure::Measurement;
use crate::model::calibrated::Compensator;
use crate::model::kinematics::Chain;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::sync::Arc;

/// What `auto` delivers for an option: a base with or without its joint
/// maps, and the compensator on it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Delivery {
    /// KM or SKCM, or their joint maps (`Base::KmMaps`, `Base::SkcmMaps`).
    pub base: Base,
    /// The maps' chosen harmonics and ridge (maps bases only).
    pub maps_choice: Option<(usize, f64)>,
    pub compensator: Option<(Method, Network)>,
}

/// One region held out: the poses left to refit on, the region's poses and
/// the fits shared by the options judged on it.
struct Region {
    ident: Vec<Measurement>,
    chains: Vec<Chain>,
    training: Vec<Measurement>,
    held: Vec<Measurement>,
    cache: Cache,
}

/// The blocked regions of one `auto` run and what was judged on them.
pub(super) struct DeliveredRegions {
    regions: Vec<Region>,
    judged: Vec<(Delivery, Result<BlockedFigures, String>)>,
}

/// The options the sub-runs take: the maps' harmonics up to the chosen
/// count and its ridge, their blocked folds skipped.
fn sub_options(opts: &CalibrationOptions, maps_choice: Option<(usize, f64)>) -> CalibrationOptions {
    let mut o = opts.clone();
    if let Some((k, ridge)) = maps_choice {
        o.joint_maps.harmonics.retain(|h| *h <= k);
        if !o.joint_maps.harmonics.contains(&k) {
            o.joint_maps.harmonics.push(k);
        }
        o.joint_maps.ridge = vec![ridge];
    }
    o.joint_maps.blocked_folds = 0;
    o
}

impl DeliveredRegions {
    /// The regions of `ctx`'s identification and training poses (module
    /// docs); `None` for fewer than two regions or poses than twice their
    /// number.
    pub fn draw(ctx: &Context) -> Option<DeliveredRegions> {
        let k = ctx.opts.compensator.blocked_folds;
        let all: Vec<&Measurement> = ctx.ident.iter().chain(ctx.training).collect();
        if k < 2 || all.len() < 2 * k {
            return None;
        }
        let qs: Vec<&[f64]> = all.iter().map(|m| m.q.as_slice()).collect();
        let mut rng = ChaCha8Rng::seed_from_u64(ctx.opts.compensator.seed.wrapping_add(103));
        let region = blocked_fold_assignment(&qs, k, &mut rng);
        let n_ident = ctx.ident.len();
        let regions = (0..k)
            .map(|r| {
                let kept = |i: &usize| region[*i] != r;
                let idx: Vec<usize> = (0..n_ident).filter(kept).collect();
                Region {
                    ident: idx.iter().map(|i| ctx.ident[*i].clone()).collect(),
                    chains: idx.iter().map(|i| ctx.ident_chains[*i].clone()).collect(),
                    training: (0..ctx.training.len())
                        .filter(|i| kept(&(n_ident + i)))
                        .map(|i| ctx.training[i].clone())
                        .collect(),
                    held: (0..all.len())
                        .filter(|i| region[*i] == r)
                        .map(|i| all[i].clone())
                        .collect(),
                    cache: Cache::default(),
                }
            })
            // Enough left to identify on, and something held out.
            .filter(|r| !r.held.is_empty() && r.ident.len() >= ctx.ident.len() / 2)
            .collect::<Vec<_>>();
        (regions.len() >= 2).then_some(DeliveredRegions {
            regions,
            judged: Vec::new(),
        })
    }

    /// The regions held out and the poses they hold.
    pub fn size(&self) -> (usize, usize) {
        (
            self.regions.len(),
            self.regions.iter().map(|r| r.held.len()).sum(),
        )
    }

    /// `delivery` refitted without each region and its poses predicted
    /// (module docs), computed once per run; `Err` says why it could not be
    /// (a refit failed). `go()` false cancels.
    pub fn judge(
        &mut self,
        ctx: &Context,
        delivery: Delivery,
        go: &mut dyn FnMut() -> bool,
    ) -> Result<Result<BlockedFigures, String>, MethodError> {
        if let Some((_, r)) = self.judged.iter().find(|(d, _)| *d == delivery) {
            return Ok(r.clone());
        }
        let opts = sub_options(ctx.opts, delivery.maps_choice);
        let mut errors = Vec::new();
        let mut failed = None;
        for region in &mut self.regions {
            match judge_region(ctx, &opts, region, delivery, go) {
                Ok(e) => errors.extend(e),
                Err(MethodError::Cancelled) => return Err(MethodError::Cancelled),
                Err(MethodError::Failed(f)) => {
                    failed = Some(f.to_string());
                    break;
                }
            }
        }
        let r = match failed {
            Some(f) => Err(f),
            None => {
                let n = errors.len().max(1) as f64;
                Ok(BlockedFigures {
                    mean_mm: errors.iter().sum::<f64>() / n,
                    max_mm: errors.iter().copied().fold(0.0, f64::max),
                })
            }
        };
        self.judged.push((delivery, r.clone()));
        Ok(r)
    }
}

/// The held-out errors [mm] of one region for `delivery` refitted on the
/// rest.
fn judge_region(
    ctx: &Context,
    opts: &CalibrationOptions,
    region: &mut Region,
    delivery: Delivery,
    go: &mut dyn FnMut() -> bool,
) -> Result<Vec<f64>, MethodError> {
    let sub = Context {
        nominal: ctx.nominal,
        start: ctx.start.clone(),
        ident: &region.ident,
        ident_chains: &region.chains,
        valid: &[],
        training: &region.training,
        sessions: ctx.sessions,
        kept_geo: ctx.kept_geo.clone(),
        kept_c: ctx.kept_c.clone(),
        gravity: ctx.gravity.clone(),
        opts,
    };
    let cache = &mut region.cache;
    let mf = base_fit(&sub, cache, delivery.base, &mut |_, _| go())?;
    let compensator: Option<Arc<dyn Compensator>> = match delivery.compensator {
        None => None,
        Some((method, network)) => {
            let t =
                compensated::trained(&sub, cache, method, network, &mf.fit, 0, &mut |_, _, _| {
                    go()
                })?;
            Some(t.stored.into_arc_supported(Some(t.support)))
        }
    };
    let e = SetErrors::of_compensated(
        &mf.fit.model,
        compensator.as_deref(),
        &mf.fit.session_frames,
        &region.held,
    );
    Ok(e.errors_mm)
}
