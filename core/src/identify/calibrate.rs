//! The calibration pipeline in phases: checks → registration → nominal errors
//! → identifiability → methods (each on its own, `methods`; compensators and
//! `auto` in `hybrid`) → report.
//!
//! Frames: measured positions arrive in the measurement (tracker) frame of their
//! session; each session is registered in closed form onto the nominal model's
//! TCP positions (`registration`), after which every computation happens in the
//! registered base frame. The calibrated model maps joints to that frame; its
//! base parameters absorb the residual registration error of session 0, and
//! sessions ≥ 1 get their own frame correction. Units: SI inside, mm/deg in the
//! report.
//!
//! The identification poses' forward kinematics at the nominal model are
//! computed once, by the checks, and shared by the registration, the nominal
//! errors, the identifiability factor and the first evaluation of KM and SKCM.
//!
//! A method that fails (compliance on a model without masses, a model that
//! does not load back, …) is listed in `CalibrationReport::failed` with its
//! reason; the others are reported as usual. Only when every method fails is
//! the calibration an error.

use super::checks::{
    check_set, checked_chains, fixed_params, generic_rank, gravity_problem, joint_range_detail,
    stacked_factor, CalibrationError,
};
use super::hybrid::{compensate_report, run_auto, run_compensated, Cache, Hybrid};
use super::identifiability::{self, IdentifiabilityReport};
use super::least_squares::predict;
use super::methods::{Context, MethodError, MethodFit};
use super::options::{CalibrationOptions, Method, Progress};
use super::registration::register;
use super::report::{
    CalibrationReport, FailedMethod, NominalErrors, PoseSources, SessionRegistration, SetErrors,
    REPORT_FORMAT_VERSION,
};
use crate::kinematics::Chain;
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

/// Registration per session onto the nominal TCP positions `predicted` (one
/// per identification measurement, [`nominal_predictions`]).
fn register_sessions(
    identification: &[Measurement],
    predicted: &[Option<Vector3<f64>>],
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
                .zip(predicted)
                .filter(|(m, _)| m.session == s)
                .map(|(m, p)| (m.position, p.expect("checked")))
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
    let mut r = Registered {
        ident: Vec::new(),
        valid: Vec::new(),
        sessions,
        tracker_to_base: regs,
        reports,
    };
    r.ident = r.to_base(identification);
    r.valid = r.to_base(validation);
    Ok(r)
}

impl Registered {
    /// Measurements mapped into the registered base frame of their session.
    fn to_base(&self, data: &[Measurement]) -> Vec<Measurement> {
        data.iter()
            .map(|m| {
                let t = self
                    .tracker_to_base
                    .get(m.session)
                    .copied()
                    .unwrap_or_default();
                Measurement {
                    position: t.transform_point(&m.position),
                    orientation: m.orientation.map(|r| t.r * r),
                    ..m.clone()
                }
            })
            .collect()
    }
}

/// The nominal model's TCP positions at the (deflected) joints of `data`
/// (`least_squares::predict`), from the forward kinematics `chains` of `data`
/// at the commanded joints when the model has no compliance (the joints are
/// then not deflected: the same numbers without a second pass).
fn nominal_predictions(
    nominal: &RobotModel,
    data: &[Measurement],
    chains: &[Chain],
) -> Vec<Option<Vector3<f64>>> {
    if nominal.has_compliance() {
        data.iter()
            .map(|m| predict(nominal, m).map(|(p, _)| p))
            .collect()
    } else {
        chains.iter().map(|c| Some(c.tcp.p)).collect()
    }
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
    chains: &[Chain],
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
    let (j, rows) = stacked_factor(nominal, &candidates, ident, Some(chains));
    let analysis = identifiability::analyse_factor(
        nominal,
        &j,
        rows,
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
        Method::SkcmPayload | Method::KmRbf => 2.0,
        Method::SkcmNn | Method::SkcmIwonn | Method::SkcmTlbonn => 6.0,
        Method::Auto => 12.0,
        _ => 1.0,
    }
}

/// Runs the calibration without a compensator training pool. `progress`
/// returns false to cancel.
pub fn calibrate(
    nominal: &RobotModel,
    identification: &[Measurement],
    validation: &[Measurement],
    opts: &CalibrationOptions,
    progress: &dyn Fn(&Progress) -> bool,
) -> Result<CalibrationReport, CalibrationError> {
    calibrate_with_training(nominal, identification, &[], validation, opts, progress)
}

/// Runs the calibration with the data roles of docs/design.md "Data roles": Q1
/// `identification` fits the model-based part, Q2 `training` trains the
/// compensators (empty: they train on Q1 and are judged by k-fold
/// cross-validation inside it), Q3 `validation` is never fitted. Training
/// poses must come from tracker sessions that have identification poses.
/// `progress` returns false to cancel.
pub fn calibrate_with_training(
    nominal: &RobotModel,
    identification: &[Measurement],
    training: &[Measurement],
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
    // The nominal forward kinematics of the identification poses, shared by
    // the checks, the registration, the nominal errors, the identifiability
    // Jacobian and the first evaluation of the fits.
    let chains = checked_chains(nominal, identification, "identification")?;
    check_set(nominal, training, "training")?;
    check_set(nominal, validation, "validation")?;
    if let Some((index, m)) = training
        .iter()
        .enumerate()
        .find(|(_, m)| !identification.iter().any(|i| i.session == m.session))
    {
        return Err(CalibrationError::UnregisteredSession {
            set: "training",
            index,
            session: m.session,
        });
    }
    say("registration", 0, 0.0, None)?;
    let predicted = nominal_predictions(nominal, identification, &chains);
    let reg = register_sessions(identification, &predicted, validation, opts)?;
    let train_base = reg.to_base(training);
    let id_frames = vec![Pose::identity(); reg.sessions];
    let nominal_errors = NominalErrors {
        identification: SetErrors::from_predictions(
            &id_frames,
            &reg.ident,
            predicted.iter().copied(),
        ),
        validation: (!reg.valid.is_empty()).then(|| SetErrors::of(nominal, &id_frames, &reg.valid)),
    };
    let nominal_rms = nominal_errors.identification.stats.rms_mm;
    if nominal_rms > opts.max_nominal_rms_mm {
        return Err(CalibrationError::Inconsistent {
            rms_mm: nominal_rms,
            limit_mm: opts.max_nominal_rms_mm,
        });
    }

    // Methods that need gravity torques fail fast when gravity loads no joint.
    let mut failed: Vec<FailedMethod> = Vec::new();
    let gravity = gravity_problem(nominal, &reg.ident);
    let mut to_run: Vec<Method> = Vec::new();
    for m in &opts.methods {
        match (&gravity, m.uses_torques()) {
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
    let with_compliance = to_run
        .iter()
        .any(|m| m.uses_compliance() || (*m == Method::Auto && gravity.is_none()));
    let idf = identifiability_phase(nominal, &reg, &chains, with_compliance, opts)?;
    let mut ident_report = idf.report;
    let mut start = nominal.clone();
    for l in start.links.iter_mut() {
        l.compliance = 0.0;
    }
    let ctx = Context {
        nominal,
        start,
        ident: &reg.ident,
        ident_chains: &chains,
        valid: &reg.valid,
        sessions: reg.sessions,
        kept_geo: idf.kept_geo,
        kept_c: idf.kept_c,
        opts,
    };
    // The compensators' training pool: Q2, else Q1.
    let (pool, pool_name): (&[Measurement], &str) = if train_base.is_empty() {
        (&reg.ident, "identification")
    } else {
        (&train_base, "training")
    };

    let total: f64 = to_run.iter().map(|m| weight(*m)).sum();
    let mut done = 0.0;
    let mut methods = BTreeMap::new();
    let mut cache = Cache::default();
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
        let mut frac_progress = |f: f64, it: usize, loss: Option<f64>| {
            progress(&Progress {
                phase: name.to_string(),
                iteration: it,
                percent: base_pct + span * f.clamp(0.0, 1.0),
                rms_mm: loss,
            })
        };
        let plain = |mf: MethodFit| Hybrid {
            base: mf,
            compensator: None,
            auto: None,
        };
        let outcome: Result<Hybrid, MethodError> = match method {
            Method::Km | Method::Skcm => cache.base_fit(&ctx, *method, &mut lm_progress).map(plain),
            Method::SkcmTlbo => {
                let warm = match &cache.km {
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
                .map(plain)
            }
            Method::SkcmPayload => cache
                .base_fit(&ctx, Method::Skcm, &mut |_, _| true)
                .and_then(|s| ctx.skcm_payload(&s.fit, &mut lm_progress))
                .map(plain),
            Method::KmRbf | Method::SkcmNn | Method::SkcmIwonn | Method::SkcmTlbonn => {
                run_compensated(&ctx, &mut cache, *method, pool, &mut frac_progress)
            }
            Method::Auto => run_auto(
                &ctx,
                &mut cache,
                pool,
                pool_name,
                gravity.as_deref(),
                &mut frac_progress,
            ),
        };
        done += weight(*method);
        let h = match outcome {
            Ok(h) => h,
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
        let mf = h.base;
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
        let frames = mf.fit.session_frames.clone();
        match ctx.report(*method, mf) {
            Ok(mut r) => {
                if !train_base.is_empty() {
                    r.training = Some(SetErrors::of(&r.calibrated, &frames, &train_base));
                }
                if let Some((m, t)) = &h.compensator {
                    let base = m.base().expect("a compensator method");
                    compensate_report(
                        &mut r,
                        base,
                        &frames,
                        t,
                        &reg.ident,
                        &train_base,
                        &reg.valid,
                    );
                }
                r.auto = h.auto;
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
        training_poses: training.len(),
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
