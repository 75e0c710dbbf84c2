//! The calibration pipeline in phases: checks → registration → nominal errors
//! → identifiability → methods (each on its own, [`methods::run`]) → report.
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
use super::identifiability::{self, IdentifiabilityReport};
use super::least_squares::predict;
use super::methods::{
    self, Cache, Compliance, Context, Method, MethodError, MethodFailure, MethodProgress, Planner,
};
use super::options::CalibrationOptions;
use super::progress::{Phase, Progress, ProgressReporter, SystemClock};
use super::registration::register;
use super::report::{
    CalibrationReport, FailedMethod, MethodReport, NominalErrors, PoseSources, SessionRegistration,
    SetErrors, REPORT_FORMAT_VERSION,
};
use crate::measure::Measurement;
use crate::model::description::PoseDescription;
use crate::model::kinematics::Chain;
use crate::model::pose::Pose;
use crate::model::{ParamId, ParamKind, ParamLayout, RobotModel};
use nalgebra::{Matrix3, Vector3};
use std::collections::BTreeMap;

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
/// `progress` returns false to cancel; its reports come through a
/// [`ProgressReporter`] (percentage never decreasing, time left estimated).
pub fn calibrate_with_training(
    nominal: &RobotModel,
    identification: &[Measurement],
    training: &[Measurement],
    validation: &[Measurement],
    opts: &CalibrationOptions,
    progress: &dyn Fn(&Progress) -> bool,
) -> Result<CalibrationReport, CalibrationError> {
    let clock = SystemClock::start();
    let reporter = ProgressReporter::new(progress, &clock);
    let progress = &|p: &Progress| reporter.report(p);
    // The nominal forward kinematics of the identification poses, shared by
    // the checks, the registration, the nominal errors, the identifiability
    // Jacobian and the first evaluation of the fits.
    let chains = check_inputs(nominal, identification, training, validation)?;
    say(progress, Phase::Registration, 0.0)?;
    let prepared = prepare(nominal, identification, training, validation, &chains, opts)?;
    let reg = &prepared.reg;

    let gravity = gravity_problem(nominal, &reg.ident);
    let Plan { to_run, mut failed } = plan(&opts.methods, gravity.as_ref());
    if to_run.is_empty() {
        return Err(CalibrationError::AllMethodsFailed { failed });
    }

    say(progress, Phase::Identifiability, 5.0)?;
    let with_compliance = to_run.iter().any(|m| match m.row().compliance {
        Compliance::Yes => true,
        Compliance::IfLoaded => gravity.is_none(),
        Compliance::No => false,
    });
    let idf = identifiability_phase(nominal, reg, &chains, with_compliance, opts)?;
    let mut identifiability = idf.report;
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
        training: &prepared.training,
        sessions: reg.sessions,
        kept_geo: idf.kept_geo,
        kept_c: idf.kept_c,
        gravity,
        opts,
    };
    let methods = run_methods(&ctx, &to_run, &mut failed, &mut identifiability, progress)?;
    if methods.is_empty() {
        return Err(CalibrationError::AllMethodsFailed { failed });
    }
    Ok(CalibrationReport {
        format_version: REPORT_FORMAT_VERSION,
        robot: nominal.name.clone(),
        identification_poses: identification.len(),
        validation_poses: validation.len(),
        training_poses: training.len(),
        registration: prepared.reg.reports,
        identifiability,
        nominal: prepared.nominal,
        methods,
        failed,
        session_names: Vec::new(),
        pose_sources: PoseSources::default(),
        tracker_to_base: prepared.reg.tracker_to_base[0],
    })
}

/// Reports a phase without iterations at `percent`; cancelled when
/// `progress` says so.
fn say(
    progress: &dyn Fn(&Progress) -> bool,
    phase: Phase,
    percent: f64,
) -> Result<(), CalibrationError> {
    if progress(&Progress::at(phase, percent)) {
        Ok(())
    } else {
        Err(CalibrationError::Cancelled)
    }
}

/// Checks every set; returns the nominal forward kinematics of the
/// identification poses.
fn check_inputs(
    nominal: &RobotModel,
    identification: &[Measurement],
    training: &[Measurement],
    validation: &[Measurement],
) -> Result<Vec<Chain>, CalibrationError> {
    if identification.is_empty() {
        return Err(CalibrationError::NoData);
    }
    let chains = checked_chains(nominal, identification, "identification")?;
    check_set(nominal, training, "training")?;
    check_set(nominal, validation, "validation")?;
    let fitted = identification.iter().chain(training);
    let with = fitted.clone().filter(|m| m.std.is_some()).count();
    let total = identification.len() + training.len();
    if with > 0 && with < total {
        return Err(CalibrationError::MixedStd { with, total });
    }
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
    Ok(chains)
}

/// The methods to run, and those that failed before they started.
struct Plan {
    to_run: Vec<Method>,
    failed: Vec<FailedMethod>,
}

/// Methods that need gravity torques fail fast when gravity loads no joint
/// (`gravity` says why).
fn plan(methods: &[Method], gravity: Option<&MethodFailure>) -> Plan {
    let mut p = Plan {
        to_run: Vec::new(),
        failed: Vec::new(),
    };
    for &method in methods {
        match gravity {
            Some(why) if method.uses_torques() => p.failed.push(FailedMethod {
                method,
                reason: why.to_string(),
            }),
            _ => p.to_run.push(method),
        }
    }
    p
}

/// The sets in the registered base frame and the nominal model's errors.
struct Prepared {
    reg: Registered,
    /// The compensators' training poses (Q2) in the base frame.
    training: Vec<Measurement>,
    nominal: NominalErrors,
}

/// Registers every session and measures the nominal model; rejects data
/// inconsistent with the model.
fn prepare(
    nominal: &RobotModel,
    identification: &[Measurement],
    training: &[Measurement],
    validation: &[Measurement],
    chains: &[Chain],
    opts: &CalibrationOptions,
) -> Result<Prepared, CalibrationError> {
    let poses = nominal_predictions(nominal, identification, chains);
    let predicted: Vec<Option<Vector3<f64>>> = poses.iter().map(|p| p.map(|(p, _)| p)).collect();
    if predicted
        .iter()
        .any(|p| !p.is_some_and(|p| p.iter().all(|v| v.is_finite())))
    {
        return Err(CalibrationError::ModelNotFinite {
            what: "a TCP position that is not finite (or a joint deflection that does not settle)",
        });
    }
    let reg = register_sessions(identification, &predicted, validation, opts)?;
    let training = reg.to_base(training);
    let id_frames = vec![Pose::identity(); reg.sessions];
    let nominal_errors = NominalErrors {
        identification: SetErrors::from_predictions(&id_frames, &reg.ident, poses.iter().copied()),
        validation: (!reg.valid.is_empty()).then(|| SetErrors::of(nominal, &id_frames, &reg.valid)),
    };
    let nominal_rms = nominal_errors.identification.stats.rms_mm;
    if !nominal_rms.is_finite() {
        return Err(CalibrationError::ModelNotFinite {
            what: "errors to the measurements that are not finite",
        });
    }
    if nominal_rms > opts.max_nominal_rms_mm {
        return Err(CalibrationError::Inconsistent {
            rms_mm: nominal_rms,
            limit_mm: opts.max_nominal_rms_mm,
        });
    }
    Ok(Prepared {
        reg,
        training,
        nominal: nominal_errors,
    })
}

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
                .map(|(m, p)| (m.position, p.unwrap_or(Vector3::repeat(f64::NAN))))
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

/// The nominal model's TCP poses (position, rotation) at the (deflected) joints of `data`
/// (`least_squares::predict`), from the forward kinematics `chains` of `data`
/// at the commanded joints when the model has no compliance (the joints are
/// then not deflected: the same numbers without a second pass).
fn nominal_predictions(
    nominal: &RobotModel,
    data: &[Measurement],
    chains: &[Chain],
) -> Vec<Option<(Vector3<f64>, Matrix3<f64>)>> {
    if nominal.has_compliance() {
        data.iter().map(|m| predict(nominal, m)).collect()
    } else {
        chains.iter().map(|c| Some((c.tcp.p, c.tcp.r))).collect()
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
    if j.iter().any(|v| !v.is_finite()) {
        return Err(CalibrationError::ModelNotFinite {
            what: "a non-finite identification Jacobian",
        });
    }
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
    let mut report = analysis.report;
    if any_orientation {
        report.identifiable_by_orientation =
            identifiable_by_orientation(nominal, ident, chains, &candidates, &analysis.kept, opts);
    } else {
        report.unseen_tool_tip_terms =
            unseen_without_orientation(nominal, ident, chains, &candidates, &analysis.kept, opts);
    }
    let per_pose = if any_orientation { 6 } else { 3 };
    let gen_rank = generic_rank(nominal, &geometric, any_orientation);
    // Near-dependent parameters are dropped on purpose; only a shortfall in
    // exact rank means the poses are too few or too alike.
    let near = report.near_dependent();
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
        report,
    })
}

/// The parameters of `kept` that the poses of `ident` identify only through
/// their orientation rows: the analysis of the same poses with the
/// orientations removed does not keep them.
fn identifiable_by_orientation(
    nominal: &RobotModel,
    ident: &[Measurement],
    chains: &[Chain],
    candidates: &[ParamId],
    kept: &[ParamId],
    opts: &CalibrationOptions,
) -> Vec<String> {
    let without = kept_with_orientation(nominal, ident, None, chains, candidates, opts);
    kept.iter()
        .filter(|id| !without.contains(id))
        .map(|id| id.name())
        .collect()
}

/// With position-only `ident`: the parameters the same poses would identify
/// if each had also measured an orientation, and `kept` (the position-only
/// analysis) lacks. The Jacobian rows do not depend on the measured values,
/// so any rotation stands in for the missing ones.
fn unseen_without_orientation(
    nominal: &RobotModel,
    ident: &[Measurement],
    chains: &[Chain],
    candidates: &[ParamId],
    kept: &[ParamId],
    opts: &CalibrationOptions,
) -> Vec<String> {
    let with = kept_with_orientation(
        nominal,
        ident,
        Some(Matrix3::identity()),
        chains,
        candidates,
        opts,
    );
    with.iter()
        .filter(|id| !kept.contains(id))
        .map(|id| id.name())
        .collect()
}

/// The parameters the identifiability analysis keeps for the poses of
/// `ident`, every pose's orientation replaced by `orientation`.
fn kept_with_orientation(
    nominal: &RobotModel,
    ident: &[Measurement],
    orientation: Option<Matrix3<f64>>,
    chains: &[Chain],
    candidates: &[ParamId],
    opts: &CalibrationOptions,
) -> Vec<ParamId> {
    let poses: Vec<Measurement> = ident
        .iter()
        .map(|m| Measurement {
            orientation,
            ..m.clone()
        })
        .collect();
    let (j, rows) = stacked_factor(nominal, candidates, &poses, Some(chains));
    identifiability::analyse_factor(
        nominal,
        &j,
        rows,
        candidates,
        &fixed_params(nominal),
        ident.len(),
        &opts.identifiability,
    )
    .kept
}

/// Runs every method of `to_run` in order over 10–100 % of the bar, each by
/// the work planned for it up front (`methods::Planner`: what an earlier
/// method already computed costs it nothing); a failure joins `failed`. The σ and correlations of
/// `identifiability` come from SKCM's fit, else KM's.
fn run_methods(
    ctx: &Context,
    to_run: &[Method],
    failed: &mut Vec<FailedMethod>,
    identifiability: &mut IdentifiabilityReport,
    progress: &dyn Fn(&Progress) -> bool,
) -> Result<BTreeMap<Method, MethodReport>, CalibrationError> {
    let mut plan = Planner::default();
    let units: Vec<f64> = to_run.iter().map(|m| plan.method(ctx, *m)).collect();
    let total = units.iter().sum::<f64>().max(f64::MIN_POSITIVE);
    let mut done = 0.0;
    let mut reports = BTreeMap::new();
    let mut cache = Cache::default();
    for (&method, units) in to_run.iter().zip(&units) {
        let share = MethodProgress {
            method,
            start: 10.0 + 90.0 * done / total,
            span: 90.0 * units / total,
            opts: ctx.opts,
            sink: progress,
        };
        let outcome = methods::run(method, ctx, &mut cache, &share);
        done += units;
        let phase = Phase::Method(method);
        let outcome = match outcome {
            Ok(o) => o,
            Err(MethodError::Cancelled) => return Err(CalibrationError::Cancelled),
            Err(MethodError::Failed(f)) => {
                failed.push(FailedMethod {
                    method,
                    reason: f.to_string(),
                });
                say(progress, phase, 10.0 + 90.0 * done / total)?;
                continue;
            }
        };
        let uncertainty_source =
            method == Method::Skcm || (method == Method::Km && !to_run.contains(&Method::Skcm));
        if uncertainty_source {
            if let Some(cov) = &outcome.fit.fit.covariance {
                let (sd, pairs) = identifiability::uncertainty(
                    &outcome.fit.ids,
                    cov,
                    ctx.opts.identifiability.correlation_threshold,
                );
                identifiability.std_devs = sd;
                identifiability.correlated_pairs = pairs;
            }
        }
        match ctx.report(method, outcome) {
            Ok(r) => {
                reports.insert(method, r);
            }
            Err(f) => failed.push(FailedMethod {
                method,
                reason: f.to_string(),
            }),
        }
        say(progress, phase, 10.0 + 90.0 * done / total)?;
    }
    Ok(reports)
}
