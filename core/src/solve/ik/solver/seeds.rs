//! Seeds of the solver (see the parent module's "Seeds"): closed-form
//! branches ordered by the requested branch, the joint seed or the middle of
//! the ranges, each corrected for the calibrated model's deviation; a
//! deterministic Halton multi-start for models without a closed form.
//! Joint values in the model convention [rad].

use super::eval::Local;
use super::types::{Goal, IkSolver, SolveOptions};
use crate::model::Pose;
use crate::solve::ik::analytic::{AnalyticIk, AnalyticSolution};
use crate::solve::ik::config::Configuration;
use nalgebra::Matrix3;

/// Radical inverse in base `b` (Halton sequences).
pub(super) fn halton(mut i: usize, b: usize) -> f64 {
    let (mut f, mut r) = (1.0, 0.0);
    while i > 0 {
        f /= b as f64;
        r += f * (i % b) as f64;
        i /= b;
    }
    r
}

/// A joint range capped to ±π: `(lo, hi)`.
pub(super) fn capped_span(l: [f64; 2]) -> (f64, f64) {
    (
        l[0].max(-std::f64::consts::PI),
        l[1].min(std::f64::consts::PI),
    )
}

/// The `i`-th Halton point within the limits (capped to ±π), one prime base per joint.
pub(super) fn halton_joints(limits: &[[f64; 2]], i: usize) -> Vec<f64> {
    const PRIMES: [usize; 8] = [2, 3, 5, 7, 11, 13, 17, 19];
    limits
        .iter()
        .enumerate()
        .map(|(k, l)| {
            let (lo, hi) = capped_span(*l);
            lo + (hi - lo) * halton(i, PRIMES[k % PRIMES.len()])
        })
        .collect()
}

impl IkSolver {
    /// Ordered seeds for a goal in the base frame.
    pub(super) fn seeds(&self, goal: &Goal, options: &SolveOptions) -> Seeds {
        let Some(analytic) = &self.analytic else {
            return self.numeric_seeds(options);
        };
        let hint = options.seed.as_deref();
        // The rule's reference (`ik::choice`): the seed, else the middle of the ranges.
        let reference = crate::solve::ik::choice::reference(analytic.limits(), hint);
        // Orientation for the closed form: the goal's, or the predicted one at the reference.
        let rotation = goal.rotation.unwrap_or_else(|| {
            self.model
                .predict_base(&reference)
                .map(|p| p.r)
                .unwrap_or_else(|_| Matrix3::identity())
        });
        let target = Pose::new(rotation, goal.position);
        let sols = analytic.solve_with_margin(&target, hint, self.settings.seed_reach_margin);
        let slack = self.settings.seed_limit_slack_rad;
        // The reach test needs the target's own orientation; any unclamped
        // branch means the wrist point is inside the nominal workspace.
        let oriented = goal.rotation.is_some() && !options.position_only;
        let reach_excess_m = if !oriented {
            f64::NEG_INFINITY
        } else if sols.is_empty() {
            analytic.reach_excess(&target)
        } else {
            sols.iter()
                .map(|s| s.reach_excess_m)
                .fold(f64::INFINITY, f64::min)
        };
        // Strictly within the limits (the seeds allow the slack).
        let reachable: Vec<Configuration> = sols
            .iter()
            .filter(|s| !s.clamped && self.limit_violation(&s.q) <= 1e-9)
            .map(|s| s.configuration)
            .collect();
        let branch_exists = options
            .branch
            .is_some_and(|b| sols.iter().any(|s| !s.clamped && s.configuration == b));
        // The required branch exists in the closed form, but only outside the limits.
        let branch_out_of_limits = oriented
            && options.branch.is_some_and(|b| {
                let mine: Vec<&AnalyticSolution> =
                    sols.iter().filter(|s| s.configuration == b).collect();
                !mine.is_empty()
                    && mine
                        .iter()
                        .all(|s| !s.clamped && self.limit_violation(&s.q) > slack)
            });
        let cands = self.ranked(sols, options.branch, &reference);
        let any_out_of_limits = cands.iter().any(|c| c.1 > slack);
        let all_out_of_limits = !cands.is_empty() && cands.iter().all(|c| c.1 > slack);
        let all_clamped = cands.iter().all(|c| c.0.clamped);
        // In-limit branches first; slightly out-of-limit ones after them (the
        // projected iteration may still find an in-limit calibrated solution).
        let mut list: Vec<Seed> = cands
            .iter()
            .filter(|c| c.1 <= slack)
            .map(|c| Seed {
                q: c.0.q.to_vec(),
                configuration: Some(c.0.configuration),
                on_target: !c.0.clamped,
            })
            .collect();
        let in_limit_seeds = list.len();
        // Then the out-of-limit branches, clamped into the limits.
        list.extend(cands.iter().filter(|c| c.1 > slack).map(|c| Seed {
            q: self.clamp_to_limits(&c.0.q),
            configuration: None,
            on_target: false,
        }));
        // Position-only goals and targets without closed-form seeds also start
        // from the joint seed itself.
        if let Some(h) = hint {
            if in_limit_seeds == 0 || goal.rotation.is_none() || options.position_only {
                let at = usize::from(in_limit_seeds > 0);
                list.insert(
                    at,
                    Seed {
                        q: self.clamp_to_limits(h),
                        configuration: None,
                        on_target: false,
                    },
                );
            }
        }
        let mut max_attempts = self.settings.max_attempts;
        if in_limit_seeds == 0 || goal.rotation.is_none() || options.position_only {
            // No in-limit closed-form seed (beyond the nominal reach, a branch the
            // nominal model cannot assemble, a double singularity), or a position-only goal
            // whose preferred orientation may be out of reach: multi-start on
            // the calibrated model lets it have its say.
            let extra = self.numeric_list(options, self.settings.numeric_fallback_starts);
            max_attempts = list.len().min(self.settings.max_attempts) + extra.len();
            list.truncate(self.settings.max_attempts);
            list.extend(extra);
        }
        Seeds {
            target,
            list,
            max_attempts,
            any_out_of_limits,
            all_out_of_limits,
            all_clamped,
            from_closed_form: true,
            reach_excess_m,
            reachable,
            branch_out_of_limits,
            branch_exists,
        }
    }

    /// The closed-form solutions in `branch` (any without one), each with its
    /// limit violation [rad] and distance to `reference` [rad²]: within the
    /// limits before beyond them, unclamped before clamped, then nearest
    /// first (the rule of [`crate::solve::ik::choice`]).
    fn ranked(
        &self,
        sols: Vec<AnalyticSolution>,
        branch: Option<Configuration>,
        reference: &[f64],
    ) -> Vec<(AnalyticSolution, f64, f64)> {
        let mut cands: Vec<(AnalyticSolution, f64, f64)> = sols
            .into_iter()
            .filter(|s| branch.is_none_or(|b| b == s.configuration))
            .map(|s| {
                let violation = self.limit_violation(&s.q);
                let dist = crate::solve::ik::choice::distance(&s.q, reference);
                (s, violation, dist)
            })
            .collect();
        cands.sort_by(|a, b| {
            let ka = (a.1 > 0.0, a.0.clamped);
            let kb = (b.1 > 0.0, b.0.clamped);
            ka.cmp(&kb).then(a.2.total_cmp(&b.2))
        });
        cands
    }

    pub(super) fn numeric_seeds(&self, options: &SolveOptions) -> Seeds {
        let list = self.numeric_list(options, self.settings.numeric_starts);
        Seeds {
            target: Pose::identity(),
            max_attempts: list.len(),
            list,
            any_out_of_limits: false,
            all_out_of_limits: false,
            all_clamped: false,
            from_closed_form: false,
            reach_excess_m: f64::NEG_INFINITY,
            reachable: Vec::new(),
            branch_out_of_limits: false,
            branch_exists: false,
        }
    }

    /// Multi-start seeds: the joint seed, the middle of the ranges, then
    /// `count` Halton points within the limits (capped to ±π).
    pub(super) fn numeric_list(&self, options: &SolveOptions, count: usize) -> Vec<Seed> {
        let mut list = Vec::new();
        if let Some(s) = &options.seed {
            list.push(self.clamp_to_limits(s));
        }
        list.push(
            self.limits
                .iter()
                .map(|l| {
                    let (lo, hi) = capped_span(*l);
                    0.5 * (lo + hi)
                })
                .collect(),
        );
        for i in 1..=count {
            list.push(halton_joints(&self.limits, i));
        }
        list.into_iter()
            .map(|q| Seed {
                q,
                configuration: None,
                on_target: false,
            })
            .collect()
    }

    pub(super) fn limit_violation(&self, q: &[f64]) -> f64 {
        q.iter()
            .zip(&self.limits)
            .map(|(v, l)| (l[0] - v).max(v - l[1]).max(0.0))
            .fold(0.0, f64::max)
    }

    pub(super) fn clamp_to_limits(&self, q: &[f64]) -> Vec<f64> {
        q.iter()
            .zip(&self.limits)
            .map(|(v, l)| v.clamp(l[0], l[1]))
            .collect()
    }

    /// Re-solves the closed form for the target moved by the calibrated
    /// model's deviation at the seed, in the thesis's branch (see
    /// `IkSettings::seed_corrections`).
    pub(super) fn corrected_seed(
        &self,
        analytic: &AnalyticIk,
        target: &Pose,
        seed: &Seed,
        configuration: Configuration,
    ) -> CorrectedSeed {
        let mut out = CorrectedSeed {
            q: seed.q.clone(),
            evaluations: 0,
            beyond_reach: false,
            expansion: None,
        };
        for k in 0..self.settings.seed_corrections {
            // An unclamped closed-form branch is where the seed model reaches the target.
            let seed_pose = (k == 0 && seed.on_target).then_some(target);
            // The first correction's prediction, at the seed, also expands
            // the compensator there (the runs from this seed start on it).
            let mut expansion = (k == 0 && self.prepared.has_compensator()).then(Local::new);
            let Some(moved) = self.moved_target(target, &out.q, seed_pose, expansion.as_mut())
            else {
                break;
            };
            out.expansion = out.expansion.or(expansion);
            out.evaluations += 1;
            let best = analytic.solve_branch(
                &moved,
                configuration,
                Some(&out.q),
                self.settings.seed_reach_margin,
            );
            match best {
                Some(s) => {
                    out.beyond_reach = s.reach_excess_m > 0.0;
                    out.q.copy_from_slice(&s.q);
                }
                None => {
                    // Beyond even the seed margin in this branch.
                    out.beyond_reach = true;
                    break;
                }
            }
        }
        out
    }
}

/// A closed-form seed after `IkSettings::seed_corrections`.
pub(super) struct CorrectedSeed {
    pub(super) q: Vec<f64>,
    /// Evaluations of the prediction used.
    pub(super) evaluations: usize,
    /// The moved target lies outside the nominal workspace of the thesis's
    /// branch (its wrist point beyond the arm's reach in that shoulder and
    /// elbow configuration): the calibrated model most likely cannot reach
    /// the target in this branch either, so the solver tries it after the
    /// others.
    pub(super) beyond_reach: bool,
    /// The compensator expanded at the seed (none without a compensator or
    /// a correction).
    pub(super) expansion: Option<Local>,
}

pub(super) struct Seed {
    pub(super) q: Vec<f64>,
    /// Closed-form branch of the seed (enables the seed corrections).
    pub(super) configuration: Option<Configuration>,
    /// The seed model's forward kinematics at `q` is the target (an
    /// unclamped closed-form branch), up to rounding.
    pub(super) on_target: bool,
}

/// The starts of one seed: the corrected closed-form one first (when it
/// differs), then the plain one; both start on `expansion` (the joint maps'
/// and the compensator's at the seed, from its correction).
pub(super) struct Starts {
    pub(super) list: Vec<Vec<f64>>,
    /// The corrected target lies beyond the thesis's branch's reach: tried
    /// after the other seeds.
    pub(super) beyond_reach: bool,
    pub(super) expansion: Option<Local>,
    /// Model evaluations the correction took.
    pub(super) evaluations: usize,
}

impl IkSolver {
    /// The starts of `seed` for `target` (base frame).
    pub(super) fn starts(&self, target: &Pose, seed: &Seed) -> Starts {
        let mut out = Starts {
            list: Vec::with_capacity(2),
            beyond_reach: false,
            expansion: None,
            evaluations: 0,
        };
        if let (Some(a), Some(c)) = (&self.analytic, seed.configuration) {
            let corrected = self.corrected_seed(a, target, seed, c);
            out.evaluations = corrected.evaluations;
            out.beyond_reach = corrected.beyond_reach;
            out.expansion = corrected.expansion;
            if corrected
                .q
                .iter()
                .zip(&seed.q)
                .any(|(x, y)| (x - y).abs() > 1e-9)
            {
                out.list.push(corrected.q);
            }
        }
        out.list.push(seed.q.clone());
        out
    }
}

pub(super) struct Seeds {
    /// The pose the closed form was solved for (base frame).
    pub(super) target: Pose,
    pub(super) list: Vec<Seed>,
    /// How many of `list` to try.
    pub(super) max_attempts: usize,
    pub(super) any_out_of_limits: bool,
    pub(super) all_out_of_limits: bool,
    pub(super) all_clamped: bool,
    pub(super) from_closed_form: bool,
    /// Signed distance [m] of the wrist point outside the nominal workspace
    /// ([`AnalyticIk::reach_excess`]); −∞ when the target's orientation is
    /// free (no reach test).
    pub(super) reach_excess_m: f64,
    /// Closed-form branches reaching the target within the limits (slack included).
    pub(super) reachable: Vec<Configuration>,
    /// The required branch exists only outside the limits (beyond the slack).
    pub(super) branch_out_of_limits: bool,
    /// The required branch reaches the target in the closed form (limits aside).
    pub(super) branch_exists: bool,
}
