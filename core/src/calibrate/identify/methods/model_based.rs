//! The model-based methods, each run on its own (one failing never stops the
//! others):
//!
//! - **KM** (thesis §2.2, eqs. 2.3–2.4): LM on the kept geometric parameters.
//! - **SKCM** (§2.3, eq. 2.8; closed loop eq. 4.17): the same with the
//!   compliance columns `J_θ·diag(τ)`, compliance bounded to `c ≥ 0`
//!   (projected LM, `least_squares::fit`).
//! - **SKCM-C by TLBO** (ch. 7): TLBO searches the compliance vector C of the
//!   loaded joints in `[0, c_max]`; each candidate deflects the joints by `C∘τ`
//!   (eq. 7.9) and a frozen-Jacobian inner KM (eq. 7.8) fits the geometry and
//!   the frames of every tracker session from one fixed reference (the KM fit),
//!   so a candidate's cost is a function of the candidate alone. The cost is
//!   eq. 7.10, `mean(e²) + 0.5·max(e²) + 0.3·std(e²)` over the squared
//!   position-error norms (mm²).
//! - **SKCM-payload** (beyond the thesis): the seed assumes the payload's centre
//!   of mass r (tool frame) known. SKCM with a wrong r absorbs the wrong torques
//!   into wrong compliances. This method starts from the SKCM fit and fits
//!   geometry, compliance and r jointly: `p = FK(φ, q + c∘τ(q, M, r))`, with the
//!   columns `Σ_k c_k·(∂τ_k/∂r_j)·J_k` (`kinematics::jacobian`). The mass is
//!   each pose's `payload_kg` plus one offset ΔM common to all poses (an
//!   unknown tool or adapter), fitted jointly with the column
//!   `Σ_k c_k·(∂τ_k/∂M)·J_k`, when the poses carry at least two different
//!   payload masses (with one, the offset trades off against the CoM along the
//!   tool axis and stays at 0, reported as not identified); like every
//!   candidate it is then kept only when the poses make it identifiable, and a
//!   total mass below zero on any pose is a warning.

use super::context::{Context, MethodFit};
use super::{MethodError, MethodFailure};
use crate::calibrate::identify::checks::{payload_problem, stacked_factor};
use crate::calibrate::identify::identifiability::{self, DroppedParam};
use crate::calibrate::identify::least_squares::{
    fit, fit_with_start_chains, Cancelled, Fit, FrozenSolver,
};
use crate::calibrate::identify::options::CalibrationOptions;
use crate::calibrate::identify::report::TlboSummary;
use crate::measure::Measurement;
use crate::model::kinematics::{chain, gravity_torques_of};
use crate::model::pose::Pose;
use crate::model::{ParamId, ParamKind, RobotModel};
use crate::optim::tlbo;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

impl Context<'_> {
    fn with_compliance(&self) -> Vec<ParamId> {
        self.kept_geo.iter().chain(&self.kept_c).copied().collect()
    }

    pub(crate) fn km(
        &self,
        progress: &mut dyn FnMut(usize, f64) -> bool,
    ) -> Result<Fit, Cancelled> {
        self.fit_from_start(&self.kept_geo, progress)
    }

    /// [`Context::fit_from`] `start`, whose forward kinematics at the
    /// identification poses are known.
    fn fit_from_start(
        &self,
        ids: &[ParamId],
        progress: &mut dyn FnMut(usize, f64) -> bool,
    ) -> Result<Fit, Cancelled> {
        fit_with_start_chains(
            &self.start,
            ids,
            self.ident,
            self.sessions,
            &self.opts.lm,
            Some(self.ident_chains),
            progress,
        )
    }

    fn require_compliance(&self) -> Result<(), MethodError> {
        if self.kept_c.is_empty() {
            return Err(MethodFailure::NoComplianceIdentifiable.into());
        }
        Ok(())
    }

    /// LM on `ids` from `start` with the identification poses and every
    /// tracker session (`least_squares::fit`).
    fn fit_from(
        &self,
        start: &RobotModel,
        ids: &[ParamId],
        progress: &mut dyn FnMut(usize, f64) -> bool,
    ) -> Result<Fit, Cancelled> {
        fit(
            start,
            ids,
            self.ident,
            self.sessions,
            &self.opts.lm,
            progress,
        )
    }

    pub(crate) fn skcm(
        &self,
        progress: &mut dyn FnMut(usize, f64) -> bool,
    ) -> Result<MethodFit, MethodError> {
        self.require_compliance()?;
        let ids = self.with_compliance();
        let f = self.fit_from_start(&ids, progress)?;
        Ok(MethodFit {
            fit: f,
            ids,
            tlbo: None,
            not_identified: vec![],
            maps: None,
        })
    }

    /// SKCM-C by TLBO from the KM fit `warm`.
    pub(crate) fn skcm_tlbo(
        &self,
        warm: &Fit,
        progress: &mut dyn FnMut(usize, f64) -> bool,
    ) -> Result<MethodFit, MethodError> {
        self.require_compliance()?;
        let cost = SkcmCCost::new(warm, &self.kept_geo, &self.kept_c, self.ident, self.opts)
            .ok_or(MethodFailure::SingularReference)?;
        let hi = cost.search_box(self.opts.tlbo_max_deflection_rad);
        let lo = vec![0.0; hi.len()];
        let mut rng = ChaCha8Rng::seed_from_u64(self.opts.tlbo.seed);
        let mut cancelled = false;
        let mut f = |c: &[f64]| cost.cost(c);
        let result = tlbo::minimise(&mut f, &lo, &hi, &self.opts.tlbo, &mut rng, &mut |g, b| {
            let go = progress(g, b);
            cancelled |= !go;
            go
        });
        if cancelled {
            return Err(MethodError::Cancelled);
        }
        let start = cost.with_c(&result.best);
        // The polish after the last generation stays cancellable.
        let (gens, best) = (result.history.len().saturating_sub(1), result.best_cost);
        let f = self.fit_from(&start, &self.kept_geo, &mut |_, _| progress(gens, best))?;
        Ok(MethodFit {
            fit: f,
            ids: self.with_compliance(),
            tlbo: Some(TlboSummary {
                population: self.opts.tlbo.population,
                generations: result.history.len(),
                evaluations: result.evaluations,
                history: result.history,
            }),
            not_identified: vec![],
            maps: None,
        })
    }

    /// SKCM with the payload's centre of mass, from the SKCM fit `skcm`.
    pub(crate) fn skcm_payload(
        &self,
        skcm: &Fit,
        progress: &mut dyn FnMut(usize, f64) -> bool,
    ) -> Result<MethodFit, MethodError> {
        self.require_compliance()?;
        if let Some(why) = payload_problem(self.ident) {
            return Err(why.into());
        }
        if !skcm.model.has_compliance() {
            return Err(MethodFailure::NoComplianceIdentified.into());
        }
        // Which payload parameters the poses excite, at the SKCM compliance.
        let base = self.with_compliance();
        let mut masses: Vec<f64> = self.ident.iter().map(|m| m.payload_mass).collect();
        masses.sort_by(f64::total_cmp);
        masses.dedup_by(|a, b| (*a - *b).abs() < 1e-6);
        let mut payload: Vec<ParamId> = [
            ParamKind::PayloadX,
            ParamKind::PayloadY,
            ParamKind::PayloadZ,
        ]
        .map(|k| ParamId::new(k, 0))
        .to_vec();
        let mass_offset = ParamId::new(ParamKind::PayloadMass, 0);
        let mut single_mass = Vec::new();
        if masses.len() >= 2 {
            payload.push(mass_offset);
        } else {
            single_mass.push(DroppedParam {
                name: mass_offset.name(),
                kind: identifiability::DropKind::NearlyDependent,
                reason: "every pose carries the same payload mass, so an unknown mass offset is not separable from the centre of mass along the tool axis; measure a set with a different payload to identify it".into(),
                depends_on: vec!["payload_z".into()],
            });
        }
        let candidates: Vec<ParamId> = base.iter().chain(&payload).copied().collect();
        let (j, rows) = stacked_factor(&skcm.model, &candidates, self.ident, None);
        let analysis = identifiability::analyse_factor(
            &skcm.model,
            &j,
            rows,
            &candidates,
            &[],
            self.ident.len(),
            &self.opts.identifiability,
        );
        let kept_payload: Vec<ParamId> = payload
            .iter()
            .copied()
            .filter(|p| analysis.kept.contains(p))
            .collect();
        if kept_payload.is_empty() {
            return Err(MethodFailure::PayloadNotExcited.into());
        }
        let not_identified = analysis
            .report
            .dropped
            .into_iter()
            .filter(|d| payload.iter().any(|p| p.name() == d.name))
            .chain(single_mass)
            .collect();
        let ids: Vec<ParamId> = base.iter().chain(&kept_payload).copied().collect();
        let f = self.fit_from(&skcm.model, &ids, progress)?;
        Ok(MethodFit {
            fit: f,
            ids,
            tlbo: None,
            not_identified,
            maps: None,
        })
    }
}

/// Eq. 7.10 on squared error norms [mm²].
fn tlbo_cost(errors_mm: &[f64]) -> f64 {
    let sq: Vec<f64> = errors_mm.iter().map(|e| e * e).collect();
    let n = sq.len() as f64;
    let mean = sq.iter().sum::<f64>() / n;
    let max = sq.iter().cloned().fold(0.0, f64::max);
    let std = if sq.len() > 1 {
        (sq.iter().map(|s| (s - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
    } else {
        0.0
    };
    mean + 0.5 * max + 0.3 * std
}

/// Inner iterations of the frozen-Jacobian KM per TLBO candidate.
const INNER_ITERATIONS: usize = 20;

/// The SKCM-C cost of a compliance candidate (eq. 7.10 after the inner KM of
/// eq. 7.8). A pure function of the candidate: the reference geometry, session
/// frames and the factorised Jacobian are fixed when it is built.
pub(crate) struct SkcmCCost<'a> {
    reference: RobotModel,
    kept_c: &'a [ParamId],
    ident: &'a [Measurement],
    solver: FrozenSolver,
    opts: &'a CalibrationOptions,
}

impl<'a> SkcmCCost<'a> {
    pub(super) fn new(
        warm: &Fit,
        kept_geo: &[ParamId],
        kept_c: &'a [ParamId],
        ident: &'a [Measurement],
        opts: &'a CalibrationOptions,
    ) -> Option<Self> {
        let frames: Vec<Pose> = warm.session_frames.clone();
        let solver = FrozenSolver::new(&warm.model, &frames, kept_geo, ident, &opts.lm)?;
        Some(SkcmCCost {
            reference: warm.model.clone(),
            kept_c,
            ident,
            solver,
            opts,
        })
    }

    /// Upper bounds of the search: compliance up to the deflection limit at the
    /// largest torque of each loaded joint.
    pub(super) fn search_box(&self, max_deflection_rad: f64) -> Vec<f64> {
        let mut max_tau = vec![0.0_f64; self.kept_c.len()];
        for m in self.ident {
            let c0 = chain(&self.reference, &m.q).expect("checked");
            let tau = gravity_torques_of(&self.reference, &c0, m.payload_mass);
            for (i, id) in self.kept_c.iter().enumerate() {
                max_tau[i] = max_tau[i].max(tau[id.link].abs());
            }
        }
        max_tau
            .iter()
            .map(|t| max_deflection_rad / t.max(1e-9))
            .collect()
    }

    /// The reference geometry with compliance `c`.
    pub(super) fn with_c(&self, c: &[f64]) -> RobotModel {
        let mut m = self.reference.clone();
        for (id, v) in self.kept_c.iter().zip(c) {
            m.links[id.link].compliance = *v;
        }
        m
    }

    /// Eq. 7.10 cost [mm²] of candidate `c` (infinite when the inner fit fails).
    pub(super) fn cost(&self, c: &[f64]) -> f64 {
        match self.solver.solve(
            &self.with_c(c),
            self.ident,
            &self.opts.lm,
            INNER_ITERATIONS,
            1e-12,
        ) {
            Some((_, _, e)) => tlbo_cost(&e),
            None => f64::INFINITY,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibrate::identify::checks::stacked_jacobian;
    use crate::measure::to_measurements;
    use crate::model::preset;
    use crate::model::ParamLayout;
    use crate::sim::{perturb_geometry, random_configurations, ErrorMagnitudes, TrueRobot};

    /// A TLBO candidate's cost depends on the candidate alone: the same c gives
    /// the same cost whatever was evaluated before (the greedy acceptance of
    /// TLBO compares like with like).
    #[test]
    fn skcm_c_cost_is_a_function_of_the_candidate() {
        let nominal = preset("ys100").unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut tm = perturb_geometry(&nominal, &ErrorMagnitudes::from_mm_deg(1.0, 0.1), &mut rng);
        for (k, l) in tm.links.iter_mut().enumerate() {
            l.compliance = if (1..5).contains(&k) { 1e-6 } else { 0.0 };
        }
        let truth = TrueRobot::new(tm);
        let qs = random_configurations(&nominal, 30, &mut rng);
        let rows = truth
            .measure(&qs, Some(nominal.payload.mass), None, &mut rng)
            .unwrap();
        let ident = to_measurements(&nominal, &rows, nominal.payload.mass);
        let mut start = nominal.clone();
        for l in start.links.iter_mut() {
            l.compliance = 0.0;
        }
        let geo = ParamLayout::geometric(&nominal).ids;
        let j = stacked_jacobian(&nominal, &geo, &ident);
        let opts = CalibrationOptions::default();
        let kept_geo =
            identifiability::analyse(&nominal, &j, &geo, &[], 30, &opts.identifiability).kept;
        let kept_c: Vec<ParamId> = (1..5)
            .map(|k| ParamId::new(ParamKind::Compliance, k))
            .collect();
        let warm = fit(&start, &kept_geo, &ident, 1, &opts.lm, &mut |_, _| true).unwrap();
        let cost = SkcmCCost::new(&warm, &kept_geo, &kept_c, &ident, &opts).unwrap();
        let a = [1.0e-6, 1.0e-6, 1.0e-6, 1.0e-6];
        let b = [2.0e-6, 0.5e-6, 3.0e-7, 1.5e-6];
        let first = cost.cost(&a);
        let _ = cost.cost(&b);
        let again = cost.cost(&a);
        assert_eq!(first.to_bits(), again.to_bits());
        // The truth's compliance costs far less than a wrong one.
        assert!(
            cost.cost(&a) < 0.01 * cost.cost(&b),
            "{first} vs {}",
            cost.cost(&b)
        );
    }
}
