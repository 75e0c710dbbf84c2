//! The work of a calibration's methods planned up front, in units of SKCM's
//! fit, so that the progress bar moves with work done over work planned
//! ([`Planner`]).
//!
//! A unit's cost follows the table's `weight` (measured time over SKCM's): a joint-map
//! fit costs its method's weight less its base's, a compensator's
//! cross-validated training its method's weight less its base's, scaled by
//! its trainings over [`REFERENCE_TRAININGS`] (the weight is set for 5 random
//! folds, 4 blocked and the final training), `skcm-tlbo` its weight and
//! `skcm-payload` its weight less SKCM's. `auto` sums what it runs: per base
//! (KM, SKCM when gravity loads a joint) the fit and each candidate
//! compensator, then per base with a joint-map candidate the maps and the
//! compensators on them, then one check of the blocked-fold veto
//! ([`Planner::veto`]). Work the run's cache already holds (a base fitted,
//! a compensator trained with the same folds by an earlier method) costs
//! nothing, as it costs no time.

use super::cache::Cache;
use super::context::Context;
use super::regions::planned_regions;
use super::{Base, Method, Run};

/// Trainings of one cross-validated compensator that its table weight is set
/// for: 5 random folds, 4 blocked ones and the final training.
pub(crate) const REFERENCE_TRAININGS: f64 = 10.0;

/// What the plan already counts as done (or the cache holds): the fitted
/// bases and the trained compensators with their folds.
#[derive(Debug, Clone, Default)]
pub(crate) struct Planner {
    fitted: Vec<Base>,
    trained: Vec<(Method, usize)>,
}

impl Planner {
    /// A plan that knows what `cache` holds.
    pub(crate) fn from_cache(cache: &Cache) -> Self {
        let (fitted, trained) = cache.held();
        Planner { fitted, trained }
    }

    /// Units of fitting `base` (and what it builds on), 0 when fitted before;
    /// marks it fitted.
    pub(crate) fn base(&mut self, base: Base) -> f64 {
        if self.fitted.contains(&base) {
            return 0.0;
        }
        self.fitted.push(base);
        match base {
            Base::Km | Base::Skcm => base.method().row().weight,
            Base::KmMaps => self.base(Base::Km) + maps_units(Method::KmMaps, Method::Km),
            Base::SkcmMaps => self.base(Base::Skcm) + maps_units(Method::SkcmMaps, Method::Skcm),
        }
    }

    /// Units of training compensator `method` with `folds`-fold
    /// cross-validation, 0 when trained before; marks it trained.
    pub(crate) fn training(&mut self, ctx: &Context, method: Method, folds: usize) -> f64 {
        let Some(c) = method.compensated() else {
            return 0.0;
        };
        if self.trained.contains(&(method, folds)) {
            return 0.0;
        }
        self.trained.push((method, folds));
        let stages = ctx.opts.compensator.cv_stages(folds) as f64;
        let cost = (method.row().weight - c.base.method().row().weight).max(0.0);
        cost * stages / REFERENCE_TRAININGS
    }

    /// Units of running `method` after what the plan holds; marks its work
    /// done.
    pub(crate) fn method(&mut self, ctx: &Context, method: Method) -> f64 {
        let row = method.row();
        match row.run {
            Run::Km => self.base(Base::Km),
            Run::Skcm => self.base(Base::Skcm),
            // Warm-started from KM, fitted for it when no method did.
            Run::SkcmTlbo => {
                let warm = if self.fitted.contains(&Base::Km) {
                    0.0
                } else {
                    Method::Km.row().weight
                };
                warm + row.weight
            }
            Run::SkcmPayload => {
                self.base(Base::Skcm) + (row.weight - Method::Skcm.row().weight).max(0.0)
            }
            Run::Maps(Base::Km) => self.base(Base::KmMaps),
            Run::Maps(_) => self.base(Base::SkcmMaps),
            Run::Compensated(c) => {
                self.base(c.base) + self.training(ctx, method, ctx.opts.compensator.cv_folds)
            }
            Run::Auto => self.auto(ctx),
        }
    }

    /// Units of `auto` (module docs), in the order it runs them.
    pub(crate) fn auto(&mut self, ctx: &Context) -> f64 {
        let folds = auto_folds(ctx);
        let bases = auto_bases(ctx);
        let mut units = 0.0;
        for base in &bases {
            units += self.base(*base);
            for m in auto_compensators(ctx, *base) {
                units += self.training(ctx, m, folds);
            }
        }
        for base in &bases {
            let maps = if *base == Base::Km {
                Base::KmMaps
            } else {
                Base::SkcmMaps
            };
            if !auto_has_maps(ctx, *base) {
                continue;
            }
            units += self.base(maps);
            for m in auto_compensators(ctx, maps) {
                units += self.training(ctx, m, folds);
            }
        }
        units + Planner::veto(ctx)
    }

    /// Units of one check of `auto`'s blocked-fold veto
    /// (`methods::delivered`) as planned before `auto` has chosen: the
    /// median of [`Planner::veto_of`] over `auto`'s joint-map and compensator
    /// candidates, 0 when no candidate would be checked. The check refits
    /// the option `auto` delivers, which is not known until the
    /// cross-validation ends; the costliest candidates (the population-trained
    /// networks, whose one training costs some hundred SKCM fits) are seldom
    /// delivered, so planning the check at the costliest, as an upper bound,
    /// counted most of a run's planned work in a check that did not run, and
    /// the time left was stated several times too long (docs/progress.md).
    /// When the option is known the rest of the bar is laid over its own
    /// check ([`Planner::veto_of`], `auto_choice::apply_veto`).
    pub(crate) fn veto(ctx: &Context) -> f64 {
        let mut each: Vec<f64> = ctx
            .opts
            .compensator
            .auto_candidates
            .iter()
            .filter_map(|m| Planner::veto_of(ctx, *m))
            .collect();
        if each.is_empty() {
            return 0.0;
        }
        each.sort_by(f64::total_cmp);
        let mid = each.len() / 2;
        if each.len() % 2 == 1 {
            each[mid]
        } else {
            0.5 * (each[mid - 1] + each[mid])
        }
    }

    /// Units of one check of the veto on candidate `option`: per region it
    /// may hold out, the base refitted (the heavier of `auto`'s bases) and
    /// the option refitted on it (a joint-map fit's units, a compensator's
    /// one training without cross-validation on its base's maps, if any).
    /// Nothing of it is cached: every region refits. `None` when `option` is
    /// not a candidate the veto checks (a base, or one needing torques
    /// without gravity).
    pub(crate) fn veto_of(ctx: &Context, option: Method) -> Option<f64> {
        if ctx.gravity.is_some() && option.uses_torques() {
            return None;
        }
        let maps = |b: Base| match b {
            Base::KmMaps => maps_units(Method::KmMaps, Method::Km),
            Base::SkcmMaps => maps_units(Method::SkcmMaps, Method::Skcm),
            Base::Km | Base::Skcm => 0.0,
        };
        let extra = match option.row().run {
            Run::Maps(b) => maps_units(option, b.method()),
            Run::Compensated(c) => {
                maps(c.base)
                    + (option.row().weight - c.base.method().row().weight).max(0.0)
                        / REFERENCE_TRAININGS
            }
            _ => return None,
        };
        let base = auto_bases(ctx)
            .iter()
            .map(|b| b.method().row().weight)
            .fold(0.0, f64::max);
        Some(planned_regions(ctx) as f64 * (base + extra))
    }
}

/// Units of a joint-map fit on its base's fit.
fn maps_units(maps: Method, base: Method) -> f64 {
    (maps.row().weight - base.row().weight).max(0.0)
}

/// The folds `auto` cross-validates with (5 when the options say 0).
pub(crate) fn auto_folds(ctx: &Context) -> usize {
    match ctx.opts.compensator.cv_folds {
        0 => 5,
        k => k,
    }
}

/// The bases `auto` weighs: KM, and SKCM when gravity loads a joint.
pub(crate) fn auto_bases(ctx: &Context) -> Vec<Base> {
    if ctx.gravity.is_some() {
        vec![Base::Km]
    } else {
        vec![Base::Km, Base::Skcm]
    }
}

/// `auto`'s candidate compensators on `base` (none needing torques without
/// gravity).
pub(crate) fn auto_compensators(ctx: &Context, base: Base) -> Vec<Method> {
    ctx.opts
        .compensator
        .auto_candidates
        .iter()
        .copied()
        .filter(|m| {
            m.compensated().is_some_and(|c| c.base == base)
                && (ctx.gravity.is_none() || !m.uses_torques())
        })
        .collect()
}

/// Whether `auto` runs a joint-map candidate on `base`.
fn auto_has_maps(ctx: &Context, base: Base) -> bool {
    ctx.opts
        .compensator
        .auto_candidates
        .iter()
        .any(|m| m.row().run == Run::Maps(base))
}

#[cfg(test)]
mod tests {
    use super::super::auto::run_auto;
    use super::super::fixture::Fixture;
    use super::*;

    /// `auto`'s plan counts the veto's refits: its share of the bar is one
    /// check over every region it may hold out, and the region refits of
    /// the check `auto` makes (`km-maps` against KM, on the simulated UR5
    /// of `fixture`) report inside that share, region by region. Every
    /// report stays in [0, 1] and never goes back, and the last is 1.
    #[test]
    fn the_plan_counts_the_veto_refits_and_progress_reaches_the_end() {
        let fixture = Fixture::measured(240);
        let opts = fixture.options(1);
        let ctx = fixture.context(&opts);
        let mut cache = Cache::default();
        let total = Planner::from_cache(&cache).auto(&ctx);
        let veto = Planner::veto(&ctx);
        let regions = planned_regions(&ctx);
        // Four clusters and two edges of each of the six joints.
        assert_eq!(regions, 4 + 2 * 6);
        let per_region = Method::Km.row().weight + maps_units(Method::KmMaps, Method::Km);
        assert!((veto - regions as f64 * per_region).abs() <= 1e-12 * veto);
        assert!(veto > 0.0 && veto < total);
        let mut fractions = Vec::new();
        let out = run_auto(&ctx, &mut cache, &mut |s| {
            fractions.push(s.fraction);
            true
        })
        .unwrap();
        let auto = out.auto.unwrap();
        let checks = &auto.decision.blocked_checks;
        assert_eq!(checks.len(), 1, "{}", auto.reason);
        assert_eq!(checks[0].option, Method::KmMaps);
        assert_eq!(checks[0].regions + checks[0].edges, regions);
        for w in fractions.windows(2) {
            assert!(w[1] >= w[0], "{} after {}", w[1], w[0]);
        }
        assert!(fractions.iter().all(|f| (0.0..=1.0).contains(f)));
        assert_eq!(fractions.last().copied(), Some(1.0));
        // The check's share starts where the rest of `auto` ends; each of
        // the option's and the base's region refits reports in it.
        let start = (total - veto) / total;
        let inside = fractions
            .iter()
            .filter(|f| **f > start + 1e-12 && **f < 1.0)
            .count();
        assert!(
            inside >= 2 * regions - 1,
            "{inside} reports inside the veto's share"
        );
    }

    /// Before `auto` has chosen, one check of its veto is planned at the
    /// median of its candidates' checks: of KM-GP (one GP training on KM's
    /// refits), KM+maps (a joint-map fit) and KM+maps-GP (both), the
    /// joint maps'. With the fixture's single candidate the plan is that
    /// candidate's check.
    #[test]
    fn the_veto_is_planned_at_the_median_candidates_check() {
        let fixture = Fixture::measured(240);
        let mut opts = fixture.options(1);
        let ctx = fixture.context(&opts);
        assert_eq!(
            Planner::veto(&ctx),
            Planner::veto_of(&ctx, Method::KmMaps).unwrap()
        );
        opts.compensator.auto_candidates = vec![Method::KmMapsGp, Method::KmGp, Method::KmMaps];
        let ctx = fixture.context(&opts);
        let each: Vec<f64> = opts
            .compensator
            .auto_candidates
            .iter()
            .map(|m| Planner::veto_of(&ctx, *m).unwrap())
            .collect();
        assert!(each[1] < each[2] && each[2] < each[0], "{each:?}");
        assert_eq!(Planner::veto(&ctx), each[2]);
        assert_eq!(Planner::veto_of(&ctx, Method::Km), None);
    }
}
