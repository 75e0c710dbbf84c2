//! Damped Newton (Levenberg–Marquardt) on the compensated prediction: the
//! step, the error vector and the weighted Jacobian of the parent module's
//! header, with Nielsen's damping rule and projection onto the joint limits.
//! Frames: base frame; units: m, rad.

use super::*;

pub(super) struct Eval {
    pub(super) pose: Pose,
    pub(super) jac: DMatrix<f64>,
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

    pub(super) fn evaluate(&self, q: &[f64]) -> Option<Eval> {
        let (pose, jac) = self.model.predict_base_with_jacobian(q).ok()?;
        Some(Eval { pose, jac })
    }

    /// Weighted error vector and the unweighted residual norms.
    pub(super) fn error(
        &self,
        goal: &Goal,
        pose: &Pose,
        position_only: bool,
    ) -> (DVector<f64>, f64, f64) {
        let ep = goal.position - pose.p;
        let er = goal
            .rotation
            .map(|r| rotation_log(&(r * pose.r.transpose())))
            .unwrap_or_else(Vector3::zeros);
        let e = if position_only {
            DVector::from_column_slice(ep.as_slice())
        } else {
            let l = self.settings.orientation_length_m;
            DVector::from_iterator(6, ep.iter().copied().chain(er.iter().map(|v| v * l)))
        };
        (e, ep.norm(), er.norm())
    }

    pub(super) fn weighted_jacobian(
        &self,
        jac: &DMatrix<f64>,
        position_only: bool,
    ) -> DMatrix<f64> {
        if position_only {
            jac.rows(0, 3).into_owned()
        } else {
            let mut j = jac.clone();
            let l = self.settings.orientation_length_m;
            j.rows_mut(3, 3).scale_mut(l);
            j
        }
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
        let s = &self.settings;
        let mut q = self.clamp_to_limits(q0);
        let fail = |q: Vec<f64>, iterations| Refined {
            q,
            converged: false,
            position_residual_m: f64::INFINITY,
            orientation_residual_rad: f64::INFINITY,
            iterations,
            at_limit: false,
            sigma_min: f64::NAN,
            failed_evaluation: true,
        };
        let Some(mut ev) = self.evaluate(&q) else {
            return fail(q, 1);
        };
        let (mut e, mut pos, mut rot) = self.error(goal, &ev.pose, position_only);
        let mut cost = e.norm_squared();
        // Damping μ = λ² [m²], updated from the gain ratio (Nielsen).
        let mut mu = s.initial_damping * s.initial_damping;
        let mut nu = 2.0;
        let mut iterations = 1;
        let mut at_limit = false;
        let m = e.len();
        while !self.done(pos, rot, position_only) && iterations < max_iterations {
            let jw = self.weighted_jacobian(&ev.jac, position_only);
            let mut a = &jw * jw.transpose();
            for i in 0..m {
                a[(i, i)] += mu;
            }
            let Some(chol) = a.cholesky() else {
                mu = (mu * nu).max(1e-18);
                nu *= 2.0;
                iterations += 1;
                continue;
            };
            let mut dq = jw.transpose() * chol.solve(&e);
            let step = dq.amax();
            if step > s.max_step_rad {
                dq *= s.max_step_rad / step;
            }
            if !dq.iter().all(|v| v.is_finite()) {
                break;
            }
            let mut clamped = false;
            let trial: Vec<f64> = q
                .iter()
                .zip(dq.iter())
                .zip(&self.limits)
                .map(|((v, d), l)| {
                    let (x, c) = Self::project(v + d, *l);
                    clamped |= c;
                    x
                })
                .collect();
            iterations += 1;
            at_limit = clamped;
            let Some(ev_t) = self.evaluate(&trial) else {
                mu = (mu * nu).max(1e-18);
                nu *= 2.0;
                continue;
            };
            let (e_t, pos_t, rot_t) = self.error(goal, &ev_t.pose, position_only);
            let cost_t = e_t.norm_squared();
            if cost_t < cost {
                let jd = &jw * &dq;
                let predicted = 2.0 * jd.dot(&e) - jd.norm_squared();
                let rho = if predicted > 0.0 {
                    (cost - cost_t) / predicted
                } else {
                    1.0
                };
                mu *= (1.0 - (2.0 * rho - 1.0).powi(3)).max(1.0 / 3.0);
                mu = mu.max(1e-30);
                nu = 2.0;
                q = trial;
                ev = ev_t;
                e = e_t;
                cost = cost_t;
                pos = pos_t;
                rot = rot_t;
            } else {
                mu = (mu * nu).max(1e-18);
                nu *= 2.0;
                if mu > 1e8 {
                    break;
                }
            }
        }
        let converged = self.done(pos, rot, position_only);
        let sigma_min = if converged {
            f64::NAN
        } else {
            let jw = self.weighted_jacobian(&ev.jac, position_only);
            jw.singular_values().min()
        };
        Refined {
            q,
            converged,
            position_residual_m: pos,
            orientation_residual_rad: rot,
            iterations,
            at_limit: at_limit && !converged,
            sigma_min,
            failed_evaluation: false,
        }
    }
}
