//! The calibration pipeline in phases: checks → registration → nominal errors
//! → identifiability → methods (each on its own, `methods`) → report.
//!
//! Frames: measured positions arrive in the measurement (tracker) frame of their
//! session; each session is registered in closed form onto the nominal model's
//! TCP positions (`registration`), after which every computation happens in the
//! registered base frame. The calibrated model maps joints to that frame; its
//! base parameters absorb the residual registration error of session 0, and
//! sessions ≥ 1 get their own frame correction. Units: SI inside, mm/deg in the
//! report.
//!
//! A method that fails (compliance on a model without masses, a model that
//! does not load back, …) is listed in `CalibrationReport::failed` with its
//! reason; the others are reported as usual. Only when every method fails is
//! the calibration an error.

use super::checks::{
    check_set, fixed_params, generic_rank, gravity_problem, joint_range_detail, stacked_jacobian,
    CalibrationError,
};
use super::identifiability::{self, IdentifiabilityReport};
use super::least_squares::Fit;
use super::methods::{Context, MethodError, MethodFit};
use super::options::{CalibrationOptions, Method, Progress};
use super::registration::register;
use super::report::{
    CalibrationReport, FailedMethod, NominalErrors, PoseSources, SessionRegistration, SetErrors,
    REPORT_FORMAT_VERSION,
};
use crate::kinematics::{deflected_joints, fk};
use crate::measure::Measurement;
use crate::model::description::PoseDescription;
use crate::model::pose::Pose;
use crate::model::{ParamId, ParamKind, ParamLayout, RobotModel};
use nalgebra::Vector3;
use std::collections::BTreeMap;

/// Measurements registered into the base frame.
struct Registered {
    ident: Vec<Measurement>,
    valid: Vec<Measurement>,
    sessions: usize,
    tracker_to_base: Vec<Pose>,
    reports: Vec<SessionRegistration>,
}

/// Registration per session onto the nominal TCP positions.
fn register_sessions(
    nominal: &RobotModel,
    identification: &[Measurement],
    validation: &[Measurement],
    opts: &CalibrationOptions,
) -> Result<Registered, CalibrationError> {
    let sessions = identification.iter().map(|m| m.session).max().unwrap_or(0) + 1;
    let mut regs = vec![Pose::identity(); sessions];
    let mut reports = Vec::new();
    if opts.register {
        for (s, reg) in regs.iter_mut().enumerate() {
            let (y, x): (Vec<Vector3<f64>>, Vec<Vector3<f64>>) = identification
                .iter()
                .filter(|m| m.session == s)
                .map(|m| {
                    let q = deflected_joints(nominal, &m.q, m.payload_mass).expect("checked");
                    (m.position, fk(nominal, &q).expect("checked").p)
                })
                .unzip();
            if y.is_empty() {
                continue;
            }
            let r = register(&y, &x)
                .map_err(|source| CalibrationError::Registration { session: s, source })?;
            *reg = r.tracker_to_base;
            reports.push(SessionRegistration {
                session: s,
                tracker_to_base: PoseDescription::from_pose(&r.tracker_to_base),
                rms_mm: r.rms * 1e3,
            });
        }
    }
    let to_base = |data: &[Measurement]| -> Vec<Measurement> {
        data.iter()
            .map(|m| {
                let t = regs.get(m.session).copied().unwrap_or_default();
                Measurement {
                    position: t.transform_point(&m.position),
                    orientation: m.orientation.map(|r| t.r * r),
                    ..m.clone()
                }
            })
            .collect()
    };
    Ok(Registered {
        ident: to_base(identification),
        valid: to_base(validation),
        sessions,
        tracker_to_base: regs,
        reports,
    })
}

/// The kept geometric and compliance parameters and the identifiability report.
struct Identifiable {
    kept_geo: Vec<ParamId>,
    kept_c: Vec<ParamId>,
    report: IdentifiabilityReport,
}

fn identifiability_phase(
    nominal: &RobotModel,
    reg: &Registered,
    with_compliance: bool,
    opts: &CalibrationOptions,
) -> Result<Identifiable, CalibrationError> {
    let ident = &reg.ident;
    let fixed = fixed_params(nominal);
    let geometric: Vec<ParamId> = ParamLayout::geometric(nominal)
        .ids
        .into_iter()
        .filter(|id| !fixed.iter().any(|(f, _)| f == id))
        .collect();
    let mut candidates = geometric.clone();
    if with_compliance {
        candidates.extend((0..nominal.dof()).map(|k| ParamId::new(ParamKind::Compliance, k)));
    }
    let j = stacked_jacobian(nominal, &candidates, ident);
    let analysis = identifiability::analyse(
        nominal,
        &j,
        &candidates,
        &fixed,
        ident.len(),
        &opts.identifiability,
    );
    let (kept_geo, kept_c): (Vec<ParamId>, Vec<ParamId>) =
        analysis.kept.iter().partition(|i| i.is_geometric());
    let any_orientation = ident.iter().any(|m| m.orientation.is_some());
    let per_pose = if any_orientation { 6 } else { 3 };
    let gen_rank = generic_rank(nominal, &geometric, any_orientation);
    let rows = j.nrows();
    // Near-dependent parameters are dropped on purpose; only a shortfall in
    // exact rank means the poses are too few or too alike.
    let near = analysis.report.near_dependent();
    if kept_geo.len() + near < gen_rank {
        if rows <= gen_rank {
            return Err(CalibrationError::TooFewPoses {
                poses: ident.len(),
                rows,
                params: gen_rank,
                needed: gen_rank / per_pose + 1,
            });
        }
        return Err(CalibrationError::SingularPoses {
            rank: kept_geo.len(),
            generic_rank: gen_rank,
            detail: joint_range_detail(nominal, ident),
        });
    }
    let n_unknowns = kept_geo.len() + kept_c.len() + (reg.sessions - 1) * 6;
    if rows <= n_unknowns {
        return Err(CalibrationError::TooFewPoses {
            poses: ident.len(),
            rows,
            params: n_unknowns,
            needed: n_unknowns / per_pose + 1,
        });
    }
    Ok(Identifiable {
        kept_geo,
        kept_c,
        report: analysis.report,
    })
}

/// Relative effort of a method, for the progress percentage.
fn weight(m: Method) -> f64 {
    match m {
        Method::SkcmTlbo => 8.0,
        Method::SkcmPayload => 2.0,
        _ => 1.0,
    }
}

/// Runs the calibration. `progress` returns false to cancel.
pub fn calibrate(
    nominal: &RobotModel,
    identification: &[Measurement],
    validation: &[Measurement],
    opts: &CalibrationOptions,
    progress: &dyn Fn(&Progress) -> bool,
) -> Result<CalibrationReport, CalibrationError> {
    let say = |phase: &str, iteration: usize, percent: f64, rms_mm: Option<f64>| {
        if progress(&Progress {
            phase: phase.to_string(),
            iteration,
            percent,
            rms_mm,
        }) {
            Ok(())
        } else {
            Err(CalibrationError::Cancelled)
        }
    };
    if identification.is_empty() {
        return Err(CalibrationError::NoData);
    }
    check_set(nominal, identification, "identification")?;
    check_set(nominal, validation, "validation")?;
    say("registration", 0, 0.0, None)?;
    let reg = register_sessions(nominal, identification, validation, opts)?;
    let id_frames = vec![Pose::identity(); reg.sessions];
    let nominal_errors = NominalErrors {
        identification: SetErrors::of(nominal, &id_frames, &reg.ident),
        validation: (!reg.valid.is_empty()).then(|| SetErrors::of(nominal, &id_frames, &reg.valid)),
    };
    let nominal_rms = nominal_errors.identification.stats.rms_mm;
    if nominal_rms > opts.max_nominal_rms_mm {
        return Err(CalibrationError::Inconsistent {
            rms_mm: nominal_rms,
            limit_mm: opts.max_nominal_rms_mm,
        });
    }

    // Compliance methods fail fast when gravity loads no joint.
    let mut failed: Vec<FailedMethod> = Vec::new();
    let gravity = gravity_problem(nominal, &reg.ident);
    let mut to_run: Vec<Method> = Vec::new();
    for m in &opts.methods {
        match (&gravity, m.uses_compliance()) {
            (Some(why), true) => failed.push(FailedMethod {
                method: *m,
                reason: why.clone(),
            }),
            _ => to_run.push(*m),
        }
    }
    if to_run.is_empty() {
        return Err(CalibrationError::AllMethodsFailed { failed });
    }

    say("identifiability", 0, 5.0, None)?;
    let with_compliance = to_run.iter().any(|m| m.uses_compliance());
    let idf = identifiability_phase(nominal, &reg, with_compliance, opts)?;
    let mut ident_report = idf.report;
    let mut start = nominal.clone();
    for l in start.links.iter_mut() {
        l.compliance = 0.0;
    }
    let ctx = Context {
        nominal,
        start,
        ident: &reg.ident,
        valid: &reg.valid,
        sessions: reg.sessions,
        kept_geo: idf.kept_geo,
        kept_c: idf.kept_c,
        opts,
    };

    let total: f64 = to_run.iter().map(|m| weight(*m)).sum();
    let mut done = 0.0;
    let mut methods = BTreeMap::new();
    let mut km_fit: Option<Fit> = None;
    let mut skcm_fit: Option<Fit> = None;
    for method in &to_run {
        let span = 90.0 * weight(*method) / total;
        let base_pct = 10.0 + 90.0 * done / total;
        let name = method.name();
        let max_it = opts.lm.max_iterations.max(1) as f64;
        let mut lm_progress = |it: usize, rms: f64| {
            progress(&Progress {
                phase: name.to_string(),
                iteration: it,
                percent: base_pct + span * (it as f64 / max_it).min(1.0),
                rms_mm: Some(rms),
            })
        };
        let outcome: Result<MethodFit, MethodError> = match method {
            Method::Km => ctx.km(&mut lm_progress).map_err(Into::into).map(|f| {
                km_fit = Some(f.clone());
                MethodFit {
                    ids: ctx.kept_geo.clone(),
                    fit: f,
                    tlbo: None,
                    not_identified: vec![],
                }
            }),
            Method::Skcm => ctx.skcm(&mut lm_progress).inspect(|mf| {
                skcm_fit = Some(mf.fit.clone());
            }),
            Method::SkcmTlbo => {
                let warm = match &km_fit {
                    Some(f) => f.clone(),
                    None => ctx
                        .km(&mut |_, _| true)
                        .map_err(|_| CalibrationError::Cancelled)?,
                };
                let generations = opts.tlbo.generations.max(1) as f64;
                ctx.skcm_tlbo(&warm, &mut |gen, best| {
                    progress(&Progress {
                        phase: name.to_string(),
                        iteration: gen,
                        percent: base_pct + span * (gen as f64 + 1.0) / generations,
                        rms_mm: Some(best.sqrt()),
                    })
                })
            }
            Method::SkcmPayload => {
                let skcm = match &skcm_fit {
                    Some(f) => Ok(f.clone()),
                    None => ctx.skcm(&mut |_, _| true).map(|mf| mf.fit),
                };
                skcm.and_then(|s| ctx.skcm_payload(&s, &mut lm_progress))
            }
        };
        done += weight(*method);
        let mf = match outcome {
            Ok(mf) => mf,
            Err(MethodError::Cancelled) => return Err(CalibrationError::Cancelled),
            Err(MethodError::Failed(reason)) => {
                failed.push(FailedMethod {
                    method: *method,
                    reason,
                });
                say(name, 0, 10.0 + 90.0 * done / total, None)?;
                continue;
            }
        };
        let uncertainty_source =
            *method == Method::Skcm || (*method == Method::Km && !to_run.contains(&Method::Skcm));
        if uncertainty_source {
            if let Some(cov) = &mf.fit.covariance {
                let (sd, pairs) = identifiability::uncertainty(
                    &mf.ids,
                    cov,
                    opts.identifiability.correlation_threshold,
                );
                ident_report.std_devs = sd;
                ident_report.correlated_pairs = pairs;
            }
        }
        match ctx.report(*method, mf) {
            Ok(r) => {
                methods.insert(name.to_string(), r);
            }
            Err(reason) => failed.push(FailedMethod {
                method: *method,
                reason,
            }),
        }
        say(name, 0, 10.0 + 90.0 * done / total, None)?;
    }
    if methods.is_empty() {
        return Err(CalibrationError::AllMethodsFailed { failed });
    }
    Ok(CalibrationReport {
        format_version: REPORT_FORMAT_VERSION,
        robot: nominal.name.clone(),
        identification_poses: identification.len(),
        validation_poses: validation.len(),
        registration: reg.reports,
        identifiability: ident_report,
        nominal: nominal_errors,
        methods,
        failed,
        session_names: Vec::new(),
        pose_sources: PoseSources::default(),
        tracker_to_base: reg.tracker_to_base[0],
    })
}
