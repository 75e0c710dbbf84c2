//! A method's report from its outcome: statistics per set (through the
//! compensator, if any), parameters with σ, stiffness 1/c, warnings (not
//! converged, compliance held at c = 0, stiffness outside the plausible range,
//! implausible payload), the compensator's summary and `auto`'s choice; the
//! model must load back from its JSON description.

use super::compensated::compensate_report;
use super::context::{Context, MethodFit, Outcome};
use super::{Method, MethodFailure};
use crate::calibrate::identify::least_squares::Fit;
use crate::calibrate::identify::report::{
    estimates, JointMapsSummary, MethodReport, MethodWarning, SetErrors, WarningKind,
};
use crate::model::calibrated::ValidationEvidence;
use crate::model::{ModelDescription, ParamId, ParamKind};

impl Context<'_> {
    /// `method`'s report of its `outcome`.
    pub(crate) fn report(
        &self,
        method: Method,
        outcome: Outcome,
    ) -> Result<MethodReport, MethodFailure> {
        let frames = outcome.fit.fit.session_frames.clone();
        let mut r = self.fit_report(method, outcome.fit)?;
        if !self.training.is_empty() {
            r.training = Some(SetErrors::of(&r.calibrated, &frames, self.training));
        }
        if let Some(applied) = &outcome.compensator {
            compensate_report(
                &mut r,
                applied,
                &frames,
                self.ident,
                self.training,
                self.valid,
            );
        }
        r.auto = outcome.auto;
        let model = crate::model::calibrated::CompensatedModel {
            compensator: r.compensator_arc(),
            ..crate::model::calibrated::CompensatedModel::from_nominal(r.calibrated.clone())
        };
        r.validation_evidence = ValidationEvidence::of(&model, &frames, self.valid);
        Ok(r)
    }

    /// The report of a fit: errors, parameters, stiffness, warnings; fails
    /// when the model does not load back from its description.
    fn fit_report(&self, method: Method, mf: MethodFit) -> Result<MethodReport, MethodFailure> {
        let MethodFit {
            fit: fitted,
            ids,
            tlbo,
            not_identified,
            maps,
        } = mf;
        let description = ModelDescription::from_model(&fitted.model);
        if let Err(cause) = description.to_model() {
            return Err(MethodFailure::DoesNotLoadBack { method, cause });
        }
        // The fit's last residuals are those of the identification set.
        let id_err = fitted
            .residuals
            .as_ref()
            .and_then(|r| SetErrors::from_residual_vector(self.ident, r))
            .unwrap_or_else(|| SetErrors::of(&fitted.model, &fitted.session_frames, self.ident));
        let va_err = (!self.valid.is_empty())
            .then(|| SetErrors::of(&fitted.model, &fitted.session_frames, self.valid));
        let mut warnings = Vec::new();
        if !fitted.report.converged {
            warnings.push(MethodWarning {
                kind: WarningKind::NotConverged,
                joint: None,
                message: format!("solver did not converge: {}", fitted.report.detail),
            });
        }
        for d in not_identified {
            warnings.push(MethodWarning {
                kind: WarningKind::ParameterNotIdentifiable,
                joint: None,
                message: format!("{} kept at its nominal value: {}", d.name, d.reason),
            });
        }
        for r in maps.iter().flat_map(|m| &m.refused) {
            warnings.push(MethodWarning {
                kind: WarningKind::MapRefused,
                joint: Some(r.joint),
                message: format!(
                    "no map for joint {} ({}): {}",
                    r.joint,
                    r.kind.name(),
                    r.reason
                ),
            });
        }
        let stiffness = self.stiffness(&fitted, &ids, tlbo.is_some(), &mut warnings);
        warnings.extend(self.payload_warning(fitted.model.payload.mass_offset));
        Ok(MethodReport {
            method,
            solver: fitted.report.clone(),
            identification: id_err,
            validation: va_err,
            training: None,
            parameters: estimates(
                self.nominal,
                &fitted.model,
                &ids,
                fitted.covariance.as_ref(),
                &fitted.at_bound,
            ),
            stiffness_nm_per_rad: stiffness,
            tlbo,
            warnings,
            model: description,
            compensator: None,
            auto: None,
            joint_maps: maps.map(|m| JointMapsSummary::of(&m, &fitted.model)),
            calibrated: fitted.model,
            stored_compensator: None,
            stored_support: None,
            stored_orientation: None,
            validation_evidence: None,
        })
    }

    /// The identified joint stiffness `1/c` [N·m/rad] per joint (none where
    /// compliance was not identified or is 0), with a warning for each
    /// compliance held at its bound 0 and each stiffness outside the
    /// plausible range. `by_tlbo`: the compliance was searched by TLBO.
    fn stiffness(
        &self,
        fitted: &Fit,
        ids: &[ParamId],
        by_tlbo: bool,
        warnings: &mut Vec<MethodWarning>,
    ) -> Vec<Option<f64>> {
        let [k_lo, k_hi] = self.opts.plausible_stiffness_nm_per_rad;
        let mut stiffness = Vec::with_capacity(fitted.model.dof());
        for (k, l) in fitted.model.links.iter().enumerate() {
            let cid = ParamId::new(ParamKind::Compliance, k);
            let Some(pos) = ids.iter().position(|i| *i == cid) else {
                stiffness.push(None);
                continue;
            };
            // TLBO searches c in [0, c_max] outside the LM's bounds.
            let at_bound = fitted.at_bound.get(pos).copied().unwrap_or(false)
                || (by_tlbo && l.compliance <= 0.0);
            if at_bound {
                warnings.push(MethodWarning {
                    kind: WarningKind::ComplianceAtBound,
                    joint: Some(k + 1),
                    message: format!(
                        "c{} held at its bound 0 (rigid): the data would pull it negative, i.e. the joint would move against its gravity torque; unmodelled effects or wrong masses / centres of mass are likely",
                        k + 1
                    ),
                });
            }
            if l.compliance > 0.0 {
                let kk = 1.0 / l.compliance;
                if !(k_lo..=k_hi).contains(&kk) {
                    warnings.push(MethodWarning {
                        kind: WarningKind::StiffnessImplausible,
                        joint: Some(k + 1),
                        message: format!(
                            "K{} = {kk:.3e} N·m/rad is outside the plausible range {k_lo:.0e}..{k_hi:.0e} N·m/rad",
                            k + 1
                        ),
                    });
                }
                stiffness.push(Some(kk));
            } else {
                stiffness.push(None);
            }
        }
        stiffness
    }

    /// A warning when the identified payload mass offset leaves a negative
    /// mass on some pose.
    fn payload_warning(&self, offset: f64) -> Option<MethodWarning> {
        if offset == 0.0 {
            return None;
        }
        let lightest = self
            .ident
            .iter()
            .chain(self.valid)
            .map(|m| m.payload_mass)
            .fold(f64::INFINITY, f64::min);
        if lightest + offset < 0.0 {
            return Some(MethodWarning {
                kind: WarningKind::PayloadImplausible,
                joint: None,
                message: format!(
                    "the identified payload mass offset {offset:+.2} kg leaves a negative mass on poses declared with {lightest:.2} kg: the payload and compliance are not separable in these poses"
                ),
            });
        }
        None
    }
}
