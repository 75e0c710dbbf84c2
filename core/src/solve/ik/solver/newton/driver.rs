//! The damped Newton of `newton.rs` on the generic LM driver
//! ([`optim::lm`](crate::optim::lm), Nielsen's damping, dynamic matrices):
//! the same error vector, weighted chord Jacobian, step cap and projection
//! onto the joint limits, but the primal system `(J_wᵀJ_w + μI)·Δq = J_wᵀe`.
//! It exists for the comparison that keeps the fixed-size iteration
//! (`core/benches/ik_newton.rs`, ratio in `newton.rs`'s header).

use super::super::eval::Local;
use super::super::*;
use super::Jac;
use crate::optim::lm::{self, Damping, Flow, Iterate, LeastSquaresProblem};
use nalgebra::{DVector, Dyn, Vector6, U6};

impl IkSolver {
    /// [`IkSolver::refine_with`] on the generic LM driver (benchmark only).
    #[doc(hidden)]
    pub fn refine_on_driver(
        &self,
        goal: &Goal,
        q0: &[f64],
        position_only: bool,
        max_iterations: usize,
    ) -> Refined {
        let q = self.clamp_to_limits(q0);
        let n = q.len();
        let mut jac = Jac::<Dyn>::zeros_generic(U6, Dyn(n));
        let mut local = Local::new();
        let Some(pose) = self
            .prepared
            .predict_with_jacobian(&q, &mut jac, &mut local)
        else {
            return Refined {
                q,
                converged: false,
                position_residual_m: f64::INFINITY,
                orientation_residual_rad: f64::INFINITY,
                iterations: 1,
                at_limit: false,
                sigma_min: f64::NAN,
                failed_evaluation: true,
            };
        };
        let (e, pos, rot) = self.error(goal, &pose, position_only);
        let mut p = Newton {
            solver: self,
            goal,
            position_only,
            q,
            jac_t: jac.clone(),
            jac,
            local,
            point: Point {
                e,
                pos,
                rot,
                cost: e.norm_squared(),
            },
            jw: DMatrix::zeros(6, n),
            r: DVector::zeros(6),
            next: None,
            at_limit: false,
        };
        let settings = lm::Settings {
            // The budget counts evaluations, the start included.
            max_iterations: max_iterations.saturating_sub(1),
            cost_tolerance: 0.0,
            step_tolerance: 0.0,
            gradient_tolerance: 0.0,
            damping: Damping::Nielsen {
                initial: self.settings.initial_damping * self.settings.initial_damping,
            },
            column_scaling: false,
            require_overdetermined: false,
            linearise_at_end: false,
            ..lm::Settings::default()
        };
        let run = lm::minimise(&mut p, &settings).expect("never cancelled");
        let converged = self.done(p.point.pos, p.point.rot, position_only);
        let sigma_min = if converged {
            f64::NAN
        } else {
            let m = if position_only { 3 } else { 6 };
            let jw = self.weighted_jacobian(&p.jac, position_only);
            DMatrix::from_fn(m, n, |i, j| jw[(i, j)])
                .singular_values()
                .min()
        };
        Refined {
            q: p.q,
            converged,
            position_residual_m: p.point.pos,
            orientation_residual_rad: p.point.rot,
            iterations: 1 + run.iterations,
            at_limit: p.at_limit && !converged,
            sigma_min,
            failed_evaluation: false,
        }
    }
}

/// Error vector, residual norms and cost at a joint vector.
#[derive(Clone, Copy)]
struct Point {
    e: Vector6<f64>,
    pos: f64,
    rot: f64,
    cost: f64,
}

struct Newton<'a> {
    solver: &'a IkSolver,
    goal: &'a Goal,
    position_only: bool,
    q: Vec<f64>,
    jac: Jac<Dyn>,
    jac_t: Jac<Dyn>,
    /// The compensator's derivative at the start (a chord for every step).
    local: Local,
    point: Point,
    /// The weighted Jacobian and error of the last linearisation.
    jw: DMatrix<f64>,
    r: DVector<f64>,
    next: Option<(Vec<f64>, Point)>,
    at_limit: bool,
}

impl Newton<'_> {
    fn done(&self) -> Flow {
        if self
            .solver
            .done(self.point.pos, self.point.rot, self.position_only)
        {
            Flow::Stop
        } else {
            Flow::Continue
        }
    }
}

impl LeastSquaresProblem for Newton<'_> {
    fn cost(&self) -> f64 {
        self.point.cost
    }

    fn linearise(&mut self) -> &mut DMatrix<f64> {
        let jw = self.solver.weighted_jacobian(&self.jac, self.position_only);
        self.jw.copy_from(&jw);
        self.r.copy_from(&self.point.e);
        &mut self.jw
    }

    fn residuals(&self) -> &DVector<f64> {
        &self.r
    }

    fn jacobian(&self) -> &DMatrix<f64> {
        &self.jw
    }

    fn trial(&mut self, delta: &mut DVector<f64>) -> Option<f64> {
        let step = delta.amax();
        if step > self.solver.settings.max_step_rad {
            *delta *= self.solver.settings.max_step_rad / step;
        }
        if !delta.iter().all(|v| v.is_finite()) {
            return None;
        }
        let mut clamped = false;
        let mut trial = self.q.clone();
        for ((t, d), l) in trial.iter_mut().zip(delta.iter()).zip(&self.solver.limits) {
            let (x, c) = IkSolver::project(*t + d, *l);
            clamped |= c;
            *t = x;
        }
        self.at_limit = clamped;
        let pose = self.solver.prepared.predict_with_chord(
            &trial,
            &mut self.jac_t,
            self.local.derivative(),
        )?;
        let (e, pos, rot) = self.solver.error(self.goal, &pose, self.position_only);
        let point = Point {
            e,
            pos,
            rot,
            cost: e.norm_squared(),
        };
        self.next = Some((trial, point));
        Some(point.cost)
    }

    fn accept(&mut self) {
        (self.q, self.point) = self.next.take().expect("an evaluated trial");
        std::mem::swap(&mut self.jac, &mut self.jac_t);
    }

    fn start(&mut self, _at: &Iterate) -> Flow {
        self.done()
    }

    fn accepted(&mut self, _at: &Iterate) -> Flow {
        self.done()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::preset;
    use crate::sim::{synthetic_calibration, SyntheticErrors};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// On random YS100 and UR10 targets near a known solution (full-pose and
    /// position-only goals), the driver's iteration converges wherever the
    /// fixed-size one does, to the same joints within 1e-6 rad.
    #[test]
    fn the_driver_iteration_reaches_the_fixed_size_solutions() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for name in ["ys100", "ur10"] {
            let nominal = preset(name).unwrap();
            let cm = synthetic_calibration(&nominal, &SyntheticErrors::typical(1e-6), 11);
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
                let position_only = i % 3 == 0;
                let a = solver.refine_with(&goal, &q0, position_only, 60);
                let b = solver.refine_on_driver(&goal, &q0, position_only, 60);
                if !a.converged {
                    continue;
                }
                converged += 1;
                assert!(b.converged, "{name} {i}: {b:?}");
                if !position_only {
                    for (x, y) in a.q.iter().zip(&b.q) {
                        assert!((x - y).abs() <= 1e-6, "{name} {i}: {x} vs {y}");
                    }
                }
            }
            assert!(converged >= 25, "{name}: {converged} of 30 converged");
        }
    }
}
