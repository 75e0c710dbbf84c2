//! Checks before and around a calibration: input sanity per measurement, the
//! parameters fixed by design, the rank a good pose set of this robot reaches
//! (to tell "too few / too similar poses" from a dependent parameter), and
//! whether gravity loads the joints at all (compliance methods need link
//! masses or a payload).
//!
//! Units: SI (m, rad, kg, N·m).

use super::least_squares;
use super::methods::MethodFailure;
use super::registration::RegistrationError;
use super::report::FailedMethod;
use crate::measure::Measurement;
use crate::model::kinematics::chain::{chain_with, ChainConstants};
use crate::model::kinematics::{chain, fk, gravity_torques_of, Chain, KinematicsError};
use crate::model::{ParamId, ParamKind, RobotModel};
use nalgebra::{DMatrix, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Why a calibration cannot run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CalibrationError {
    /// No identification pose was given.
    #[error("the identification set is empty")]
    NoData,
    /// A measurement has not one joint value per joint of the robot.
    #[error(
        "{set} measurement {index}: expected {expected} joint values for this robot, got {got}"
    )]
    JointCount {
        /// The set it belongs to: `identification`, `training` or `validation`.
        set: &'static str,
        /// Its 0-based place in the set.
        index: usize,
        /// Joints of the robot.
        expected: usize,
        /// Joint values given.
        got: usize,
    },
    /// A measurement's joints, position, payload mass or orientation is not a finite number, or
    /// its payload mass is negative.
    #[error("{set} measurement {index}: {what} is not a finite number")]
    NotFinite {
        /// The set it belongs to: `identification`, `training` or `validation`.
        set: &'static str,
        /// Its 0-based place in the set.
        index: usize,
        /// Which value, in words.
        what: &'static str,
    },
    /// The poses give no more equations than there are parameters to identify.
    #[error("too few poses: {poses} poses give {rows} equations, but this robot has {params} identifiable parameters; measure at least {needed} poses (3 to 5 times that is better)")]
    TooFewPoses {
        /// Identification poses given.
        poses: usize,
        /// Rows of the stacked identification Jacobian they give.
        rows: usize,
        /// Parameters (and session frames' terms) to identify.
        params: usize,
        /// The smallest number of poses that gives more rows than that.
        needed: usize,
    },
    /// The poses identify fewer of the geometric parameters than well-spread poses of this robot
    /// would.
    #[error("singular pose set: the poses excite only {rank} of the robot's {generic_rank} identifiable parameter combinations{detail}; measure poses that move every joint across its range")]
    SingularPoses {
        /// Geometric parameters the poses identify (exact rank).
        rank: usize,
        /// Geometric parameters well-spread random poses identify (`generic_rank`).
        generic_rank: usize,
        /// The joints that move less than 5 deg over the poses, in words (empty when none).
        detail: String,
    },
    /// A session's tracker frame cannot be registered.
    #[error("registration of session {session}: {source}")]
    Registration {
        /// The 0-based tracker session.
        session: usize,
        /// Why its registration failed.
        source: RegistrationError,
    },
    /// The nominal model's RMS error after registration is above `max_nominal_rms_mm`.
    #[error("the measurements do not fit the model: RMS {rms_mm:.1} mm after registering the tracker frame (limit {limit_mm:.0} mm); check units (positions in mm, joints in degrees), joint order and signs, and the model")]
    Inconsistent {
        /// RMS error of the nominal model after registration [mm].
        rms_mm: f64,
        /// The limit, `max_nominal_rms_mm` [mm].
        limit_mm: f64,
    },
    /// The nominal model's kinematics failed at a measurement's joints.
    #[error("{set} measurement {index}: {source}")]
    Kinematics {
        /// The set it belongs to: `identification`, `training` or `validation`.
        set: &'static str,
        /// Its 0-based place in the set.
        index: usize,
        /// Why the kinematics failed.
        source: KinematicsError,
    },
    /// A training pose's tracker session has no identification pose to register its frame.
    #[error("{set} measurement {index}: its tracker session has no identification poses, so its frame cannot be registered; measure identification poses in that session too")]
    UnregisteredSession {
        /// The set it belongs to (`training`).
        set: &'static str,
        /// Its 0-based place in the set.
        index: usize,
        /// The 0-based tracker session without identification poses.
        session: usize,
    },
    /// Some fitted poses carry standard deviations and others do not.
    #[error("{with} of the {total} identification and training poses carry standard deviations (std_x, std_y, std_z) and the others do not; the fit weighs rows by them, so give them for every fitted set or for none")]
    MixedStd {
        /// Identification and training poses with standard deviations.
        with: usize,
        /// Identification and training poses in all.
        total: usize,
    },
    /// The progress callback asked to stop.
    #[error("calibration cancelled")]
    Cancelled,
    /// The nominal model's positions, errors or Jacobian at the identification poses are not
    /// finite.
    #[error("the nominal model gives {what} at the identification poses, so nothing can be fitted; check the model's lengths, masses, compliances and tool")]
    ModelNotFinite {
        /// What is not finite, in words.
        what: &'static str,
    },
    /// Every method run failed.
    #[error("no method succeeded: {}", failed.iter().map(|f| format!("{}: {}", f.method.name(), f.reason)).collect::<Vec<_>>().join("; "))]
    AllMethodsFailed {
        /// Each method and why it failed.
        failed: Vec<FailedMethod>,
    },
}

pub(crate) fn check_set(
    model: &RobotModel,
    data: &[Measurement],
    set: &'static str,
) -> Result<(), CalibrationError> {
    for (index, m) in data.iter().enumerate() {
        check_inputs(model, m, set, index)?;
        fk(model, &m.q).map_err(|source| CalibrationError::Kinematics { set, index, source })?;
    }
    Ok(())
}

/// [`check_set`], keeping the forward kinematics of each measurement at its
/// commanded joints (`chain` is `fk` with every frame kept: the same numbers),
/// for the later phases that need them at `model`.
pub(crate) fn checked_chains(
    model: &RobotModel,
    data: &[Measurement],
    set: &'static str,
) -> Result<Vec<Chain>, CalibrationError> {
    let constants = ChainConstants::of(model);
    data.iter()
        .enumerate()
        .map(|(index, m)| {
            check_inputs(model, m, set, index)?;
            chain_with(model, &constants, &m.q).map_err(|source| CalibrationError::Kinematics {
                set,
                index,
                source,
            })
        })
        .collect()
}

/// The checks of one measurement before its forward kinematics.
fn check_inputs(
    model: &RobotModel,
    m: &Measurement,
    set: &'static str,
    index: usize,
) -> Result<(), CalibrationError> {
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
    Ok(())
}

/// Stacked identification Jacobian of `ids` over `data` at `model` (positions only
/// or with orientation rows where measured).
pub(crate) fn stacked_jacobian(
    model: &RobotModel,
    ids: &[ParamId],
    data: &[Measurement],
) -> DMatrix<f64> {
    stacked_jacobian_of(model, ids, data, None)
}

/// [`stacked_jacobian`] with the forward kinematics of `data` at `model` when
/// already computed (`chains[i]` of `data[i]` at its commanded joints).
fn stacked_jacobian_of(
    model: &RobotModel,
    ids: &[ParamId],
    data: &[Measurement],
    chains: Option<&[Chain]>,
) -> DMatrix<f64> {
    let rows = least_squares::residual_rows(data);
    let mut j = DMatrix::zeros(rows, ids.len());
    // Only compliance columns use the torques.
    let needs_tau = ids.iter().any(|i| i.kind == ParamKind::Compliance);
    let mut row = 0;
    for (i, m) in data.iter().enumerate() {
        let owned;
        let c0 = match chains {
            Some(c) => &c[i],
            None => {
                owned = chain(model, &m.q).expect("checked");
                &owned
            }
        };
        let tau = if needs_tau {
            gravity_torques_of(model, c0, m.payload_mass)
        } else {
            Vec::new()
        };
        let orient = m.orientation.is_some();
        crate::model::kinematics::jacobian::fill_identification_rows(
            model,
            c0,
            ids,
            &tau,
            m.payload_mass,
            orient,
            &mut j,
            row,
        );
        row += if orient { 6 } else { 3 };
    }
    j
}

/// Poses per block of [`stacked_factor`]: a block's rows and the factor so far
/// (some 200 KB for 34 candidate columns) stay in cache while the block is
/// reduced (1000 poses per block measured slower, 100 a little slower).
const FACTOR_BLOCK_POSES: usize = 250;

/// The triangular factor R of the stacked identification Jacobian J of
/// [`stacked_jacobian`] (`RᵀR = JᵀJ`, at most `ids.len()` rows, see
/// `identifiability::triangular_factor`) and J's row count, built block by
/// block: R of `[R_so_far; next block of rows]` is R of all rows so far
/// (`[R; B] = diag(Q, I)·[Q_so_farᵀ·J_so_far; B]`). J itself (thousands of
/// rows) is never formed. `chains`: the forward kinematics of `data` at
/// `model` when already computed (as in [`stacked_jacobian_of`]).
pub(crate) fn stacked_factor(
    model: &RobotModel,
    ids: &[ParamId],
    data: &[Measurement],
    chains: Option<&[Chain]>,
) -> (DMatrix<f64>, usize) {
    let n = ids.len();
    let mut r = DMatrix::zeros(0, n);
    let mut rows = 0;
    for (k, block) in data.chunks(FACTOR_BLOCK_POSES).enumerate() {
        let from = k * FACTOR_BLOCK_POSES;
        let b = stacked_jacobian_of(
            model,
            ids,
            block,
            chains.map(|c| &c[from..from + block.len()]),
        );
        rows += b.nrows();
        let mut s = DMatrix::zeros(r.nrows() + b.nrows(), n);
        s.rows_mut(0, r.nrows()).copy_from(&r);
        s.rows_mut(r.nrows(), b.nrows()).copy_from(&b);
        r = super::identifiability::triangular_factor(s);
    }
    (r, rows)
}

/// Parameters that are fixed by design, with the reason.
pub(crate) fn fixed_params(model: &RobotModel) -> Vec<(ParamId, String)> {
    let mut v = Vec::new();
    if model.closed_loop.is_some() {
        v.push((
            ParamId::new(ParamKind::LoopL3, 0),
            "fixed: sets the closed loop's scale (thesis §4.3)".to_string(),
        ));
    }
    v
}

/// Rank of the geometric identification Jacobian for well-spread random poses:
/// what a good pose set of this robot can identify.
pub(crate) fn generic_rank(model: &RobotModel, ids: &[ParamId], orientation: bool) -> usize {
    let mut rng = ChaCha8Rng::seed_from_u64(0x5eed);
    let mut data = Vec::new();
    let mut tries = 0;
    while data.len() < 60 && tries < 10_000 {
        tries += 1;
        let q: Vec<f64> = model
            .links
            .iter()
            .map(|l| {
                let (a, b) = (l.limits[0].max(-3.1), l.limits[1].min(3.1));
                if a < b {
                    rng.gen_range(a..b)
                } else {
                    // A range wholly beyond ±3.1 rad (multi-turn limits):
                    // its first 6.2 rad.
                    let (lo, hi) = (l.limits[0], l.limits[1]);
                    lo + (hi - lo).min(6.2) * rng.gen::<f64>()
                }
            })
            .collect();
        if fk(model, &q).is_ok() {
            data.push(Measurement {
                q,
                position: Vector3::zeros(),
                orientation: orientation.then(nalgebra::Matrix3::identity),
                payload_mass: model.payload.mass,
                session: 0,
                std: None,
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
    let sv = super::identifiability::singular_values(super::identifiability::triangular_factor(js));
    let smax = sv.max();
    sv.iter().filter(|s| **s > smax * 1e-9).count()
}

pub(crate) fn joint_range_detail(model: &RobotModel, data: &[Measurement]) -> String {
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

/// Why the compliance methods cannot run on this model and data, if they cannot:
/// with no link mass and no payload, gravity puts no torque on any joint.
pub(crate) fn gravity_problem(model: &RobotModel, data: &[Measurement]) -> Option<MethodFailure> {
    let link_mass: f64 = model.links.iter().map(|l| l.mass).sum();
    let payload = data.iter().any(|m| m.payload_mass > 0.0);
    (link_mass <= 0.0 && !payload).then_some(MethodFailure::NoGravityTorque)
}

/// Why `skcm-payload` cannot identify the payload's centre of mass, if it cannot.
pub(crate) fn payload_problem(data: &[Measurement]) -> Option<MethodFailure> {
    (!data.iter().any(|m| m.payload_mass > 0.0)).then_some(MethodFailure::NoPayload)
}
