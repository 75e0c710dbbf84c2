//! The solver's evaluation of the compensated model (the prediction
//! `P_base(q) = FK_cal(q + c∘τ(q) + f(q)) + NN(q, τ)` of `CompensatedModel`, docs/design.md
//! "Compensated model and false targets", thesis eq. 2.1), with the model's
//! constants computed once ([`PreparedChain`]) and every per-call buffer on
//! the stack for up to `STACK_DOF` joints.
//!
//! The joint maps' series come from their tables (`model/joint_map_table.rs`:
//! within 1e-13 rad of the series in `f`, 1e-12 in `f'`), so "equals" below
//! means within those bounds where a model has maps.
//! [`PreparedModel::predict_base`] equals `CompensatedModel::predict_base`;
//! [`PreparedModel::predict_with_jacobian`] equals
//! `CompensatedModel::predict_base_with_jacobian` (pose in the registered base
//! frame [m]; quasi-Newton Jacobian 6×N, rows `[v; ω]`: the geometric Jacobian
//! of the calibrated chain at the deflected joints, column i times the joint
//! map's `1 + f_i'(q_i)`, plus the compensator's `∂NN/∂q` on the position
//! rows, `∂τ/∂q` neglected), compared in the tests below, and expands the
//! joint maps and the compensator there ([`Local`]; at a closed-form seed,
//! [`PreparedModel::predict_expanded`], with the compensator's rough
//! prediction, which the runs' checks replace by the exact one);
//! [`PreparedModel::predict_local`] evaluates the chain exactly and those
//! terms from their expansion (the damped Newton's trial steps);
//! [`PreparedModel::predict_with_chord`] takes `∂NN/∂q` from an earlier
//! evaluation; [`PreparedModel::seed_fk`] is the seed model's forward kinematics.
//! Joints in the model convention [rad], torques N·m, payload kg.

use crate::model::calibrated::{orientation, CompensatedModel, Compensator, LearnedCompensator};
use crate::model::joint_map_table::TabulatedMaps;
use crate::model::joint_maps::AngleError;
use crate::model::kinematics::prepared::{stack_or_heap, PreparedChain, STACK_DOF};
use crate::model::kinematics::LoopPartials;
use crate::model::{MapTaylor, Pose, RobotModel};
use nalgebra::{allocator::Allocator, DefaultAllocator, Dim, OMatrix, Vector3, U6};
use std::sync::Arc;

/// Up to `STACK_DOF` values on the stack, more on the heap.
#[derive(Clone)]
struct Small<T: Copy> {
    stack: [T; STACK_DOF],
    heap: Vec<T>,
    n: usize,
}

impl<T: Copy> Small<T> {
    fn new(fill: T) -> Self {
        Small {
            stack: [fill; STACK_DOF],
            heap: Vec::new(),
            n: 0,
        }
    }

    /// `n` values set to `fill`.
    fn reset(&mut self, n: usize, fill: T) -> &mut [T] {
        self.n = n;
        let values = stack_or_heap(&mut self.stack, &mut self.heap, n, fill);
        values.fill(fill);
        values
    }

    /// The `n` values as they are, to change in place.
    fn get_mut(&mut self) -> &mut [T] {
        if self.n <= STACK_DOF {
            &mut self.stack[..self.n]
        } else {
            &mut self.heap[..]
        }
    }

    fn get(&self) -> &[T] {
        if self.n <= STACK_DOF {
            &self.stack[..self.n]
        } else {
            &self.heap[..]
        }
    }
}

/// The compensator's `∂NN/∂q` [m/rad] at one point (position rows of the
/// IK Jacobian), kept on the stack for up to `STACK_DOF` joints.
#[derive(Clone)]
pub(crate) struct NnDerivative {
    columns: Small<Vector3<f64>>,
    /// The compensator wrote a derivative (false: none, or no compensator).
    written: bool,
}

impl NnDerivative {
    pub(crate) fn new() -> Self {
        NnDerivative {
            columns: Small::new(Vector3::zeros()),
            written: false,
        }
    }

    fn columns(&mut self, n: usize) -> &mut [Vector3<f64>] {
        self.columns.reset(n, Vector3::zeros())
    }

    /// `jac[0..3, k] += ∂NN/∂q_k` when a derivative was written.
    fn add_to<D: Dim>(&self, jac: &mut OMatrix<f64, U6, D>)
    where
        DefaultAllocator: Allocator<U6, D>,
    {
        if !self.written {
            return;
        }
        for (k, d) in self.columns.get().iter().enumerate() {
            for i in 0..3 {
                jac[(i, k)] += d[i];
            }
        }
    }

    /// `Σ_k ∂NN/∂q_k·(q_k − q0_k)` (zero when no derivative was written).
    fn times(&self, q: &[f64], q0: &[f64]) -> Vector3<f64> {
        if !self.written {
            return Vector3::zeros();
        }
        self.columns
            .get()
            .iter()
            .zip(q.iter().zip(q0))
            .fold(Vector3::zeros(), |acc, (d, (q, q0))| acc + d * (q - q0))
    }
}

/// The prediction's terms outside the calibrated chain expanded at a point
/// `q₀`: each joint map to second order, `f(q₀) + f'(q₀)·Δ + ½·f''(q₀)·Δ²`
/// (Δ = q − q₀), and the compensator to first, `NN(q₁) + ∂NN/∂q(q₁)·(q − q₁)`
/// (docs/design.md "Compensated model and false targets"). The compensator's
/// point `q₁` is `q₀`, or the closed-form seed's when the damped Newton run
/// starts from the corrected seed ([`CompensatorAt::Kept`]). The
/// damped Newton's trial steps evaluate the chain exactly and these terms
/// from their expansion, which costs a few multiplications instead of a
/// series of 80 harmonics per joint or a network; it checks the exact
/// prediction where the expanded one meets the tolerance.
#[derive(Clone)]
pub(crate) struct Local {
    /// The joint maps' point `q₀` [rad].
    q0: Small<f64>,
    /// The compensator's point `q₁` [rad].
    nn_q0: Small<f64>,
    /// `f_i`, `f_i'` and `f_i''` at `q₀_i` (zero without a map).
    maps: Small<MapTaylor>,
    /// `NN(q₁)` [m].
    residual: Vector3<f64>,
    derivative: NnDerivative,
    /// Gravity torques at the iteration's current point [N·m] (the
    /// expansion's point, then each accepted trial step's).
    tau: Small<f64>,
    /// Gravity torques at the last trial step [N·m].
    trial_tau: Small<f64>,
    /// The compensator's expansion is the rough one
    /// (`Compensator::residual_and_jacobian_rough`), not exact even at its
    /// point.
    rough: bool,
}

/// How [`PreparedModel::expand`] takes the compensator.
#[derive(Clone, Copy, PartialEq)]
pub(crate) enum CompensatorAt {
    /// Evaluated at the point, exactly.
    Exact,
    /// Evaluated at the point to the compensator's rough precision
    /// (`Compensator::residual_and_jacobian_rough`): a run's start too far
    /// from the point of a seed's expansion
    /// ([`PreparedModel::expansion_holds`]).
    Rough,
    /// From its expansion in `Local`: a run's start near the point of that
    /// expansion (there exact, or rough where
    /// [`PreparedModel::predict_expanded`] made it; elsewhere second order in
    /// the distance). Saves the compensator's evaluation at the start.
    Kept,
}

impl Local {
    pub(crate) fn new() -> Self {
        Local {
            q0: Small::new(0.0),
            nn_q0: Small::new(0.0),
            maps: Small::new(MapTaylor::default()),
            residual: Vector3::zeros(),
            derivative: NnDerivative::new(),
            tau: Small::new(0.0),
            trial_tau: Small::new(0.0),
            rough: false,
        }
    }

    /// The last trial step becomes the current point.
    pub(crate) fn accept(&mut self) {
        std::mem::swap(&mut self.tau, &mut self.trial_tau);
    }

    /// Whether `q` is the point of both expansions and the compensator's is
    /// exact (then the expanded prediction is the exact one there).
    pub(crate) fn is_exact_at(&self, q: &[f64]) -> bool {
        !self.rough && self.q0.get() == q && self.nn_q0.get() == q
    }

    /// The compensator's `∂NN/∂q` at the point.
    pub(crate) fn derivative(&self) -> &NnDerivative {
        &self.derivative
    }
}

/// A compensated model prepared for repeated evaluation (see the module docs).
#[derive(Clone)]
pub(crate) struct PreparedModel {
    calibrated: PreparedChain,
    /// The model the closed form solves (nominal or its proxy).
    seed: PreparedChain,
    /// Joint compliances of the calibrated model [rad/(N·m)].
    compliance: Vec<f64>,
    has_compliance: bool,
    /// The calibrated model's joint angle error maps, tabulated (equal to
    /// the series within `TOLERANCE_RAD`, `model/joint_map_table.rs`).
    maps: Option<TabulatedMaps>,
    payload_kg: f64,
    compensator: Option<Arc<LearnedCompensator>>,
    /// The compensator's orientation part's point in the TCP frame (exact everywhere).
    rotation_point: Option<Vector3<f64>>,
}

impl std::fmt::Debug for PreparedModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PreparedModel")
            .field("dof", &self.calibrated.dof())
            .field("has_compliance", &self.has_compliance)
            .field("payload_kg", &self.payload_kg)
            .field(
                "compensator",
                &self.compensator.as_ref().map(|c| c.name().to_string()),
            )
            .finish()
    }
}

impl PreparedModel {
    pub(crate) fn new(model: &CompensatedModel, seed_model: &RobotModel) -> Self {
        let cal = &model.calibrated;
        PreparedModel {
            calibrated: PreparedChain::new(cal),
            seed: PreparedChain::new(seed_model),
            compliance: cal.links.iter().map(|l| l.compliance).collect(),
            has_compliance: cal.has_compliance(),
            maps: cal.joint_maps.as_ref().map(TabulatedMaps::new),
            payload_kg: model.payload_kg,
            compensator: model.compensator.clone(),
            rotation_point: model
                .compensator
                .as_ref()
                .and_then(|c| orientation::point_in_tcp(c.as_ref(), cal)),
        }
    }

    /// The seed model's TCP pose at `q` (base frame).
    pub(crate) fn seed_fk(&self, q: &[f64]) -> Option<Pose> {
        self.seed.fk(q).ok()
    }

    /// Whether the prediction has terms outside the chain (joint maps or a
    /// compensator): only then does the expanded prediction ([`Local`])
    /// differ from the exact one.
    pub(crate) fn has_local_terms(&self) -> bool {
        self.maps.is_some() || self.compensator.is_some()
    }

    /// The bounds of the joint maps' tables on `f` and `f'` (zeros without
    /// maps): the prepared prediction's distance from `CompensatedModel`'s.
    #[cfg(test)]
    fn maps_bound(&self) -> [f64; 2] {
        let b = self.maps.as_ref().map_or([0.0; 3], TabulatedMaps::bound);
        [b[0], b[1]]
    }

    /// Whether the prediction has a compensator.
    pub(crate) fn has_compensator(&self) -> bool {
        self.compensator.is_some()
    }

    /// `CompensatedModel::predict_base`.
    pub(crate) fn predict_base(&self, q: &[f64]) -> Option<Pose> {
        self.predict(
            q,
            |maps, q, deflected| maps.add_to(q, deflected),
            |_, _, _| {},
            |c, q, tau, payload| c.residual_at(q, tau, payload),
            |_| {},
        )
    }

    /// `CompensatedModel::predict_base_with_jacobian`, the Jacobian into `jac`,
    /// and the terms outside the chain expanded at `q` into `local` (for
    /// [`PreparedModel::predict_local`]).
    pub(crate) fn predict_with_jacobian<D: Dim>(
        &self,
        q: &[f64],
        jac: &mut OMatrix<f64, U6, D>,
        local: &mut Local,
    ) -> Option<Pose>
    where
        DefaultAllocator: Allocator<U6, D>,
    {
        self.expand(q, Some(jac), CompensatorAt::Exact, local)
    }

    /// Whether the compensator's expansion in `local` is expected to hold at
    /// `q` to within `tolerance_m` (`Compensator::expansion_remainder`; true
    /// for compensators that do not know it).
    pub(crate) fn expansion_holds(&self, local: &Local, q: &[f64], tolerance_m: f64) -> bool {
        let Some(c) = &self.compensator else {
            return true;
        };
        c.expansion_remainder(local.nn_q0.get(), q)
            .is_none_or(|r| r <= tolerance_m)
    }

    /// [`PreparedModel::predict_base`] with the compensator's rough
    /// prediction (`Compensator::residual_and_jacobian_rough`), expanded at
    /// `q` into `local` (the closed-form seed's correction: the damped Newton
    /// runs from that seed start on this expansion of the compensator, and
    /// check the exact prediction where they end). The joint maps only add
    /// their values: the runs expand them where they start.
    pub(crate) fn predict_expanded(&self, q: &[f64], local: &mut Local) -> Option<Pose> {
        self.expand::<U6>(q, None, CompensatorAt::Rough, local)
    }

    /// The start of a damped Newton run: the chain exact and the joint maps
    /// expanded at `q`, as in [`PreparedModel::predict_with_jacobian`], and
    /// the compensator as `at` says.
    pub(crate) fn predict_start<D: Dim>(
        &self,
        q: &[f64],
        jac: &mut OMatrix<f64, U6, D>,
        at: CompensatorAt,
        local: &mut Local,
    ) -> Option<Pose>
    where
        DefaultAllocator: Allocator<U6, D>,
    {
        self.expand(q, Some(jac), at, local)
    }

    /// The prediction at `q`, its Jacobian into `jac` and the joint maps
    /// expanded at `q` into `local` when `jac` is given (otherwise the maps
    /// only add their values), and the compensator as `at` says.
    fn expand<D: Dim>(
        &self,
        q: &[f64],
        mut jac: Option<&mut OMatrix<f64, U6, D>>,
        at: CompensatorAt,
        local: &mut Local,
    ) -> Option<Pose>
    where
        DefaultAllocator: Allocator<U6, D>,
    {
        let n = q.len();
        let chain = &self.calibrated;
        let expand_maps = jac.is_some();
        // Without the maps' expansion `local` has no maps' point.
        let q0: &[f64] = if expand_maps { q } else { &[] };
        local.q0.reset(q0.len(), 0.0).copy_from_slice(q0);
        let keep_compensator = at == CompensatorAt::Kept;
        if !keep_compensator {
            local.rough = at == CompensatorAt::Rough
                && self.compensator.as_ref().is_some_and(|c| c.has_rough());
            local.nn_q0.reset(n, 0.0).copy_from_slice(q);
            local.residual = Vector3::new(0.0, 0.0, 0.0);
            local.derivative.columns(n);
            local.derivative.written = false;
        }
        let taylor = local.maps.reset(n, MapTaylor::default());
        let nn_q0 = local.nn_q0.get();
        let residual = &mut local.residual;
        let derivative = &mut local.derivative;
        let tau_at = &mut local.tau;
        let pose = self.predict(
            q,
            |maps, q, deflected| {
                if !expand_maps {
                    maps.add_to(q, deflected);
                    return;
                }
                // One pass over each series: the value and two derivatives.
                maps.taylor(q, taylor);
                for (d, t) in deflected.iter_mut().zip(&*taylor) {
                    *d += t.value;
                }
            },
            |frames, tcp, lp| {
                if let Some(jac) = jac.as_deref_mut() {
                    chain.jacobian_into(frames, tcp, lp, jac);
                }
            },
            |c, q, tau, payload| {
                if keep_compensator {
                    return *residual + derivative.times(q, nn_q0);
                }
                let dq = derivative.columns(n);
                let (r, w) = if at == CompensatorAt::Rough {
                    c.residual_and_jacobian_rough(q, tau, payload, dq)
                } else {
                    c.residual_and_jacobian(q, tau, payload, dq)
                };
                derivative.written = w;
                *residual = r;
                r
            },
            |tau| tau_at.reset(n, 0.0).copy_from_slice(tau),
        )?;
        let Some(jac) = jac else {
            return Some(pose);
        };
        if self.maps.is_some() {
            let (mut s_s, mut s_h) = ([1.0; STACK_DOF], Vec::new());
            let scale = stack_or_heap(&mut s_s, &mut s_h, n, 1.0);
            for (s, t) in scale.iter_mut().zip(local.maps.get()) {
                *s = 1.0 + t.slope;
            }
            scale_columns(jac, scale);
        }
        local.derivative.add_to(jac);
        Some(pose)
    }

    /// The prediction with the terms outside the chain taken from their
    /// expansion `local` (the chain itself exact), and the Jacobian of that
    /// prediction (`∂τ/∂q` neglected, as in the exact one). Equal to
    /// [`PreparedModel::predict_with_jacobian`] at `local`'s point; elsewhere
    /// it differs by the expansion's remainder: third order in Δ for the
    /// maps, second for the compensator.
    pub(crate) fn predict_local<D: Dim>(
        &self,
        q: &[f64],
        jac: &mut OMatrix<f64, U6, D>,
        local: &mut Local,
    ) -> Option<Pose>
    where
        DefaultAllocator: Allocator<U6, D>,
    {
        let chain = &self.calibrated;
        let n = q.len();
        let (q0, nn_q0) = (local.q0.get(), local.nn_q0.get());
        let taylor = local.maps.get();
        let (residual, derivative) = (&local.residual, &local.derivative);
        let trial_tau = &mut local.trial_tau;
        // The chain rule factor of the expansion, `1 + f'(q₀) + f''(q₀)·Δ`.
        let (mut s_s, mut s_h) = ([1.0; STACK_DOF], Vec::new());
        let scale = stack_or_heap(&mut s_s, &mut s_h, q.len(), 1.0);
        let pose = self.predict(
            q,
            |_, q, deflected| {
                for (i, d) in deflected.iter_mut().enumerate() {
                    let (t, delta) = (&taylor[i], q[i] - q0[i]);
                    *d += t.value_at(delta);
                    scale[i] = 1.0 + t.slope_at(delta);
                }
            },
            |frames, tcp, lp| chain.jacobian_into(frames, tcp, lp, jac),
            |_, q, _, _| residual + derivative.times(q, nn_q0),
            |tau| trial_tau.reset(n, 0.0).copy_from_slice(tau),
        )?;
        if self.maps.is_some() {
            scale_columns(jac, scale);
        }
        local.derivative.add_to(jac);
        Some(pose)
    }

    /// The exact prediction at the iteration's current point `q`, whose
    /// expanded prediction is `current` (as [`PreparedModel::predict_base`]),
    /// with `local`'s constant terms shifted so that the expansion equals
    /// the exact prediction at `q` too (its derivatives stay those of its
    /// point): after a failed check the iteration goes on from `q` without
    /// expanding again. `local` holds the gravity torques at `q` (the
    /// iteration's current point): without joint maps the chain of `current`
    /// is already exact and only the compensator is evaluated, at `q` and
    /// those torques; with them, only the deflected chain is evaluated again.
    pub(crate) fn predict_checked(
        &self,
        q: &[f64],
        current: &Pose,
        local: &mut Local,
    ) -> Option<Pose> {
        let (q0, nn_q0) = (local.q0.get(), local.nn_q0.get());
        if self.maps.is_none() {
            let Some(c) = &self.compensator else {
                return Some(*current);
            };
            let expanded = local.residual + local.derivative.times(q, nn_q0);
            let r = c.residual_at(q, local.tau.get(), self.payload_kg);
            local.residual = r - local.derivative.times(q, nn_q0);
            let mut pose = *current;
            pose.p += r - expanded;
            return Some(pose);
        }
        let taylor = local.maps.get_mut();
        let residual = &mut local.residual;
        let derivative = &local.derivative;
        let (mut f_s, mut f_h) = ([Pose::identity(); STACK_DOF], Vec::new());
        let frames = stack_or_heap(&mut f_s, &mut f_h, q.len(), Pose::identity());
        self.predict_deflected(
            q,
            local.tau.get(),
            frames,
            |maps, q, deflected| {
                for (i, (m, d)) in maps.joints.iter().zip(deflected.iter_mut()).enumerate() {
                    let f = m.as_ref().map_or(0.0, |m| m.value(q[i]));
                    *d += f;
                    let t = &mut taylor[i];
                    let delta = q[i] - q0[i];
                    t.value += f - t.value_at(delta);
                }
            },
            |_, _, _| {},
            |c, q, tau, payload| {
                let r = c.residual_at(q, tau, payload);
                *residual = r - derivative.times(q, nn_q0);
                r
            },
        )
    }

    /// [`PreparedModel::predict_with_jacobian`] with the compensator's
    /// derivative taken from `nn_dq` (computed at an earlier point: a chord)
    /// instead of at `q`: the residual itself is exact, only its derivative in
    /// the Jacobian is older (the generic LM driver's trial steps,
    /// `newton/driver.rs`).
    pub(crate) fn predict_with_chord<D: Dim>(
        &self,
        q: &[f64],
        jac: &mut OMatrix<f64, U6, D>,
        nn_dq: &NnDerivative,
    ) -> Option<Pose>
    where
        DefaultAllocator: Allocator<U6, D>,
    {
        let chain = &self.calibrated;
        let (mut s_s, mut s_h) = ([1.0; STACK_DOF], Vec::new());
        let scale = stack_or_heap(&mut s_s, &mut s_h, q.len(), 1.0);
        let pose = self.predict(
            q,
            |maps, q, deflected| maps.apply(q, deflected, scale),
            |frames, tcp, lp| chain.jacobian_into(frames, tcp, lp, jac),
            |c, q, tau, payload| c.residual_at(q, tau, payload),
            |_| {},
        )?;
        if self.maps.is_some() {
            scale_columns(jac, scale);
        }
        nn_dq.add_to(jac);
        Some(pose)
    }

    /// The prediction: `add_maps(maps, q, deflected)` adds the joint maps'
    /// angle errors to the deflected joints, `at_deflected(frames, tcp, loop
    /// partials)` sees the calibrated chain at the deflected joints,
    /// `residual(compensator, q, τ, payload)` gives the compensator's residual,
    /// `on_tau(τ)` sees the gravity torques (zeros when nothing needs them).
    fn predict(
        &self,
        q: &[f64],
        add_maps: impl FnOnce(&TabulatedMaps, &[f64], &mut [f64]),
        at_deflected: impl FnOnce(&[Pose], &Pose, Option<&LoopPartials>),
        residual: impl FnOnce(&dyn Compensator, &[f64], &[f64], f64) -> Vector3<f64>,
        on_tau: impl FnOnce(&[f64]),
    ) -> Option<Pose> {
        let chain = &self.calibrated;
        let n = q.len();
        let (mut f_s, mut f_h) = ([Pose::identity(); STACK_DOF], Vec::new());
        let frames = stack_or_heap(&mut f_s, &mut f_h, n, Pose::identity());
        let (tcp0, lp0) = chain.frames(q, frames).ok()?;
        let needs_tau = self.has_compliance || self.compensator.is_some();
        let (mut tau_s, mut tau_h) = ([0.0; STACK_DOF], Vec::new());
        let tau = stack_or_heap(&mut tau_s, &mut tau_h, n, 0.0);
        if needs_tau {
            chain.gravity_torques(frames, &tcp0, lp0.as_ref(), self.payload_kg, tau);
        }
        on_tau(tau);
        if self.deflects() {
            return self.predict_deflected(q, tau, frames, add_maps, at_deflected, residual);
        }
        at_deflected(frames, &tcp0, lp0.as_ref());
        let mut pose = tcp0;
        if let Some(c) = &self.compensator {
            pose.p += residual(c.as_ref(), q, tau, self.payload_kg);
            let d = self.rotation_point.as_ref();
            orientation::rotate(&mut pose, c.as_ref(), (q, tau, self.payload_kg), d);
        }
        Some(pose)
    }

    /// Whether the calibrated chain is evaluated at joints other than `q`
    /// (compliance or joint maps).
    fn deflects(&self) -> bool {
        self.has_compliance || self.maps.is_some()
    }

    /// [`PreparedModel::predict`] given the gravity torques `tau` at `q`,
    /// for a model that [deflects](PreparedModel::deflects): the chain at
    /// `q + c∘τ` plus the joint maps (its frames into `frames`, one per
    /// joint), and the compensator's residual.
    fn predict_deflected(
        &self,
        q: &[f64],
        tau: &[f64],
        frames: &mut [Pose],
        add_maps: impl FnOnce(&TabulatedMaps, &[f64], &mut [f64]),
        at_deflected: impl FnOnce(&[Pose], &Pose, Option<&LoopPartials>),
        residual: impl FnOnce(&dyn Compensator, &[f64], &[f64], f64) -> Vector3<f64>,
    ) -> Option<Pose> {
        let n = q.len();
        let (mut d_s, mut d_h) = ([0.0; STACK_DOF], Vec::new());
        let deflected = stack_or_heap(&mut d_s, &mut d_h, n, 0.0);
        for (((d, q), t), c) in deflected.iter_mut().zip(q).zip(tau).zip(&self.compliance) {
            *d = q + c * t;
        }
        if let Some(maps) = &self.maps {
            add_maps(maps, q, deflected);
        }
        let (tcp, lp) = self.calibrated.frames(deflected, frames).ok()?;
        at_deflected(frames, &tcp, lp.as_ref());
        let mut pose = tcp;
        if let Some(c) = &self.compensator {
            pose.p += residual(c.as_ref(), q, tau, self.payload_kg);
            let d = self.rotation_point.as_ref();
            orientation::rotate(&mut pose, c.as_ref(), (q, tau, self.payload_kg), d);
        }
        Some(pose)
    }
}

/// The chain rule through the joint maps: column i of the chain's Jacobian
/// (taken at the mapped joints) times `1 + f_i'(q_i)`.
fn scale_columns<D: Dim>(jac: &mut OMatrix<f64, U6, D>, scale: &[f64])
where
    DefaultAllocator: Allocator<U6, D>,
{
    for (i, s) in scale.iter().enumerate().take(jac.ncols()) {
        jac.column_mut(i).scale_mut(*s);
    }
}

#[cfg(test)]
mod tests;
