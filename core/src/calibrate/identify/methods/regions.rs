//! How many regions the blocked-fold veto holds out (`delivered`): the
//! k-means clusters of the poses and two edges per moving joint. Its own
//! file so that the progress plan can count them without importing the
//! refits. Joint values in rad.

use super::context::Context;
use crate::measure::Measurement;

/// The joints whose drawn range over `poses` spans at least
/// `JointMapSettings::min_range_rad`, with that range [rad].
pub(super) fn moving_joints(ctx: &Context, poses: &[&Measurement]) -> Vec<(usize, [f64; 2])> {
    let n = poses.first().map_or(0, |m| m.q.len());
    (0..n)
        .filter_map(|j| {
            let [lo, hi] = poses.iter().fold([f64::MAX, f64::MIN], |[lo, hi], m| {
                [lo.min(m.q[j]), hi.max(m.q[j])]
            });
            (hi - lo >= ctx.opts.joint_maps.min_range_rad).then_some((j, [lo, hi]))
        })
        .collect()
}

/// Whether `ctx` has poses enough for the clusters (module docs).
pub(super) fn clusters_drawn(ctx: &Context) -> bool {
    let k = ctx.opts.compensator.blocked_folds;
    k >= 2 && ctx.ident.len() + ctx.training.len() >= 2 * k
}

/// The regions `delivered::DeliveredRegions::draw` holds out at most: the clusters
/// and two edges per moving joint (for the progress plan).
pub(super) fn planned_regions(ctx: &Context) -> usize {
    if !clusters_drawn(ctx) {
        return 0;
    }
    let all: Vec<&Measurement> = ctx.ident.iter().chain(ctx.training).collect();
    ctx.opts.compensator.blocked_folds + 2 * moving_joints(ctx, &all).len()
}
