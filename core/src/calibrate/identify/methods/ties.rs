//! The tie rule `auto` chooses among its options by ([`break_ties`]).
//!
//! Each option (a base alone, a base with a compensator, joint maps with or
//! without a compensator on them) is a [`Contender`]: its cross-validated
//! mean and max on the pool [mm], its error on the spatially blocked folds
//! (whole regions of joint space held out, `compensate::select`) [mm], the
//! physics its base models ([`Physics`]) and its count of fitted quantities.
//!
//! Two figures differ when the larger exceeds the smaller by more than the
//! relative margin `m` (`CompensatorOptions::tie_margin`, 5 % by default, the
//! bar `min_gain` sets for taking a compensator at all): `b − a > m·a`. The
//! rule, in order:
//!
//! 1. the lowest cross-validated mean wins outright when every other option's
//!    mean differs from it ([`DecidingStep::Mean`]); otherwise the options
//!    whose mean does not differ from the lowest are **tied** and go on;
//! 2. the lowest blocked-fold mean, keeping those that do not differ from it
//!    (skipped unless every tied option has one);
//! 3. the lowest cross-validated max, the same way;
//! 4. the most physics: SKCM before KM, an identified payload before none;
//! 5. the fewest fitted quantities;
//! 6. still tied: the lowest cross-validated mean ([`DecidingStep::Unbroken`]).
//!
//! The first step that leaves one option decides ([`TieOutcome::step`]); the
//! runner-up is the best of the options that step removed, and the margin is
//! by how much the winner led it there. A relative margin, not the folds' own
//! scatter, makes the outcome independent of how the folds were dealt when
//! the options are within it of each other: reshuffled folds move the means
//! by far less than 5 %, and the later steps compare the same margins.

use super::{Method, Run};
use serde::{Deserialize, Serialize};

/// How much physics an option's base models, least first: a closed set
/// whose order is the rule's step 4.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Physics {
    /// KM: geometry alone.
    Geometry,
    /// SKCM: geometry and joint compliance.
    Compliance,
    /// SKCM with the payload identified: geometry, compliance and payload.
    CompliancePayload,
}

impl Physics {
    /// Every level, least physics first.
    pub const ALL: [Physics; 3] = [
        Physics::Geometry,
        Physics::Compliance,
        Physics::CompliancePayload,
    ];

    /// What the base of `method` models, from its row of the method table.
    pub fn of(method: Method) -> Physics {
        match method.row().run {
            Run::SkcmPayload => Physics::CompliancePayload,
            _ if method.uses_compliance() => Physics::Compliance,
            _ => Physics::Geometry,
        }
    }

    /// The serialised name.
    pub fn name(self) -> &'static str {
        match self {
            Physics::Geometry => "geometry",
            Physics::Compliance => "compliance",
            Physics::CompliancePayload => "compliance_payload",
        }
    }
}

/// One option as the tie rule weighs it.
#[derive(Debug, Clone, PartialEq)]
pub struct Contender {
    /// Cross-validated mean on the pool [mm].
    pub mean_mm: f64,
    /// Mean over the spatially blocked folds [mm]; `None` when they were not
    /// run for this option.
    pub blocked_mean_mm: Option<f64>,
    /// Cross-validated max on the pool [mm].
    pub max_mm: f64,
    /// What the option's base models.
    pub physics: Physics,
    /// Fitted quantities: identified parameters, map coefficients, three
    /// output weights per compensator unit.
    pub parameters: usize,
}

/// The step of the rule that decided ([`break_ties`]): a closed set, in the
/// rule's order, from which the names and labels derive.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DecidingStep {
    /// The lowest cross-validated mean, beyond the margin: no tie.
    Mean,
    /// The lowest error on the spatially blocked folds.
    BlockedFolds,
    /// The lowest cross-validated max.
    Max,
    /// The base that models more physics.
    Physics,
    /// Fewer fitted quantities.
    Parameters,
    /// Tied at every step: the lowest cross-validated mean.
    Unbroken,
}

impl DecidingStep {
    /// Every step, in the rule's order.
    pub const ALL: [DecidingStep; 6] = [
        DecidingStep::Mean,
        DecidingStep::BlockedFolds,
        DecidingStep::Max,
        DecidingStep::Physics,
        DecidingStep::Parameters,
        DecidingStep::Unbroken,
    ];

    /// The serialised name.
    pub fn name(self) -> &'static str {
        match self {
            DecidingStep::Mean => "mean",
            DecidingStep::BlockedFolds => "blocked_folds",
            DecidingStep::Max => "max",
            DecidingStep::Physics => "physics",
            DecidingStep::Parameters => "parameters",
            DecidingStep::Unbroken => "unbroken",
        }
    }

    /// What the step compares, for the report.
    pub fn label(self) -> &'static str {
        match self {
            DecidingStep::Mean => "the lower cross-validated mean",
            DecidingStep::BlockedFolds => "the lower error on the spatially blocked folds",
            DecidingStep::Max => "the lower cross-validated max",
            DecidingStep::Physics => "the base that models more physics",
            DecidingStep::Parameters => "fewer fitted quantities",
            DecidingStep::Unbroken => "tied at every step, the lower cross-validated mean",
        }
    }

    /// The unit of [`TieOutcome::margin`] at this step.
    pub fn unit(self) -> &'static str {
        match self {
            DecidingStep::Mean
            | DecidingStep::BlockedFolds
            | DecidingStep::Max
            | DecidingStep::Unbroken => "mm",
            DecidingStep::Physics => "physics rank",
            DecidingStep::Parameters => "fitted quantities",
        }
    }
}

/// What the tie rule decided among the contenders (indices into them).
#[derive(Debug, Clone, PartialEq)]
pub struct TieOutcome {
    /// The chosen contender.
    pub winner: usize,
    /// Whether another option's mean was within the margin of the lowest.
    pub tie: bool,
    /// The step of the rule that decided.
    pub step: DecidingStep,
    /// The best of the options the deciding step removed (`None`: one
    /// contender).
    pub runner_up: Option<usize>,
    /// By how much the winner led the runner-up at the deciding step, in
    /// [`DecidingStep::unit`] (0 without a runner-up).
    pub margin: f64,
    /// The runner-up's cross-validated mean less the winner's [mm] (negative
    /// when a tie went to the option with the higher mean).
    pub mean_margin_mm: f64,
}

/// Whether `b` exceeds `a` by more than `margin` (relative to `a`).
fn above(b: f64, a: f64, margin: f64) -> bool {
    b - a > margin * a.abs()
}

/// The tie rule (module docs) over `contenders` with the relative margin
/// `margin`; `None` for no contenders. Non-finite figures lose against
/// finite ones.
pub fn break_ties(contenders: &[Contender], margin: f64) -> Option<TieOutcome> {
    let key = |v: f64| if v.is_finite() { v } else { f64::INFINITY };
    let by_mean = |a: &usize, b: &usize| {
        key(contenders[*a].mean_mm)
            .total_cmp(&key(contenders[*b].mean_mm))
            .then(a.cmp(b))
    };
    let mut order: Vec<usize> = (0..contenders.len()).collect();
    order.sort_by(by_mean);
    let best = *order.first()?;
    let lowest = key(contenders[best].mean_mm);
    let (mut alive, out): (Vec<usize>, Vec<usize>) = order
        .iter()
        .partition(|i| !above(key(contenders[**i].mean_mm), lowest, margin));
    let outcome =
        |winner: usize, step: DecidingStep, runner_up: Option<usize>, m: f64| TieOutcome {
            winner,
            tie: step != DecidingStep::Mean,
            step,
            runner_up,
            margin: runner_up.map_or(0.0, |_| m),
            mean_margin_mm: runner_up.map_or(0.0, |r| {
                key(contenders[r].mean_mm) - key(contenders[winner].mean_mm)
            }),
        };
    if alive.len() == 1 {
        let r = out.first().copied();
        let m = r.map_or(0.0, |r| key(contenders[r].mean_mm) - lowest);
        return Some(outcome(best, DecidingStep::Mean, r, m));
    }
    // Steps 2 and 3: keep those within the margin of the lowest figure.
    type Figure = fn(&Contender) -> Option<f64>;
    let figures: [(DecidingStep, Figure); 2] = [
        (DecidingStep::BlockedFolds, |c| c.blocked_mean_mm),
        (DecidingStep::Max, |c| Some(c.max_mm)),
    ];
    for (step, figure) in figures {
        let Some(values) = alive
            .iter()
            .map(|i| figure(&contenders[*i]).map(key))
            .collect::<Option<Vec<f64>>>()
        else {
            continue;
        };
        let low = values.iter().copied().fold(f64::INFINITY, f64::min);
        type Scored = Vec<(usize, f64)>;
        let (keep, gone): (Scored, Scored) = alive
            .iter()
            .copied()
            .zip(values)
            .partition(|(_, v)| !above(*v, low, margin));
        if keep.len() == 1 {
            let (w, wv) = keep[0];
            let r = gone
                .iter()
                .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
            return Some(outcome(
                w,
                step,
                r.map(|r| r.0),
                r.map_or(0.0, |r| r.1 - wv),
            ));
        }
        alive = keep.into_iter().map(|k| k.0).collect();
    }
    // Step 4: the most physics.
    let most = alive.iter().map(|i| contenders[*i].physics).max()?;
    let (keep, gone): (Vec<usize>, Vec<usize>) =
        alive.iter().partition(|i| contenders[**i].physics == most);
    if keep.len() == 1 {
        let r = gone.iter().copied().max_by(|a, b| {
            contenders[*a]
                .physics
                .cmp(&contenders[*b].physics)
                .then(b.cmp(a))
        });
        let rank = |p: Physics| p as usize as f64;
        let m = r.map_or(0.0, |r| rank(most) - rank(contenders[r].physics));
        return Some(outcome(keep[0], DecidingStep::Physics, r, m));
    }
    alive = keep;
    // Step 5: the fewest fitted quantities.
    let fewest = alive.iter().map(|i| contenders[*i].parameters).min()?;
    let (keep, gone): (Vec<usize>, Vec<usize>) = alive
        .iter()
        .partition(|i| contenders[**i].parameters == fewest);
    if keep.len() == 1 {
        let r = gone
            .iter()
            .copied()
            .min_by_key(|i| (contenders[*i].parameters, *i));
        let m = r.map_or(0.0, |r| (contenders[r].parameters - fewest) as f64);
        return Some(outcome(keep[0], DecidingStep::Parameters, r, m));
    }
    // Step 6: `keep` is still in the order of the means.
    let (w, r) = (keep[0], keep[1]);
    let m = key(contenders[r].mean_mm) - key(contenders[w].mean_mm);
    Some(outcome(w, DecidingStep::Unbroken, Some(r), m))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(mean: f64, blocked: Option<f64>, max: f64, physics: Physics, n: usize) -> Contender {
        Contender {
            mean_mm: mean,
            blocked_mean_mm: blocked,
            max_mm: max,
            physics,
            parameters: n,
        }
    }

    use Physics::{Compliance as Skcm, CompliancePayload as Payload, Geometry as Km};

    #[test]
    fn a_mean_beyond_the_margin_wins_outright() {
        // 0.090 against 0.100: 11 % apart, beyond 5 %; the loser's better
        // blocked folds and max do not matter.
        let t = break_ties(
            &[
                c(0.100, Some(0.1), 0.2, Skcm, 30),
                c(0.090, Some(0.5), 0.9, Km, 20),
            ],
            0.05,
        )
        .unwrap();
        assert_eq!(
            t,
            TieOutcome {
                winner: 1,
                tie: false,
                step: DecidingStep::Mean,
                runner_up: Some(0),
                margin: 0.100 - 0.090,
                mean_margin_mm: 0.100 - 0.090,
            }
        );
        let one = break_ties(&[c(0.3, None, 1.0, Km, 5)], 0.05).unwrap();
        assert_eq!((one.winner, one.tie, one.runner_up), (0, false, None));
        assert_eq!(one.margin, 0.0);
        assert_eq!(break_ties(&[], 0.05), None);
    }

    /// The figures of the real UR10 where `km-maps` won on a 0.4 % lower
    /// mean: a tie, which the blocked folds break for `skcm-maps`.
    #[test]
    fn a_near_tie_goes_to_the_lower_blocked_fold_error() {
        let km_maps = c(0.0939, Some(0.160), 1.13, Km, 200);
        let skcm_maps = c(0.0943, Some(0.120), 0.625, Skcm, 206);
        let t = break_ties(&[km_maps.clone(), skcm_maps.clone()], 0.05).unwrap();
        assert_eq!(
            (t.winner, t.tie, t.step),
            (1, true, DecidingStep::BlockedFolds)
        );
        assert_eq!(t.runner_up, Some(0));
        assert!((t.margin - 0.040).abs() < 1e-12, "{t:?}");
        assert!((t.mean_margin_mm - (0.0939 - 0.0943)).abs() < 1e-12);
        // The order of the contenders does not matter.
        let t = break_ties(&[skcm_maps, km_maps], 0.05).unwrap();
        assert_eq!(
            (t.winner, t.step, t.runner_up),
            (0, DecidingStep::BlockedFolds, Some(1))
        );
    }

    #[test]
    fn each_later_step_decides_when_the_earlier_ones_tie() {
        // Blocked folds within 5 % of each other: the max decides.
        let t = break_ties(
            &[
                c(0.100, Some(0.150), 0.40, Km, 10),
                c(0.102, Some(0.155), 0.30, Km, 10),
            ],
            0.05,
        )
        .unwrap();
        assert_eq!(
            (t.winner, t.step, t.runner_up),
            (1, DecidingStep::Max, Some(0))
        );
        assert!((t.margin - 0.10).abs() < 1e-12);
        // Blocked folds missing on one: that step is skipped, max within the
        // margin, physics decides for SKCM.
        let t = break_ties(
            &[
                c(0.100, None, 0.40, Km, 10),
                c(0.102, Some(0.155), 0.41, Skcm, 16),
            ],
            0.05,
        )
        .unwrap();
        assert_eq!(
            (t.winner, t.step, t.margin),
            (1, DecidingStep::Physics, 1.0)
        );
        // A stated payload before none.
        let t = break_ties(
            &[
                c(0.100, None, 0.40, Skcm, 16),
                c(0.101, None, 0.40, Payload, 20),
            ],
            0.05,
        )
        .unwrap();
        assert_eq!((t.winner, t.step), (1, DecidingStep::Physics));
        // Same physics: fewer fitted quantities.
        let t = break_ties(
            &[
                c(0.100, None, 0.40, Skcm, 26),
                c(0.101, None, 0.40, Skcm, 16),
            ],
            0.05,
        )
        .unwrap();
        assert_eq!(
            (t.winner, t.step, t.margin),
            (1, DecidingStep::Parameters, 10.0)
        );
        // Equal everywhere but the mean: the lower mean, said to be unbroken.
        let t = break_ties(
            &[
                c(0.101, None, 0.40, Skcm, 16),
                c(0.100, None, 0.40, Skcm, 16),
            ],
            0.05,
        )
        .unwrap();
        assert_eq!(
            (t.winner, t.step, t.runner_up),
            (1, DecidingStep::Unbroken, Some(0))
        );
        assert!(t.tie);
    }

    /// Three options: the one beyond the margin drops out at the mean; of the
    /// two left the blocked folds decide, and the runner-up is the one the
    /// blocked folds removed, not the one the mean did.
    #[test]
    fn the_runner_up_is_the_one_the_deciding_step_removed() {
        let t = break_ties(
            &[
                c(0.200, Some(0.01), 0.1, Payload, 1),
                c(0.100, Some(0.30), 0.4, Km, 10),
                c(0.104, Some(0.20), 0.4, Skcm, 16),
            ],
            0.05,
        )
        .unwrap();
        assert_eq!(
            (t.winner, t.step, t.runner_up),
            (2, DecidingStep::BlockedFolds, Some(1))
        );
        assert!((t.margin - 0.10).abs() < 1e-12);
    }

    /// Near-tied means moved about by reshuffled folds (within the margin)
    /// give the same winner.
    #[test]
    fn the_outcome_does_not_depend_on_small_shifts_of_the_means() {
        for shift in [-0.002, -0.001, 0.0, 0.001, 0.002] {
            let t = break_ties(
                &[
                    c(0.0939 + shift, Some(0.160), 1.13, Km, 200),
                    c(0.0943 - shift, Some(0.120), 0.625, Skcm, 206),
                ],
                0.05,
            )
            .unwrap();
            assert_eq!(
                (t.winner, t.step),
                (1, DecidingStep::BlockedFolds),
                "{shift}"
            );
        }
    }

    #[test]
    fn a_non_finite_mean_loses() {
        let t = break_ties(
            &[c(f64::NAN, None, 0.1, Payload, 1), c(0.5, None, 1.0, Km, 9)],
            0.05,
        )
        .unwrap();
        assert_eq!((t.winner, t.step), (1, DecidingStep::Mean));
    }

    #[test]
    fn names_and_labels_derive_from_the_closed_sets() {
        let names: Vec<&str> = DecidingStep::ALL.iter().map(|s| s.name()).collect();
        for (s, n) in DecidingStep::ALL.iter().zip(&names) {
            assert_eq!(serde_json::to_value(s).unwrap(), *n);
            assert!(!s.label().is_empty() && !s.unit().is_empty());
        }
        let mut sorted = DecidingStep::ALL.to_vec();
        sorted.sort();
        assert_eq!(sorted, DecidingStep::ALL);
        for p in Physics::ALL {
            assert_eq!(serde_json::to_value(p).unwrap(), p.name());
        }
        assert!(Physics::ALL.windows(2).all(|w| w[0] < w[1]));
        assert_eq!(Physics::of(Method::KmMapsGp), Physics::Geometry);
        assert_eq!(Physics::of(Method::SkcmMaps), Physics::Compliance);
        assert_eq!(Physics::of(Method::SkcmGp), Physics::Compliance);
        assert_eq!(Physics::of(Method::SkcmPayload), Physics::CompliancePayload);
    }
}
