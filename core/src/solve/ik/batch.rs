//! Batch and path solving.
//!
//! - **Batch**: targets are independent and solved in parallel on rayon
//!   (`IkSettings::threads` workers, or rayon's global pool when 0), in chunks
//!   of at least 8 targets; the output order is the input order.
//! - **Path**: targets are solved in order; each is seeded with the previous
//!   solution and kept in its configuration branch (the requested branch, or
//!   the branch of the first solved target). A change of any joint larger than
//!   `IkSettings::jump_threshold_rad` from the previous solved target is
//!   reported as a [`JointJump`] (controller convention, degrees).
//!
//! A bad target only fails itself (per-target `FailureReason`).

use super::invalid::TargetError;
use super::solver::{Goal, IkSolution, IkSolver, SolveOptions};
use super::targets::JointJump;
use crate::solve::ik::config::Configuration;
use rayon::prelude::*;

impl IkSolver {
    /// Solves independent goals (in `options.frame`) in parallel.
    pub fn solve_batch(&self, goals: &[Goal], options: &SolveOptions) -> Vec<IkSolution> {
        self.parallel_map(goals, |g| self.solve_goal(g, options))
    }

    /// Solves goals as a path: seeded by the previous solution, same branch.
    pub fn solve_path(
        &self,
        goals: &[Goal],
        options: &SolveOptions,
    ) -> Vec<(IkSolution, Option<JointJump>)> {
        let checked: Vec<Result<Goal, TargetError>> = goals.iter().map(|g| Ok(*g)).collect();
        self.solve_path_checked(&checked, options)
    }

    pub(crate) fn solve_batch_checked(
        &self,
        goals: &[Result<Goal, TargetError>],
        options: &SolveOptions,
    ) -> Vec<IkSolution> {
        self.parallel_map(goals, |g| match g {
            Ok(g) => self.solve_goal(g, options),
            Err(e) => IkSolution::invalid(e.clone()),
        })
    }

    fn parallel_map<T: Sync, R: Send>(
        &self,
        items: &[T],
        f: impl Fn(&T) -> R + Sync + Send,
    ) -> Vec<R> {
        let run = || items.par_iter().with_min_len(8).map(&f).collect();
        let threads = self.settings().threads;
        if threads == 0 {
            return run();
        }
        match rayon::ThreadPoolBuilder::new().num_threads(threads).build() {
            Ok(pool) => pool.install(run),
            Err(_) => items.iter().map(&f).collect(),
        }
    }

    pub(crate) fn solve_path_checked(
        &self,
        goals: &[Result<Goal, TargetError>],
        options: &SolveOptions,
    ) -> Vec<(IkSolution, Option<JointJump>)> {
        let mut prev: Option<(Vec<f64>, Option<Configuration>)> = None;
        let mut out = Vec::with_capacity(goals.len());
        for g in goals {
            let sol = match g {
                Err(e) => IkSolution::invalid(e.clone()),
                Ok(g) => self.path_step(g, options, prev.as_ref()),
            };
            let mut jump = None;
            if sol.converged {
                if let Some((q_prev, _)) = &prev {
                    jump = self.jump(q_prev, &sol.q);
                }
                prev = Some((sol.q.clone(), sol.branch));
            }
            out.push((sol, jump));
        }
        out
    }

    fn path_step(
        &self,
        goal: &Goal,
        options: &SolveOptions,
        prev: Option<&(Vec<f64>, Option<Configuration>)>,
    ) -> IkSolution {
        let Some((q_prev, branch_prev)) = prev else {
            return self.solve_goal(goal, options);
        };
        let want = options.branch.or(*branch_prev);
        let mut o = options.clone();
        o.seed = Some(q_prev.clone());
        o.branch = want;
        // Continuation from the previous solution first.
        let base = self.goal_to_base(goal, options.frame);
        let position_only = options.position_only || goal.rotation.is_none();
        let mut iterations = 0;
        if self.validate(goal, options).is_ok() && self.within_reach(&base) {
            let r = self.refine(&base, q_prev, position_only);
            iterations = r.iterations;
            if r.converged && (want.is_none() || self.configuration(&r.q) == want) {
                return self.solution(&base, r, iterations, None);
            }
        }
        let mut s = self.solve_goal(goal, &o);
        s.iterations += iterations;
        s
    }

    fn jump(&self, a: &[f64], b: &[f64]) -> Option<JointJump> {
        let (k, d) = a
            .iter()
            .zip(b)
            .map(|(x, y)| y - x)
            .enumerate()
            .max_by(|x, y| x.1.abs().total_cmp(&y.1.abs()))?;
        if d.abs() > self.settings().jump_threshold_rad {
            let sign = self.model().nominal.links[k].sign;
            Some(JointJump {
                joint: k + 1,
                delta_deg: (d * sign).to_degrees(),
            })
        } else {
            None
        }
    }
}
