//! Damped Newton (Levenberg–Marquardt) on the compensated prediction: the
//! step, the error vector and the weighted Jacobian of the parent module's
//! header, with Nielsen's damping rule and projection onto the joint limits.
//! Frames: base frame; units: m, rad.
//!
//! One generic iteration (`refine_in`): six-joint models run it on
//! fixed-size (stack) matrices, others on dynamic ones (compared in the tests).
//! The step's system `J_w J_wᵀ + λ² I` is always 6×6: a position-only goal has
//! zero orientation rows in `J_w` and `e` and a unit diagonal there, which
//! decouples them (their solution is 0), so the step is the 3-row
//! minimum-norm step of the parent module's header. The prediction and its
//! Jacobian come from the prepared model (`solver/eval.rs`): trial steps take
//! the joint maps and the compensator from their expansion at the last
//! evaluation that expanded them (the chain itself is always exact; the
//! compensator's expansion at a closed-form seed is its rough prediction, and
//! a run whose start lies where that expansion is not expected to hold,
//! `PreparedModel::expansion_holds`, expands it roughly at its start); where
//! the expanded prediction meets the tolerance, the exact one is evaluated
//! there, and the iteration ends if it meets the tolerance too or goes on
//! expanded there. The residuals reported are always those of the exact
//! prediction.
//!
//! Kept beside the generic LM driver (`optim::lm`; the same iteration on it is
//! `newton/driver.rs`): on `cargo bench -p robocal-core --bench ik_newton`
//! (YS100, one refinement from 0.05 rad off) the fixed-size iteration is
//! about 1.4× faster, 6.7 µs against 9.6 µs per refinement (best of 8 runs;
//! medians 8.2 against 14.8 µs on a loaded 2-core machine).

use super::eval::{CompensatorAt, Local};
use super::*;

mod driver;
use nalgebra::{
    allocator::Allocator, DefaultAllocator, Dim, Dyn, Matrix6, OMatrix, OVector, Vector6, U1, U6,
};

/// Quasi-Newton Jacobian of `N` joints (rows `[v; ω]`).
type Jac<D> = OMatrix<f64, U6, D>;

/// Nielsen's damping μ = λ² [m²] and its growth factor ν.
struct Nielsen {
    mu: f64,
    nu: f64,
}

impl Nielsen {
    fn new(lambda: f64) -> Self {
        Nielsen {
            mu: lambda * lambda,
            nu: 2.0,
        }
    }

    /// A step failed or did not lower the cost: μ grows by ν, ν doubles.
    fn reject(&mut self) {
        self.mu = (self.mu * self.nu).max(1e-18);
        self.nu *= 2.0;
    }

    /// A step lowered the cost with gain ratio `rho`.
    fn accept(&mut self, rho: f64) {
        self.mu *= (1.0 - (2.0 * rho - 1.0).powi(3)).max(1.0 / 3.0);
        self.mu = self.mu.max(1e-30);
        self.nu = 2.0;
    }
}

impl Refined {
    /// A run whose prediction failed after `iterations` evaluations at `q`.
    fn failed_evaluation(q: Vec<f64>, iterations: usize) -> Refined {
        Refined {
            q,
            converged: false,
            position_residual_m: f64::INFINITY,
            orientation_residual_rad: f64::INFINITY,
            iterations,
            at_limit: false,
            sigma_min: f64::NAN,
            failed_evaluation: true,
        }
    }
}

impl IkSolver {
    /// Projects a trial joint value onto the limits, first trying the 2π
    /// equivalent (revolute joints with a range of 2π or more).
    pub(super) fn project(x: f64, l: [f64; 2]) -> (f64, bool) {
        let tau = std::f64::consts::TAU;
        let x = if x < l[0] && x + tau <= l[1] {
            x + tau
        } else if x > l[1] && x - tau >= l[0] {
            x - tau
        } else {
            x
        };
        (x.clamp(l[0], l[1]), x < l[0] || x > l[1])
    }

    /// Weighted error vector `[p* − p; L·log(R*·Rᵀ)]` (orientation rows 0 for
    /// position-only goals) and the unweighted residual norms.
    pub(super) fn error(
        &self,
        goal: &Goal,
        pose: &Pose,
        position_only: bool,
    ) -> (Vector6<f64>, f64, f64) {
        let ep = goal.position - pose.p;
        let er = goal
            .rotation
            .map(|r| rotation_log(&(r * pose.r.transpose())))
            .unwrap_or_else(Vector3::zeros);
        let l = self.settings.orientation_length_m;
        let e = if position_only {
            Vector6::new(ep.x, ep.y, ep.z, 0.0, 0.0, 0.0)
        } else {
            Vector6::new(ep.x, ep.y, ep.z, er.x * l, er.y * l, er.z * l)
        };
        (e, ep.norm(), er.norm())
    }

    /// The weighted Jacobian: orientation rows times `L`, or 0 for
    /// position-only goals (which then decouple from the position rows in the
    /// step's 6×6 system).
    pub(super) fn weighted_jacobian<D: Dim>(&self, jac: &Jac<D>, position_only: bool) -> Jac<D>
    where
        DefaultAllocator: Allocator<U6, D>,
    {
        let mut j = jac.clone();
        let l = if position_only {
            0.0
        } else {
            self.settings.orientation_length_m
        };
        j.fixed_rows_mut::<3>(3).scale_mut(l);
        j
    }

    pub(super) fn done(&self, pos: f64, rot: f64, position_only: bool) -> bool {
        pos < self.settings.position_tolerance_m
            && (position_only || rot < self.settings.orientation_tolerance_rad)
    }

    /// Damped Newton from `q0` (model convention, rad) towards a goal in the
    /// base frame.
    pub fn refine(&self, goal: &Goal, q0: &[f64], position_only: bool) -> Refined {
        self.refine_with(goal, q0, position_only, self.settings.max_iterations)
    }

    /// [`IkSolver::refine`] with an explicit evaluation budget.
    pub fn refine_with(
        &self,
        goal: &Goal,
        q0: &[f64],
        position_only: bool,
        max_iterations: usize,
    ) -> Refined {
        self.refine_from(goal, q0, position_only, max_iterations, None)
    }

    /// [`IkSolver::refine_with`] starting on `expansion` (the joint maps and
    /// the compensator expanded at a nearby point, the closed-form seed's;
    /// see `PreparedModel::predict_expanded`) instead of expanding at `q0`.
    pub(super) fn refine_from(
        &self,
        goal: &Goal,
        q0: &[f64],
        position_only: bool,
        max_iterations: usize,
        expansion: Option<&Local>,
    ) -> Refined {
        let q = self.clamp_to_limits(q0);
        // Six joints on the stack (fixed-size matrices), others on the heap:
        // the same iteration.
        if q.len() == 6 {
            self.refine_in(U6, goal, q, position_only, max_iterations, expansion)
        } else {
            self.refine_in(
                Dyn(q.len()),
                goal,
                q,
                position_only,
                max_iterations,
                expansion,
            )
        }
    }

    /// The prediction at `q_start` and whether it is exact there, with the
    /// joint maps and the compensator expanded at the start (or taken
    /// expanded at a nearby point, `expansion`): trial steps use the
    /// expansion (`eval::Local`), and the exact prediction is checked, and
    /// expanded again, where the expanded one meets the tolerance.
    fn start<D: Dim>(
        &self,
        q_start: &[f64],
        expansion: Option<&Local>,
        jac: &mut Jac<D>,
        local: &mut Local,
    ) -> Option<(Pose, bool)>
    where
        DefaultAllocator: Allocator<U6, D>,
    {
        let linearised = self.prepared.has_local_terms();
        let near = |e: &Local| {
            self.prepared
                .expansion_holds(e, q_start, self.settings.position_tolerance_m)
        };
        let at = match expansion {
            Some(e) if linearised && near(e) => {
                local.clone_from(e);
                CompensatorAt::Kept
            }
            // Too far from that expansion's point: a rough expansion here.
            Some(_) if linearised => CompensatorAt::Rough,
            _ => CompensatorAt::Exact,
        };
        let start = self.prepared.predict_start(q_start, jac, at, local);
        start.map(|p| (p, local.is_exact_at(q_start)))
    }

    /// Smallest singular value of the weighted Jacobian's rows (3 for
    /// position-only goals) [m].
    fn sigma_min<D: Dim>(&self, jac: &Jac<D>, position_only: bool) -> f64
    where
        DefaultAllocator: Allocator<U6, D>,
    {
        let m = if position_only { 3 } else { 6 };
        let jw = self.weighted_jacobian(jac, position_only);
        DMatrix::from_fn(m, jw.ncols(), |i, j| jw[(i, j)])
            .singular_values()
            .min()
    }

    /// The prediction `pose` judged against `goal`.
    fn at(&self, goal: &Goal, pose: Pose, position_only: bool) -> At {
        let (e, pos, rot) = self.error(goal, &pose, position_only);
        At {
            cost: e.norm_squared(),
            e,
            pos,
            rot,
            pose,
        }
    }

    /// The exact prediction at `q` (the expansion shifted onto it), judged
    /// against `goal`; `None` when it cannot be evaluated.
    fn exact_at<D: Dim>(
        &self,
        goal: &Goal,
        q: &OVector<f64, D>,
        current: &Pose,
        local: &mut Local,
        position_only: bool,
    ) -> Option<At>
    where
        DefaultAllocator: Allocator<D>,
    {
        let pose = self
            .prepared
            .predict_checked(q.as_slice(), current, local)?;
        Some(self.at(goal, pose, position_only))
    }

    /// The damped Gauss–Newton step `dq = Jwᵀ (Jw Jwᵀ + μ I)⁻¹ e` on the
    /// first `m` rows (a unit diagonal on the others, whose step component is
    /// 0), capped at `max_step_rad`; `None` when the system is not positive
    /// definite.
    fn damped_step<D: Dim>(
        &self,
        jw: &Jac<D>,
        e: &Vector6<f64>,
        mu: f64,
        m: usize,
    ) -> Option<OVector<f64, D>>
    where
        DefaultAllocator: Allocator<U6, D> + Allocator<D> + Allocator<D, U6>,
    {
        let mut a: Matrix6<f64> = jw * jw.transpose();
        for i in 0..6 {
            a[(i, i)] += if i < m { mu } else { 1.0 };
        }
        let mut dq: OVector<f64, D> = jw.transpose() * a.cholesky()?.solve(e);
        let step = dq.amax();
        if step > self.settings.max_step_rad {
            dq *= self.settings.max_step_rad / step;
        }
        Some(dq)
    }

    /// `q + dq` projected into the joint limits, and whether a joint was
    /// clamped.
    fn limited<D: Dim>(&self, q: &OVector<f64, D>, dq: &OVector<f64, D>) -> (OVector<f64, D>, bool)
    where
        DefaultAllocator: Allocator<D>,
    {
        let mut clamped = false;
        let mut trial = q.clone();
        for ((t, d), l) in trial.iter_mut().zip(dq.iter()).zip(&self.limits) {
            let (x, c) = Self::project(*t + d, *l);
            clamped |= c;
            *t = x;
        }
        (trial, clamped)
    }

    /// The damped Newton iteration for `d` joints.
    pub(super) fn refine_in<D: Dim>(
        &self,
        d: D,
        goal: &Goal,
        q_start: Vec<f64>,
        position_only: bool,
        max_iterations: usize,
        expansion: Option<&Local>,
    ) -> Refined
    where
        DefaultAllocator: Allocator<U6, D> + Allocator<D> + Allocator<D, U6>,
    {
        let fail = Refined::failed_evaluation;
        let mut jac = Jac::<D>::zeros_generic(U6, d);
        let linearised = self.prepared.has_local_terms();
        let mut local = Local::new();
        let Some((pose, at_expansion)) = self.start(&q_start, expansion, &mut jac, &mut local)
        else {
            return fail(q_start, 1);
        };
        // `now` is the exact prediction at `q` where `exact` (the expansion
        // at its own point is exact), else the expanded one.
        let mut exact = at_expansion;
        // Checks of the exact prediction that failed since the last expansion.
        let mut failed_checks = 0;
        let mut q = OVector::<f64, D>::from_column_slice_generic(d, U1, &q_start);
        let mut jac_t = jac.clone();
        let mut now = self.at(goal, pose, position_only);
        let mut damping = Nielsen::new(self.settings.initial_damping);
        let mut iterations = 1;
        let mut at_limit = false;
        let m = if position_only { 3 } else { 6 }; // rows of the system (`damped_step`)
        while iterations < max_iterations {
            if self.done(now.pos, now.rot, position_only) {
                if exact {
                    break;
                }
                // The expanded prediction meets the tolerance: check the
                // exact one, which also shifts the expansion onto it at `q`.
                iterations += 1;
                let Some(x) = self.exact_at(goal, &q, &now.pose, &mut local, position_only) else {
                    return fail(q.as_slice().to_vec(), iterations);
                };
                now = x;
                exact = true;
                failed_checks += 1;
                if failed_checks > 1 && !self.done(now.pos, now.rot, position_only) {
                    // Twice off: the expansion's derivatives are too old; expand here.
                    iterations += 1;
                    failed_checks = 0;
                    let p = &self.prepared;
                    if p.predict_with_jacobian(q.as_slice(), &mut jac, &mut local)
                        .is_none()
                    {
                        return fail(q.as_slice().to_vec(), iterations);
                    }
                }
                continue;
            }
            let jw = self.weighted_jacobian(&jac, position_only);
            let Some(dq) = self.damped_step(&jw, &now.e, damping.mu, m) else {
                damping.reject();
                iterations += 1;
                continue;
            };
            if !dq.iter().all(|v| v.is_finite()) {
                break;
            }
            let trial;
            (trial, at_limit) = self.limited(&q, &dq);
            iterations += 1;
            let Some(pose_t) =
                self.prepared
                    .predict_local(trial.as_slice(), &mut jac_t, &mut local)
            else {
                damping.reject();
                continue;
            };
            let next = self.at(goal, pose_t, position_only);
            if next.cost < now.cost {
                damping.accept(gain_ratio(&jw, &dq, &now, &next));
                q = trial;
                now = next;
                local.accept();
                std::mem::swap(&mut jac, &mut jac_t);
                exact = !linearised;
            } else {
                damping.reject();
                if damping.mu > 1e8 {
                    break;
                }
            }
        }
        if !exact {
            // The budget or the damping ended on the expanded prediction:
            // the residuals reported are the exact ones.
            iterations += 1;
            let Some(x) = self.exact_at(goal, &q, &now.pose, &mut local, position_only) else {
                return fail(q.as_slice().to_vec(), iterations);
            };
            now = x;
        }
        let (pos, rot) = (now.pos, now.rot);
        let converged = self.done(pos, rot, position_only);
        Refined {
            q: q.as_slice().to_vec(),
            converged,
            position_residual_m: pos,
            orientation_residual_rad: rot,
            iterations,
            at_limit: at_limit && !converged,
            sigma_min: if converged {
                f64::NAN
            } else {
                self.sigma_min(&jac, position_only)
            },
            failed_evaluation: false,
        }
    }
}

/// Gain ratio of a step `dq` from `now` to `next`: the actual decrease of
/// the cost over the linear model's (1 when the model predicts none).
fn gain_ratio<D: Dim>(jw: &Jac<D>, dq: &OVector<f64, D>, now: &At, next: &At) -> f64
where
    DefaultAllocator: Allocator<U6, D> + Allocator<D>,
{
    let jd: Vector6<f64> = jw * dq;
    let predicted = 2.0 * jd.dot(&now.e) - jd.norm_squared();
    if predicted > 0.0 {
        (now.cost - next.cost) / predicted
    } else {
        1.0
    }
}

/// A prediction judged against the goal: the weighted error, its residual
/// norms [m, rad] and its cost `|e|²`.
struct At {
    e: Vector6<f64>,
    pos: f64,
    rot: f64,
    cost: f64,
    pose: Pose,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::preset;
    use crate::sim::{synthetic_calibration, SyntheticErrors};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The fixed-size iteration (six joints) against the dynamic-size one on
    /// random targets of YS100, UR10 and the HH800 loop, calibrated (Hayati β,
    /// compliance under the payload), full-pose and position-only goals.
    #[test]
    fn fixed_size_iteration_equals_the_dynamic_one() {
        let mut rng = ChaCha8Rng::seed_from_u64(31);
        for name in ["ys100", "ur10", "hh800"] {
            let nominal = preset(name).unwrap();
            let cm = synthetic_calibration(&nominal, &SyntheticErrors::typical(1e-6), 11);
            assert!(cm.calibrated.has_compliance());
            let solver = IkSolver::new(cm.clone(), IkSettings::default());
            let mut converged = 0;
            for i in 0..30 {
                let q: Vec<f64> = nominal
                    .links
                    .iter()
                    .map(|l| rng.gen_range(l.limits[0]..l.limits[1]))
                    .collect();
                let Ok(p) = cm.predict_base(&q) else { continue };
                let goal = Goal::from(&p);
                let q0: Vec<f64> = q.iter().map(|v| v + rng.gen_range(-0.05..0.05)).collect();
                let q0 = solver.clamp_to_limits(&q0);
                let position_only = i % 3 == 0;
                let a = solver.refine_in(U6, &goal, q0.clone(), position_only, 60, None);
                let b = solver.refine_in(Dyn(6), &goal, q0, position_only, 60, None);
                assert_eq!(a.converged, b.converged, "{name} {i}");
                assert_eq!(a.iterations, b.iterations, "{name} {i}");
                for (x, y) in a.q.iter().zip(&b.q) {
                    assert!((x - y).abs() <= 1e-12, "{name} {i}: {x} vs {y}");
                }
                assert!((a.position_residual_m - b.position_residual_m).abs() <= 1e-12);
                converged += usize::from(a.converged);
            }
            assert!(converged >= 20, "{name}: {converged} of 30 converged");
        }
    }
}
