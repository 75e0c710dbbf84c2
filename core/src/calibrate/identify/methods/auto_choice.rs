//! How `auto` chooses among its options (`methods::auto`): those that lose
//! orientation are excluded ([`choose_option`]), the tie rule
//! (`ties::break_ties`, margin `CompensatorOptions::tie_margin`) picks among
//! the rest, and an option on the weaker base is set aside for the best one
//! on the better base ([`decide`]).
//!
//! The better base: KM and SKCM alone compared outside the region they were
//! fitted on — their geometry alone on the joint maps' spatially blocked
//! folds when the maps ran on both (`joint_maps::BlockedMaps`), else their
//! residual mean on the pool — the better when the other's figure exceeds
//! its own by more than the tie margin. Beyond its trained region a
//! compensator or a joint map fades to its base, so an option on the weaker
//! base is not delivered while an option on the better base is there. When
//! the set-aside option's counterpart on the better base ([`counterpart`]:
//! the same network, or the joint maps, on it) was not among the candidates,
//! `auto` trains it first and decides again.
//!
//! The blocked-fold veto ([`apply_veto`]): the option decided on (unless a
//! base alone) is refitted without each blocked region and judged there
//! against its base alone (`methods::delivered`, `methods::veto`); a vetoed
//! option leaves the options, its base alone joins them when it is not
//! there, and the rule decides again among the rest, until an option passes
//! or a base alone is chosen.

use super::auto_tally::{BaseOption, Tally, ORIENTATION_SLACK};
use super::cache::Cache;
use super::compensated::base_pool_errors;
use super::context::{Context, Outcome, Step};
use super::delivered::{DeliveredRegions, Delivery};
use super::maps::base_fit;
use super::plan::Planner;
use super::ties::{break_ties, Contender, Physics, TieOutcome};
use super::veto::{veto, worst_edge, BlockedCheck};
use super::{Base, Compensated, Method, MethodError, MethodFailure, Run};
use crate::calibrate::identify::joint_maps::MapOrder;
use crate::calibrate::identify::report::{AutoDecision, AutoSummary, BaseFallback};

/// The option `auto` takes among `(position mean [mm], orientation mean
/// [deg])` pairs (orientation `None`: not measured): those whose orientation
/// mean exceeds the lowest by more than `slack` (relative) are excluded, then
/// the lowest position mean wins. Returns its index and the excluded ones;
/// `None` for no options.
pub(crate) fn choose_option(
    options: &[(f64, Option<f64>)],
    slack: f64,
) -> Option<(usize, Vec<usize>)> {
    let best_orientation = options
        .iter()
        .filter_map(|o| o.1)
        .fold(f64::INFINITY, f64::min);
    let loses = |o: &(f64, Option<f64>)| {
        o.1.is_some_and(|a| best_orientation.is_finite() && a > best_orientation * (1.0 + slack))
    };
    let excluded: Vec<usize> = (0..options.len()).filter(|i| loses(&options[*i])).collect();
    let chosen = (0..options.len())
        .filter(|i| !excluded.contains(i))
        .min_by(|a, b| options[*a].0.total_cmp(&options[*b].0))?;
    Some((chosen, excluded))
}

/// KM or SKCM: the model-based base under an option's fit.
pub(super) fn family(base: Base) -> Base {
    match base {
        Base::Km | Base::KmMaps => Base::Km,
        Base::Skcm | Base::SkcmMaps => Base::Skcm,
    }
}

/// The same base on the other family (KM ↔ SKCM).
fn swap(base: Base) -> Base {
    match base {
        Base::Km => Base::Skcm,
        Base::Skcm => Base::Km,
        Base::KmMaps => Base::SkcmMaps,
        Base::SkcmMaps => Base::KmMaps,
    }
}

/// The method on the other family that does what `method` does: the same
/// network on the swapped base, or the joint maps on it; `None` for a
/// model-based method or one without a counterpart (`km-rbf`).
pub(super) fn counterpart(method: Method) -> Option<Method> {
    let run = match method.row().run {
        Run::Compensated(c) => Run::Compensated(Compensated {
            base: swap(c.base),
            network: c.network,
        }),
        Run::Maps(b) => Run::Maps(swap(b)),
        _ => return None,
    };
    Method::ALL.iter().copied().find(|m| m.row().run == run)
}

/// The method an option delivers.
pub(super) fn option_name(o: &BaseOption) -> &'static str {
    match (&o.compensator, o.maps) {
        (Some(a), _) => a.method.name(),
        (None, Some(m)) => m.name(),
        (None, None) => o.base.method().name(),
    }
}

fn option_method(o: &BaseOption) -> Method {
    Method::from_name(option_name(o)).expect("a method's own name")
}

/// Fitted quantities of an option: identified parameters, joint-map
/// coefficients, three output weights per compensator unit.
fn parameters(o: &BaseOption) -> usize {
    let maps: usize = o.fit.fit.model.joint_maps.as_ref().map_or(0, |m| {
        m.joints.iter().flatten().map(|j| 2 * j.harmonics()).sum()
    });
    let units = o
        .compensator
        .as_ref()
        .map_or(0, |a| 3 * a.trained.stored.shape().units);
    o.fit.ids.len() + maps + units
}

fn contender(o: &BaseOption) -> Contender {
    Contender {
        mean_mm: o.mean_mm,
        blocked_mean_mm: o.blocked_mm,
        max_mm: o.max_mm,
        physics: Physics::of(option_method(o)),
        parameters: parameters(o),
    }
}

/// The better of KM and SKCM outside the region (module docs).
struct BetterBase {
    better: Base,
    weaker: Base,
    better_mm: f64,
    weaker_mm: f64,
    measured_by: String,
}

fn better_base(t: &Tally, margin: f64, pool_name: &str) -> Option<BetterBase> {
    let blocked = |b: Base| t.geometry_blocked.iter().find(|g| g.0 == b).map(|g| g.1);
    let alone = |b: Base| {
        t.options
            .iter()
            .find(|o| o.base == b && o.maps.is_none())
            .and_then(|o| o.alone_mm)
    };
    let (km, skcm, measured_by) = match (blocked(Base::Km), blocked(Base::Skcm)) {
        (Some(k), Some(s)) => (
            k,
            s,
            "the geometry alone on the joint maps' spatially blocked folds".to_string(),
        ),
        _ => (
            alone(Base::Km)?,
            alone(Base::Skcm)?,
            format!("the base alone on the {pool_name} poses"),
        ),
    };
    let (better, weaker, better_mm, weaker_mm) = if skcm <= km {
        (Base::Skcm, Base::Km, skcm, km)
    } else {
        (Base::Km, Base::Skcm, km, skcm)
    };
    (weaker_mm - better_mm > margin * better_mm).then_some(BetterBase {
        better,
        weaker,
        better_mm,
        weaker_mm,
        measured_by,
    })
}

/// What [`decide`] found; indices are into the tally's options.
pub(super) struct Decision {
    pub outcome: TieOutcome,
    /// Options excluded for losing orientation.
    pub excluded: Vec<usize>,
    pub fallback: Option<BaseFallback>,
    /// The set-aside option's counterpart on the better base, with that
    /// base, when it was not among the candidates.
    pub untried: Option<Method>,
    /// The blocked-fold veto's checks ([`apply_veto`]).
    pub checks: Vec<BlockedCheck>,
}

/// The tie rule over the options (module docs), then the fallback to the
/// better base.
pub(super) fn decide(ctx: &Context, t: &Tally) -> Result<Decision, MethodError> {
    let margin = ctx.opts.compensator.tie_margin;
    let (_, pool_name) = ctx.pool();
    // The orientation bar is set by the options still in the running: one
    // the veto set aside no longer excludes the others.
    let live: Vec<usize> = (0..t.options.len())
        .filter(|i| !t.vetoed.contains(i))
        .collect();
    let scores: Vec<(f64, Option<f64>)> = live
        .iter()
        .map(|&i| (t.options[i].mean_mm, t.options[i].orientation_deg))
        .collect();
    let no_option = || MethodFailure::NoBaseSucceeded {
        notes: t.notes.clone(),
    };
    let (_, excluded) = choose_option(&scores, ORIENTATION_SLACK).ok_or_else(no_option)?;
    let excluded: Vec<usize> = excluded.iter().map(|&k| live[k]).collect();
    let rule = |among: &[usize]| {
        let c: Vec<Contender> = among.iter().map(|i| contender(&t.options[*i])).collect();
        break_ties(&c, margin).map(|o| TieOutcome {
            winner: among[o.winner],
            runner_up: o.runner_up.map(|r| among[r]),
            ..o
        })
    };
    let eligible: Vec<usize> = (0..t.options.len())
        .filter(|i| !excluded.contains(i) && !t.vetoed.contains(i))
        .collect();
    let first = rule(&eligible).ok_or_else(no_option)?;
    let chosen = &t.options[first.winner];
    let Some(b) = better_base(t, margin, pool_name).filter(|b| family(chosen.base) == b.weaker)
    else {
        return Ok(Decision {
            outcome: first,
            excluded,
            fallback: None,
            untried: None,
            checks: Vec::new(),
        });
    };
    let set_aside = option_method(chosen);
    let offer = if chosen.maps.is_some() {
        chosen.maps.and_then(counterpart)
    } else {
        counterpart(set_aside)
    };
    let untried = offer.filter(|m| {
        (ctx.gravity.is_none() || !m.uses_torques()) && !t.candidates.iter().any(|c| c.method == *m)
    });
    let better: Vec<usize> = eligible
        .iter()
        .copied()
        .filter(|i| family(t.options[*i].base) == b.better)
        .collect();
    let Some(outcome) = rule(&better) else {
        return Ok(Decision {
            outcome: first,
            excluded,
            fallback: None,
            untried,
            checks: Vec::new(),
        });
    };
    Ok(Decision {
        outcome,
        excluded,
        fallback: Some(BaseFallback {
            instead_of: set_aside,
            weaker_base: b.weaker.method(),
            better_base: b.better.method(),
            weaker_mm: b.weaker_mm,
            better_mm: b.better_mm,
            measured_by: b.measured_by,
        }),
        untried,
        checks: Vec::new(),
    })
}

/// What `auto` delivers for option `o` (`delivered::Delivery`).
fn delivery(o: &BaseOption) -> Delivery {
    let base = match (o.maps, family(o.base)) {
        (None, b) => b,
        (Some(_), Base::Km) => Base::KmMaps,
        (Some(_), _) => Base::SkcmMaps,
    };
    Delivery {
        base,
        maps_choice: o.maps.and(o.fit.maps.as_ref()).map(|m| MapOrder {
            harmonics: m.chosen.harmonics,
            ridge: m.chosen.ridge,
        }),
        compensator: o
            .compensator
            .as_ref()
            .and_then(|a| Some((a.method, a.method.compensated()?.network))),
    }
}

/// `base` alone as an option, from its fit on the pool (cached).
fn base_alone(ctx: &Context, cache: &mut Cache, base: Base) -> Result<BaseOption, MethodError> {
    let (pool, pool_name) = ctx.pool();
    let fit = base_fit(ctx, cache, base, &mut |_, _| true)?;
    let e = base_pool_errors(&fit.fit, pool);
    Ok(BaseOption {
        base,
        maps: None,
        fit,
        compensator: None,
        mean_mm: e.stats.mean_mm,
        max_mm: e.stats.max_mm,
        blocked_mm: (!ctx.training.is_empty()).then_some(e.stats.mean_mm),
        alone_mm: Some(e.stats.mean_mm),
        orientation_deg: e.orientation.as_ref().map(|o| o.mean_deg),
        orientation_part: None,
        reason: format!(
            "{} alone: {:.4} / {:.4} mm mean / max on the {pool_name} poses, the option on it vetoed",
            base.method().name(),
            e.stats.mean_mm,
            e.stats.max_mm
        ),
    })
}

/// Lays the rest of `auto`'s bar over `need` units of the check about to
/// run where the plan held `held` (the veto's check planned before the
/// option was known, `Planner::veto`): the fraction done stays, so the bar
/// neither jumps nor goes back, and from here it moves with the check's own
/// work (`Planner::veto_of`) and what the plan holds after it.
fn lay_rest_over(t: &mut Tally, held: f64, need: f64) {
    (t.done, t.total) = rebased(t.done, t.total, held, need);
}

/// `(done, total)` units with `done / total` kept and `need` units in place
/// of `held` of the `total − done` left.
pub(super) fn rebased(done: f64, total: f64, held: f64, need: f64) -> (f64, f64) {
    let fraction = (done / total).clamp(0.0, 1.0);
    let left = (need + (total - done - held).max(0.0)).max(0.0);
    if fraction >= 1.0 || left <= 0.0 {
        return (done, done + left);
    }
    let total = left / (1.0 - fraction);
    (fraction * total, total)
}

/// The blocked-fold veto over `decision` (module docs): returns the decision
/// on the option that passed (or a base alone) with the checks made. Each
/// check moves the bar over its own units (`plan::Planner::veto_of` of the
/// option checked): the rest of the bar is laid over them when the check
/// starts, in place of the units `plan::Planner::veto` planned with `auto`
/// (the first check) or none (a check after a veto).
pub(super) fn apply_veto(
    ctx: &Context,
    cache: &mut Cache,
    t: &mut Tally,
    mut decision: Decision,
) -> Result<Decision, MethodError> {
    let margin = ctx.opts.compensator.tie_margin;
    // What the plan holds for the first check; later checks were not planned.
    let mut held = Planner::veto(ctx);
    let mut regions: Option<Option<DeliveredRegions>> = None;
    let mut checks = Vec::new();
    let mut first_fallback = None;
    loop {
        let w = decision.outcome.winner;
        let o = &t.options[w];
        if o.maps.is_none() && o.compensator.is_none() {
            break;
        }
        let (option, method, base) = (delivery(o), option_method(o), family(o.base));
        let Some(rs) = regions
            .get_or_insert_with(|| DeliveredRegions::draw(ctx))
            .as_mut()
        else {
            t.notes.push(
                "the blocked-fold veto did not run: too few poses for two blocked regions with enough left to refit on"
                    .to_string(),
            );
            break;
        };
        let planned = Planner::veto_of(ctx, method).unwrap_or(held);
        lay_rest_over(t, held, planned);
        held = 0.0;
        let (at, total) = (t.done, t.total);
        let progress = &mut *t.progress;
        // The option's refits, then its base's: half the check's units each.
        let mut step = |half: f64, f: f64| {
            progress(&Step {
                candidate: Some(method),
                ..Step::plain((at + planned * 0.5 * (half + f)) / total, 0, None)
            })
        };
        let alone = Delivery {
            base,
            maps_choice: None,
            compensator: None,
        };
        let of = rs.judge(ctx, option, &mut |f| step(0.0, f))?;
        let bf = rs.judge(ctx, alone, &mut |f| step(1.0, f))?;
        t.done += planned;
        let (of, bf) = match (of, bf) {
            (Ok(of), Ok(bf)) => (of, bf),
            (Err(e), _) | (_, Err(e)) => {
                t.notes.push(format!(
                    "the blocked-fold veto could not judge {}: {e}",
                    method.name()
                ));
                break;
            }
        };
        let c = rs.compare(&of, &bf);
        let verdict = veto(&c.option, &c.base, &c.edges, margin);
        let [(count, poses), (edges, edge_poses)] = rs.size();
        checks.push(BlockedCheck {
            option: method,
            base: base.method(),
            verdict,
            verdict_label: verdict.label(),
            regions: count,
            poses,
            option_blocked: c.option,
            base_blocked: c.base,
            edges,
            edge_poses,
            worst_edge: worst_edge(&c.edges).copied(),
        });
        if !verdict.vetoed() {
            break;
        }
        t.vetoed.push(w);
        let has_alone = t.options.iter().enumerate().any(|(i, o)| {
            !t.vetoed.contains(&i)
                && family(o.base) == base
                && o.maps.is_none()
                && o.compensator.is_none()
        });
        if !has_alone {
            let o = base_alone(ctx, cache, base)?;
            t.options.push(o);
        }
        first_fallback = first_fallback.or(decision.fallback.take());
        decision = decide(ctx, t)?;
        decision.untried = None;
    }
    // The check planned with `auto` did not run (`held` is 0 once one did).
    t.done += held;
    decision.fallback = decision.fallback.or(first_fallback);
    decision.checks = checks;
    Ok(decision)
}

/// The option `auto` delivers by `decision`, with its reason, the other
/// options' reasons and the notes.
pub(super) fn choose_among(
    ctx: &Context,
    t: Tally,
    decision: Decision,
) -> Result<Outcome, MethodError> {
    let (_, pool_name) = ctx.pool();
    let Tally {
        mut notes,
        candidates,
        mut options,
        ..
    } = t;
    let best = decision.outcome.winner;
    let best_orientation = options[best].orientation_deg;
    for i in &decision.excluded {
        notes.push(format!(
            "{} not chosen: it loses orientation, {:.4}° mean on the {pool_name} poses, more than {:.0} % above the best option's",
            option_name(&options[*i]),
            options[*i].orientation_deg.unwrap_or(f64::NAN),
            ORIENTATION_SLACK * 100.0
        ));
    }
    let o = &decision.outcome;
    let runner_up = o.runner_up.map(|r| option_method(&options[r]));
    let reasons: Vec<String> = options.iter().map(|o| o.reason.clone()).collect();
    let best = options.swap_remove(best);
    let chosen = option_method(&best);
    let result = AutoDecision {
        tie: o.tie,
        step: o.step,
        step_label: o.step.label(),
        runner_up,
        margin: o.margin,
        margin_unit: o.step.unit(),
        mean_margin_mm: o.mean_margin_mm,
        tie_margin: ctx.opts.compensator.tie_margin,
        fallback: decision.fallback,
        blocked_checks: decision.checks,
    };
    let mut reason = format!(
        "{}; {} mean {:.4} mm on the {pool_name} poses — {}",
        result.sentence(chosen),
        chosen.name(),
        best.mean_mm,
        reasons.join("; ")
    );
    if let Some(a) = best_orientation {
        reason.push_str(&format!(
            "; orientation {a:.4}° mean on the {pool_name} poses (orientation within {:.0} % of the best option's is required)",
            ORIENTATION_SLACK * 100.0
        ));
    }
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
            orientation_part: best.orientation_part,
            decision: result,
        }),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Laying the rest of the bar over other units keeps the fraction done
    /// and leaves the check's units and what the plan held after it: fewer
    /// units than planned shorten the rest, more lengthen it, and the bar
    /// does not move at the switch either way.
    #[test]
    fn the_rest_of_the_bar_is_laid_over_the_checks_own_units() {
        // 600 of 1000 units done; the plan held 300 for the check, 100 after.
        for need in [30.0, 300.0, 3000.0] {
            let (done, total) = rebased(600.0, 1000.0, 300.0, need);
            assert!((done / total - 0.6).abs() < 1e-12, "{done} / {total}");
            assert!((total - done - (need + 100.0)).abs() < 1e-9 * total);
        }
        // Nothing held (a check after a veto): its units are added.
        let (done, total) = rebased(900.0, 1000.0, 0.0, 50.0);
        assert!((done / total - 0.9).abs() < 1e-12);
        assert!((total - done - 150.0).abs() < 1e-9);
        // The bar at its end stays there.
        assert_eq!(rebased(1000.0, 1000.0, 0.0, 50.0), (1000.0, 1050.0));
    }

    /// Without orientation the lowest position mean wins; with it, an option
    /// that gains position but loses orientation beyond the slack is
    /// excluded, one within the slack still competes by position.
    #[test]
    fn an_option_losing_orientation_is_not_chosen() {
        assert_eq!(
            choose_option(&[(0.45, None), (0.10, None)], 0.02),
            Some((1, vec![]))
        );
        // Maps: 4× better position, but 0.060° against 0.053°: excluded.
        assert_eq!(
            choose_option(&[(0.45, Some(0.053)), (0.10, Some(0.060))], 0.02),
            Some((0, vec![1]))
        );
        // 0.0535° is within 2 % of 0.053°: the better position wins.
        assert_eq!(
            choose_option(&[(0.45, Some(0.053)), (0.10, Some(0.0535))], 0.02),
            Some((1, vec![]))
        );
        // Better on both: chosen.
        assert_eq!(
            choose_option(&[(0.45, Some(0.053)), (0.10, Some(0.019))], 0.02),
            Some((1, vec![0]))
        );
        assert_eq!(choose_option(&[], 0.02), None);
    }

    /// Every compensator and joint-map method has its counterpart on the
    /// other base but the torque-input RBF; counterparts pair up.
    #[test]
    fn counterparts_pair_the_bases() {
        assert_eq!(counterpart(Method::KmMaps), Some(Method::SkcmMaps));
        assert_eq!(counterpart(Method::KmGp), Some(Method::SkcmGp));
        assert_eq!(counterpart(Method::KmMapsGp), Some(Method::SkcmMapsGp));
        assert_eq!(counterpart(Method::KmRbf), None);
        assert_eq!(counterpart(Method::Skcm), None);
        for m in Method::ALL {
            if let Some(c) = counterpart(m) {
                assert_eq!(counterpart(c), Some(m), "{m}");
                assert_ne!(Physics::of(c), Physics::of(m), "{m}");
            }
        }
    }
}
