//! The calibration pipeline: checks → registration → identifiability → methods
//! (KM, SKCM, SKCM-C by TLBO) → statistics per set.
//!
//! Frames: measured positions arrive in the measurement (tracker) frame of their
//! session; each session is registered in closed form onto the nominal model's
//! TCP positions (`registration`), after which every computation happens in the
//! registered base frame. The calibrated model maps joints to that frame; its
//! base parameters absorb the residual registration error of session 0, and
//! sessions ≥ 1 get their own frame correction. Units: SI inside, mm/deg in the
//! report.
//!
//! SKCM-C by TLBO (ch. 7): TLBO searches the compliance vector C of the joints
//! gravity loads; for each candidate the joints are deflected by `C∘τ` (eq. 7.9)
//! and an inner least-squares KM (eq. 7.8) fits the geometry; the candidate's
//! cost is eq. 7.10, `mean(e²) + 0.5·max(e²) + 0.3·std(e²)` over the squared
//! position-error norms (mm²).

use super::identifiability::{self, IdentifiabilityReport, IdentifiabilitySettings};
use super::least_squares::{self, fit, Cancelled, LmReport, LmSettings};
use super::registration::{register, RegistrationError};
use super::stats::ErrorStats;
use super::tlbo::{self, TlboSettings};
use crate::kinematics::{chain, deflected_joints, fk, gravity_torques_of, KinematicsError};
use crate::measure::Measurement;
use crate::model::description::PoseDescription;
use crate::model::params::ParamUnit;
use crate::model::pose::Pose;
use crate::model::{ModelDescription, ParamId, ParamKind, ParamLayout, RobotModel};
use nalgebra::{DMatrix, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// A calibration method of the seed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Kinematic calibration, §2.2.
    Km,
    /// Simultaneous kinematic and compliance calibration, §2.3.
    Skcm,
    /// SKCM with the compliance searched by TLBO, ch. 7.
    SkcmTlbo,
}

impl Method {
    pub const ALL: [Method; 3] = [Method::Km, Method::Skcm, Method::SkcmTlbo];

    pub fn name(&self) -> &'static str {
        match self {
            Method::Km => "km",
            Method::Skcm => "skcm",
            Method::SkcmTlbo => "skcm-tlbo",
        }
    }

    pub fn parse(s: &str) -> Option<Method> {
        match s.trim().to_ascii_lowercase().as_str() {
            "km" => Some(Method::Km),
            "skcm" => Some(Method::Skcm),
            "skcm-tlbo" | "skcm-c" | "skcm_tlbo" | "tlbo" => Some(Method::SkcmTlbo),
            _ => None,
        }
    }

    /// Parses a comma-separated list, naming any unknown entry.
    pub fn parse_list(s: &str) -> Result<Vec<Method>, String> {
        let mut out = Vec::new();
        for part in s.split(',').filter(|p| !p.trim().is_empty()) {
            let m = Method::parse(part).ok_or_else(|| {
                format!(
                    "unknown method `{}` (known: km, skcm, skcm-tlbo)",
                    part.trim()
                )
            })?;
            if !out.contains(&m) {
                out.push(m);
            }
        }
        if out.is_empty() {
            return Err("no method given (known: km, skcm, skcm-tlbo)".into());
        }
        Ok(out)
    }
}

/// Calibration settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CalibrationOptions {
    pub methods: Vec<Method>,
    /// Register the measurement frame in closed form first (off only when the
    /// data is already in the base frame and should stay there exactly).
    pub register: bool,
    pub lm: LmSettings,
    pub tlbo: TlboSettings,
    pub identifiability: IdentifiabilitySettings,
    /// Above this RMS [mm] of the nominal model after registration, the data is
    /// rejected as inconsistent with the model (units, joint order, signs).
    pub max_nominal_rms_mm: f64,
    /// Upper bound of the TLBO compliance search, as the largest joint deflection
    /// it may cause in the identification poses [rad].
    pub tlbo_max_deflection_rad: f64,
}

impl Default for CalibrationOptions {
    fn default() -> Self {
        CalibrationOptions {
            methods: Method::ALL.to_vec(),
            register: true,
            lm: LmSettings::default(),
            tlbo: TlboSettings::default(),
            identifiability: IdentifiabilitySettings::default(),
            max_nominal_rms_mm: 250.0,
            tlbo_max_deflection_rad: 0.01,
        }
    }
}

/// Progress of a running calibration.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Progress {
    pub phase: String,
    pub iteration: usize,
    /// Overall completion in [0, 100].
    pub percent: f64,
    /// Current RMS residual [mm], when the phase has one.
    pub rms_mm: Option<f64>,
}

/// Why a calibration cannot run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CalibrationError {
    #[error("the identification set is empty")]
    NoData,
    #[error(
        "{set} measurement {index}: expected {expected} joint values for this robot, got {got}"
    )]
    JointCount {
        set: &'static str,
        index: usize,
        expected: usize,
        got: usize,
    },
    #[error("{set} measurement {index}: {what} is not a finite number")]
    NotFinite {
        set: &'static str,
        index: usize,
        what: &'static str,
    },
    #[error("too few poses: {poses} poses give {rows} equations, but this robot has {params} identifiable parameters; measure at least {needed} poses (3 to 5 times that is better)")]
    TooFewPoses {
        poses: usize,
        rows: usize,
        params: usize,
        needed: usize,
    },
    #[error("singular pose set: the poses excite only {rank} of the robot's {generic_rank} identifiable parameter combinations{detail}; measure poses that move every joint across its range")]
    SingularPoses {
        rank: usize,
        generic_rank: usize,
        detail: String,
    },
    #[error("registration of session {session}: {source}")]
    Registration {
        session: usize,
        source: RegistrationError,
    },
    #[error("the measurements do not fit the model: RMS {rms_mm:.1} mm after registering the tracker frame (limit {limit_mm:.0} mm); check units (positions in mm, joints in degrees), joint order and signs, and the model")]
    Inconsistent { rms_mm: f64, limit_mm: f64 },
    #[error("{set} measurement {index}: {source}")]
    Kinematics {
        set: &'static str,
        index: usize,
        source: KinematicsError,
    },
    #[error("calibration cancelled")]
    Cancelled,
}

/// Errors of one set: statistics plus the per-pose error norms (mm).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SetErrors {
    #[serde(flatten)]
    pub stats: ErrorStats,
    pub errors_mm: Vec<f64>,
}

impl SetErrors {
    fn new(errors_mm: Vec<f64>) -> Self {
        SetErrors {
            stats: ErrorStats::from_errors_mm(&errors_mm),
            errors_mm,
        }
    }
}

/// One identified parameter in display units (mm, deg or rad/(N·m)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamEstimate {
    pub name: String,
    pub unit: String,
    pub nominal: f64,
    pub value: f64,
    pub std: Option<f64>,
}

/// TLBO summary of SKCM-C.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TlboSummary {
    pub population: usize,
    pub generations: usize,
    pub evaluations: usize,
    /// Best eq. 7.10 cost [mm²] after each generation.
    pub history: Vec<f64>,
}

/// Result of one method.
#[derive(Debug, Clone, Serialize)]
pub struct MethodReport {
    pub method: Method,
    pub solver: LmReport,
    pub identification: SetErrors,
    pub validation: Option<SetErrors>,
    pub parameters: Vec<ParamEstimate>,
    /// Identified joint stiffness 1/c [N·m/rad] (None: not identified / rigid).
    pub stiffness_nm_per_rad: Vec<Option<f64>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tlbo: Option<TlboSummary>,
    /// The calibrated model in the registered base frame (mm/deg).
    pub model: ModelDescription,
    #[serde(skip)]
    pub calibrated: RobotModel,
}

/// Registration of each measurement session.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SessionRegistration {
    pub session: usize,
    /// Tracker → registered base frame (`x_base = R·x_tracker + t`).
    pub tracker_to_base: PoseDescription,
    /// RMS distance of the nominal model after the registration [mm].
    pub rms_mm: f64,
}

/// Nominal-model errors (before calibration) in the registered frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NominalErrors {
    pub identification: SetErrors,
    pub validation: Option<SetErrors>,
}

/// Everything a calibration found.
#[derive(Debug, Clone, Serialize)]
pub struct CalibrationReport {
    pub robot: String,
    pub identification_poses: usize,
    pub validation_poses: usize,
    pub registration: Vec<SessionRegistration>,
    pub identifiability: IdentifiabilityReport,
    pub nominal: NominalErrors,
    pub methods: BTreeMap<String, MethodReport>,
    /// Tracker → registered base frame of session 0.
    #[serde(skip)]
    pub tracker_to_base: Pose,
}

impl CalibrationReport {
    /// The best method by validation mean (identification mean without validation).
    pub fn best_method(&self) -> Option<&MethodReport> {
        self.methods.values().min_by(|a, b| {
            let key = |m: &MethodReport| {
                m.validation
                    .as_ref()
                    .map_or(m.identification.stats.mean_mm, |v| v.stats.mean_mm)
            };
            key(a).total_cmp(&key(b))
        })
    }
}

/// Converts an SI parameter value to display units.
pub fn to_display(id: &ParamId, v: f64) -> f64 {
    match id.unit() {
        ParamUnit::Length => v * 1e3,
        ParamUnit::Angle => v.to_degrees(),
        ParamUnit::Compliance => v,
    }
}

fn unit_name(id: &ParamId) -> &'static str {
    match id.unit() {
        ParamUnit::Length => "mm",
        ParamUnit::Angle => "deg",
        ParamUnit::Compliance => "rad/(N·m)",
    }
}

fn check_set(
    model: &RobotModel,
    data: &[Measurement],
    set: &'static str,
) -> Result<(), CalibrationError> {
    for (index, m) in data.iter().enumerate() {
        if m.q.len() != model.dof() {
            return Err(CalibrationError::JointCount {
                set,
                index,
                expected: model.dof(),
                got: m.q.len(),
            });
        }
        if m.q.iter().any(|x| !x.is_finite()) {
            return Err(CalibrationError::NotFinite {
                set,
                index,
                what: "a joint value",
            });
        }
        if m.position.iter().any(|x| !x.is_finite()) {
            return Err(CalibrationError::NotFinite {
                set,
                index,
                what: "the measured position",
            });
        }
        if !m.payload_mass.is_finite() || m.payload_mass < 0.0 {
            return Err(CalibrationError::NotFinite {
                set,
                index,
                what: "the payload mass",
            });
        }
        if let Some(r) = &m.orientation {
            if r.iter().any(|x| !x.is_finite()) {
                return Err(CalibrationError::NotFinite {
                    set,
                    index,
                    what: "the measured orientation",
                });
            }
        }
        fk(model, &m.q).map_err(|source| CalibrationError::Kinematics { set, index, source })?;
    }
    Ok(())
}

/// Stacked identification Jacobian of `ids` over `data` at `model` (positions only
/// or with orientation rows where measured).
fn stacked_jacobian(model: &RobotModel, ids: &[ParamId], data: &[Measurement]) -> DMatrix<f64> {
    let rows = least_squares::residual_rows(data);
    let mut j = DMatrix::zeros(rows, ids.len());
    let mut row = 0;
    for m in data {
        let c0 = chain(model, &m.q).expect("checked");
        let tau = gravity_torques_of(model, &c0, m.payload_mass);
        let orient = m.orientation.is_some();
        crate::kinematics::jacobian::fill_identification_rows(
            model, &c0, ids, &tau, orient, &mut j, row,
        );
        row += if orient { 6 } else { 3 };
    }
    j
}

/// Parameters that are fixed by design, with the reason.
fn fixed_params(model: &RobotModel) -> Vec<(ParamId, String)> {
    let mut v = Vec::new();
    if model.closed_loop.is_some() {
        v.push((
            ParamId::new(ParamKind::LoopL3, 0),
            "fixed: sets the closed loop's scale (seed §4.3)".to_string(),
        ));
    }
    v
}

/// Rank of the geometric identification Jacobian for well-spread random poses:
/// what a good pose set of this robot can identify.
fn generic_rank(model: &RobotModel, ids: &[ParamId], orientation: bool) -> usize {
    let mut rng = ChaCha8Rng::seed_from_u64(0x5eed);
    let mut data = Vec::new();
    let mut tries = 0;
    while data.len() < 60 && tries < 10_000 {
        tries += 1;
        let q: Vec<f64> = model
            .links
            .iter()
            .map(|l| rng.gen_range(l.limits[0].max(-3.1)..l.limits[1].min(3.1)))
            .collect();
        if fk(model, &q).is_ok() {
            data.push(Measurement {
                q,
                position: Vector3::zeros(),
                orientation: orientation.then(nalgebra::Matrix3::identity),
                payload_mass: model.payload.mass,
                session: 0,
            });
        }
    }
    let j = stacked_jacobian(model, ids, &data);
    let norms: Vec<f64> = j.column_iter().map(|c| c.norm()).collect();
    let max = norms.iter().cloned().fold(0.0, f64::max);
    let live: Vec<usize> = (0..ids.len()).filter(|&c| norms[c] > 1e-9 * max).collect();
    let mut js = DMatrix::zeros(j.nrows(), live.len());
    for (k, &c) in live.iter().enumerate() {
        js.set_column(k, &(j.column(c) / norms[c]));
    }
    let sv = js.svd(false, false).singular_values;
    let smax = sv.max();
    sv.iter().filter(|s| **s > smax * 1e-9).count()
}

fn joint_range_detail(model: &RobotModel, data: &[Measurement]) -> String {
    let mut still = Vec::new();
    for k in 0..model.dof() {
        let (lo, hi) = data
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), m| {
                (a.min(m.q[k]), b.max(m.q[k]))
            });
        if (hi - lo).to_degrees() < 5.0 {
            still.push(format!(
                "J{} moves only {:.2} deg",
                k + 1,
                (hi - lo).to_degrees()
            ));
        }
    }
    if still.is_empty() {
        String::new()
    } else {
        format!(" ({})", still.join(", "))
    }
}

fn estimates(
    nominal: &RobotModel,
    fitted: &RobotModel,
    ids: &[ParamId],
    cov: Option<&DMatrix<f64>>,
) -> Vec<ParamEstimate> {
    ids.iter()
        .enumerate()
        .map(|(i, id)| ParamEstimate {
            name: id.name(),
            unit: unit_name(id).into(),
            nominal: to_display(id, crate::model::params::get(nominal, *id)),
            value: to_display(id, crate::model::params::get(fitted, *id)),
            std: cov
                .filter(|c| i < c.nrows())
                .map(|c| to_display(id, c[(i, i)].max(0.0).sqrt())),
        })
        .collect()
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

    // Registration per session onto the nominal TCP positions.
    let sessions = identification.iter().map(|m| m.session).max().unwrap_or(0) + 1;
    let mut regs = vec![Pose::identity(); sessions];
    let mut reg_reports = Vec::new();
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
            reg_reports.push(SessionRegistration {
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
    let ident = to_base(identification);
    let valid = to_base(validation);
    let id_frames = vec![Pose::identity(); sessions];

    let nominal_errors = NominalErrors {
        identification: SetErrors::new(least_squares::position_errors_mm(
            nominal, &id_frames, &ident,
        )),
        validation: (!valid.is_empty()).then(|| {
            SetErrors::new(least_squares::position_errors_mm(
                nominal, &id_frames, &valid,
            ))
        }),
    };
    let nominal_rms = nominal_errors.identification.stats.rms_mm;
    if nominal_rms > opts.max_nominal_rms_mm {
        return Err(CalibrationError::Inconsistent {
            rms_mm: nominal_rms,
            limit_mm: opts.max_nominal_rms_mm,
        });
    }

    // Identifiability on geometric + compliance candidates.
    say("identifiability", 0, 5.0, None)?;
    let fixed = fixed_params(nominal);
    let geometric: Vec<ParamId> = ParamLayout::geometric(nominal)
        .ids
        .into_iter()
        .filter(|id| !fixed.iter().any(|(f, _)| f == id))
        .collect();
    let with_compliance = opts.methods.iter().any(|m| *m != Method::Km);
    let mut candidates = geometric.clone();
    if with_compliance {
        candidates.extend((0..nominal.dof()).map(|k| ParamId::new(ParamKind::Compliance, k)));
    }
    let j = stacked_jacobian(nominal, &candidates, &ident);
    let analysis = identifiability::analyse(
        nominal,
        &j,
        &candidates,
        &fixed,
        ident.len(),
        &opts.identifiability,
    );
    let kept_geo: Vec<ParamId> = analysis
        .kept
        .iter()
        .copied()
        .filter(|i| i.is_geometric())
        .collect();
    let kept_c: Vec<ParamId> = analysis
        .kept
        .iter()
        .copied()
        .filter(|i| !i.is_geometric())
        .collect();
    let any_orientation = ident.iter().any(|m| m.orientation.is_some());
    let gen_rank = generic_rank(nominal, &geometric, any_orientation);
    let rows = j.nrows();
    if kept_geo.len() < gen_rank {
        let per_pose = if any_orientation { 6 } else { 3 };
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
            detail: joint_range_detail(nominal, &ident),
        });
    }
    let n_unknowns = kept_geo.len() + kept_c.len() + (sessions - 1) * 6;
    if rows <= n_unknowns {
        let per_pose = if any_orientation { 6 } else { 3 };
        return Err(CalibrationError::TooFewPoses {
            poses: ident.len(),
            rows,
            params: n_unknowns,
            needed: n_unknowns / per_pose + 1,
        });
    }
    let mut ident_report = analysis.report;

    // Method runs.
    let weights: Vec<f64> = opts
        .methods
        .iter()
        .map(|m| if *m == Method::SkcmTlbo { 8.0 } else { 1.0 })
        .collect();
    let total: f64 = weights.iter().sum();
    let mut done = 0.0;
    let mut methods = BTreeMap::new();
    let mut km_fit: Option<least_squares::Fit> = None;
    let mut start_nominal = nominal.clone();
    for l in start_nominal.links.iter_mut() {
        l.compliance = 0.0;
    }
    for (mi, method) in opts.methods.iter().enumerate() {
        let span = 90.0 * weights[mi] / total;
        let base_pct = 10.0 + 90.0 * done / total;
        let name = method.name();
        let mut lm_progress = |it: usize, rms: f64| {
            progress(&Progress {
                phase: name.to_string(),
                iteration: it,
                percent: base_pct + span * (it as f64 / opts.lm.max_iterations as f64).min(1.0),
                rms_mm: Some(rms),
            })
        };
        let (fitted, ids, tlbo_summary) = match method {
            Method::Km => {
                let f = fit(
                    &start_nominal,
                    &kept_geo,
                    &ident,
                    sessions,
                    &opts.lm,
                    &mut lm_progress,
                )
                .map_err(|Cancelled| CalibrationError::Cancelled)?;
                km_fit = Some(f.clone());
                (f, kept_geo.clone(), None)
            }
            Method::Skcm => {
                let ids: Vec<ParamId> = kept_geo.iter().chain(&kept_c).copied().collect();
                let f = fit(
                    &start_nominal,
                    &ids,
                    &ident,
                    sessions,
                    &opts.lm,
                    &mut lm_progress,
                )
                .map_err(|Cancelled| CalibrationError::Cancelled)?;
                (f, ids, None)
            }
            Method::SkcmTlbo => {
                let warm = match &km_fit {
                    Some(f) => f.clone(),
                    None => fit(
                        &start_nominal,
                        &kept_geo,
                        &ident,
                        sessions,
                        &opts.lm,
                        &mut |_, _| true,
                    )
                    .map_err(|Cancelled| CalibrationError::Cancelled)?,
                };
                let (f, summary) = skcm_tlbo(
                    &warm,
                    &kept_geo,
                    &kept_c,
                    &ident,
                    sessions,
                    opts,
                    &mut |gen, best| {
                        progress(&Progress {
                            phase: name.to_string(),
                            iteration: gen,
                            percent: base_pct
                                + span * (gen as f64 + 1.0) / opts.tlbo.generations.max(1) as f64,
                            rms_mm: Some(best.sqrt()),
                        })
                    },
                )?;
                let ids: Vec<ParamId> = kept_geo.iter().chain(&kept_c).copied().collect();
                (f, ids, Some(summary))
            }
        };
        done += weights[mi];
        let id_err =
            least_squares::position_errors_mm(&fitted.model, &fitted.session_frames, &ident);
        let va_err = (!valid.is_empty()).then(|| {
            SetErrors::new(least_squares::position_errors_mm(
                &fitted.model,
                &fitted.session_frames,
                &valid,
            ))
        });
        if *method == Method::Skcm
            || (*method == Method::Km && !opts.methods.contains(&Method::Skcm))
        {
            if let Some(cov) = &fitted.covariance {
                let (sd, pairs) = identifiability::uncertainty(
                    &ids,
                    cov,
                    opts.identifiability.correlation_threshold,
                );
                ident_report.std_devs = sd;
                ident_report.correlated_pairs = pairs;
            }
        }
        let stiffness = fitted
            .model
            .links
            .iter()
            .enumerate()
            .map(|(k, l)| {
                let identified = ids.contains(&ParamId::new(ParamKind::Compliance, k));
                (identified && l.compliance > 0.0).then(|| 1.0 / l.compliance)
            })
            .collect();
        methods.insert(
            name.to_string(),
            MethodReport {
                method: *method,
                solver: fitted.report.clone(),
                identification: SetErrors::new(id_err),
                validation: va_err,
                parameters: estimates(nominal, &fitted.model, &ids, fitted.covariance.as_ref()),
                stiffness_nm_per_rad: stiffness,
                tlbo: tlbo_summary,
                model: ModelDescription::from_model(&fitted.model),
                calibrated: fitted.model.clone(),
            },
        );
        say(name, 0, 10.0 + 90.0 * done / total, None)?;
    }
    Ok(CalibrationReport {
        robot: nominal.name.clone(),
        identification_poses: identification.len(),
        validation_poses: validation.len(),
        registration: reg_reports,
        identifiability: ident_report,
        nominal: nominal_errors,
        methods,
        tracker_to_base: regs[0],
    })
}

/// SKCM-C by TLBO (ch. 7): returns the final fit at the best compliance.
fn skcm_tlbo(
    warm: &least_squares::Fit,
    kept_geo: &[ParamId],
    kept_c: &[ParamId],
    ident: &[Measurement],
    sessions: usize,
    opts: &CalibrationOptions,
    progress: &mut dyn FnMut(usize, f64) -> bool,
) -> Result<(least_squares::Fit, TlboSummary), CalibrationError> {
    // Search box: compliance up to the deflection limit at the largest torque.
    let mut max_tau = vec![0.0_f64; kept_c.len()];
    for m in ident {
        let c0 = chain(&warm.model, &m.q).expect("checked");
        let tau = gravity_torques_of(&warm.model, &c0, m.payload_mass);
        for (i, id) in kept_c.iter().enumerate() {
            max_tau[i] = max_tau[i].max(tau[id.link].abs());
        }
    }
    let hi: Vec<f64> = max_tau
        .iter()
        .map(|t| opts.tlbo_max_deflection_rad / t.max(1e-9))
        .collect();
    let lo = vec![0.0; kept_c.len()];
    // Inner KM (eq. 7.8) by a frozen-Jacobian solver, re-factorised at the best
    // geometry after every generation, warm-started from the best geometry.
    let with_c = |c: &[f64], start: &RobotModel| {
        let mut m = start.clone();
        for (id, v) in kept_c.iter().zip(c) {
            m.links[id.link].compliance = *v;
        }
        m
    };
    let frozen = |m: &RobotModel| {
        least_squares::FrozenSolver::new(m, &warm.session_frames, kept_geo, ident, &opts.lm)
    };
    let best = std::cell::RefCell::new((warm.model.clone(), f64::INFINITY));
    let solver = std::cell::RefCell::new(frozen(&warm.model));
    let mut cost = |c: &[f64]| -> f64 {
        let start = with_c(c, &best.borrow().0);
        let solved = solver
            .borrow()
            .as_ref()
            .and_then(|s| s.solve(&start, ident, &opts.lm, 10, 1e-10));
        match solved {
            Some((model, e)) => {
                let cost = tlbo_cost(&e);
                let mut b = best.borrow_mut();
                if cost < b.1 {
                    *b = (model, cost);
                }
                cost
            }
            None => f64::INFINITY,
        }
    };
    let mut rng = ChaCha8Rng::seed_from_u64(opts.tlbo.seed);
    let mut cancelled = false;
    let result = tlbo::minimise(&mut cost, &lo, &hi, &opts.tlbo, &mut rng, &mut |g, b| {
        let refreshed = frozen(&best.borrow().0);
        if refreshed.is_some() {
            *solver.borrow_mut() = refreshed;
        }
        let go = progress(g, b);
        cancelled |= !go;
        go
    });
    if cancelled {
        return Err(CalibrationError::Cancelled);
    }
    let start = with_c(&result.best, &best.borrow().0);
    let f = fit(&start, kept_geo, ident, sessions, &opts.lm, &mut |_, _| {
        true
    })
    .map_err(|Cancelled| CalibrationError::Cancelled)?;
    Ok((
        f,
        TlboSummary {
            population: opts.tlbo.population,
            generations: result.history.len(),
            evaluations: result.evaluations,
            history: result.history,
        },
    ))
}
