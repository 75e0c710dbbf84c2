//! Fitting the per-joint angle error maps (beyond the thesis; docs/design.md
//! "Joint angle error maps"): `Δθ_i = f_i(q_i)`, a Fourier series per joint
//! (`model::joint_maps`), identified jointly with the linearised geometry.
//!
//! At a calibrated model φ (no maps), the residual of pose p (measured −
//! predicted, registered base frame of its session, m) is linear in the map
//! coefficients through joint i's column `J_θi(q)` of the identification
//! Jacobian (the column of the θ_i offset, eq. 4.9):
//! `r ≈ J_φ·Δφ + Σ_i J_θi(q)·Σ_k (a_ik·cos(k·q_i) + b_ik·sin(k·q_i))`.
//! The stacked problem is solved by ridge regression: λ times the mean
//! squared norm of the map columns on every map coefficient (one penalty in
//! radians for all joints), the geometry and session-frame columns free
//! (1e-9 on unit-norm columns, for conditioning). The number of harmonics K and λ are chosen
//! by k-fold cross-validation over the poses: the lowest cost of the
//! thesis's eq. 7.10 (mean, max and spread of the squared position errors)
//! on the held-out poses; K = 0 (geometry only) is always a candidate, so
//! maps are kept only when they help on poses they never saw. The folds are
//! dealt by the poses themselves (a hash of each pose's joints, point and
//! session; `folds`), not by a seed: candidates within the folds' scatter of
//! each other (the real UR5's `skcm-maps`, 60 harmonics at ridge 0.1 or
//! 0.01) were otherwise decided by the seed, the same data giving other maps
//! on another seed.
//! Each joint's map covers the range of its training angles and fades to
//! zero beyond it; a joint that moves less than `min_range_rad` gets none.
//!
//! Observability: a map is fitted only where the measurements see its effect.
//! With position-only data a joint's angle is seen through the position
//! rows of its column `J_θi` alone, whose norm is the lever arm from joint
//! i's axis to the measured point [m/rad]; its RMS over the poses is
//! `L_i = √(mean_p ‖J_pos,θi(q_p)‖²)`. One pose measured with a position
//! noise σ per coordinate resolves an angle of joint i no finer than
//! `α_i = σ / L_i` [rad]: an angle error of that size moves the measured
//! point by one σ, no more than the noise. It turns a production tool whose
//! tip is `ℓ` from the measured point by `ℓ·α_i` at the tip, unseen. The
//! joint's map is refused (not fitted) when
//!
//! - `ℓ·α_i > max(max_unseen_tip_m, noise_ratio·σ)`
//!   ([`MapRefusal::AngleNotResolved`]; `ℓ` = `production_tool_m`, 250 mm,
//!   `max_unseen_tip_m` 0.5 mm, `noise_ratio` 2): the tip would go wrong by
//!   more than 0.5 mm unseen **and** by more than twice what the noise
//!   leaves at the measured point (`ℓ / L_i > 2`; data whose noise is already
//!   millimetres, where the geometry leaves that much, are not held to a
//!   finer bound at the tip than at the measured point), or else
//! - `L_i < min_lever_m` (20 mm), a floor whatever the noise
//!   ([`MapRefusal::LeverBelowFloor`]): the data's noise estimate may be
//!   optimistic, and a joint seen through so short a lever is not mapped.
//!
//! σ is the RMS of the rows' position standard deviations where the data
//! gives them (`std_x..z`), else the RMS per coordinate of the position
//! residual the calibrated geometry leaves on the poses (over rows minus
//! fitted columns): an upper bound of the noise, since it also holds what the
//! maps are to explain, so the rule errs towards refusing. Joint 6 seen from a
//! reflector 0.3 mm from its axis with σ = 0.01 mm resolves 33 mrad (1.9°):
//! 8 mm unseen at a 250 mm tip. [`MapFit::refused`] says which rule and its
//! figures. Any measured orientation sees every joint's angle directly
//! (`‖J_rot,θi‖ = 1`), so with orientation rows no map is refused on this
//! ground.

mod blocked;
mod design;
mod folds;
mod refusal;

pub use blocked::BlockedMaps;
pub use refusal::{MapRefusal, RefusedMap};

use super::evaluate::{evaluate, gram_checked};
use crate::calibrate::compensate::select::Parallelism;
use crate::measure::Measurement;
use crate::model::{JointMap, JointMaps, ParamId, ParamKind, Pose, RobotModel};
use design::{normal_of, solve, Design};
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// Settings of the joint-map fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct JointMapSettings {
    /// Candidate numbers of harmonics K per joint (0, geometry only, is
    /// always tried).
    pub harmonics: Vec<usize>,
    /// Candidate ridge weights λ on the unit-norm map columns.
    pub ridge: Vec<f64>,
    /// Cross-validation folds.
    pub folds: usize,
    /// At least this many residual rows per unknown, else a K is skipped.
    pub rows_per_unknown: f64,
    /// Width of the fade to zero beyond a joint's trained range [rad].
    pub fade_rad: f64,
    /// A joint whose training angles span less than this gets no map [rad].
    pub min_range_rad: f64,
    /// Rounds of (map fit, LM refit of the geometry with the maps fixed).
    pub rounds: usize,
    /// With position-only data, a joint whose RMS lever arm to the measured
    /// point is below this gets no map, whatever the noise (module docs) [m].
    pub min_lever_m: f64,
    /// Distance of a production tool's tip from the measured point the
    /// observability rule guards (`ℓ`, module docs) [m].
    pub production_tool_m: f64,
    /// With position-only data, a joint whose angle one pose resolves
    /// (σ / L_i) would move that tip by more than this unseen gets no map
    /// (module docs) [m] …
    pub max_unseen_tip_m: f64,
    /// … and by more than this many times the position noise σ.
    pub noise_ratio: f64,
    /// Spatially blocked folds the chosen maps are also judged on (whole
    /// regions of joint space held out, `blocked`); fewer than 2 skips them.
    pub blocked_folds: usize,
    /// Threads a candidate's cross-validation folds are fitted on; results
    /// do not depend on it. Set by the caller, not by a request.
    #[serde(skip)]
    pub parallel: Parallelism,
}

impl Default for JointMapSettings {
    fn default() -> Self {
        JointMapSettings {
            harmonics: vec![10, 20, 40, 60, 80],
            ridge: vec![1e-4, 1e-3, 1e-2, 1e-1, 1.0, 10.0],
            folds: 5,
            rows_per_unknown: 4.0,
            fade_rad: 5f64.to_radians(),
            min_range_rad: 10f64.to_radians(),
            rounds: 2,
            min_lever_m: 0.02,
            production_tool_m: 0.25,
            max_unseen_tip_m: 0.5e-3,
            noise_ratio: 2.0,
            blocked_folds: 4,
            parallel: Parallelism::default(),
        }
    }
}

/// One (K, λ) the cross-validation tried.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MapCandidate {
    /// Harmonics per joint K (0: geometry alone).
    pub harmonics: usize,
    /// Ridge weight λ, relative to the mean squared norm of the map columns (module docs).
    pub ridge: f64,
    /// Mean / max held-out position error over all poses [mm].
    pub cv_mean_mm: f64,
    /// Largest held-out position error over all poses [mm].
    pub cv_max_mm: f64,
    /// The thesis's eq. 7.10 on the held-out errors,
    /// `mean(e²) + 0.5·max(e²) + 0.3·std(e²)` [mm²]: the choice's criterion.
    pub cv_cost_mm2: f64,
    /// Mean held-out orientation error over the poses that measured one
    /// (the linearised rotation residual's angle) [deg]; none without.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cv_orientation_mean_deg: Option<f64>,
}

/// How the maps' structure, the number of harmonics K and the ridge λ, is
/// set: a closed set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MapStructure {
    /// By cross-validation over the settings' harmonics and ridges, K = 0
    /// competing (module docs).
    CrossValidated,
    /// Held at a structure chosen before, on other poses: the maps are
    /// fitted with that K and λ whatever the folds say, so the fit depends on
    /// the poses alone, not on how folds were dealt. K is lowered to the
    /// largest of the settings' harmonics the poses afford
    /// (`rows_per_unknown`), 0 when none. The folds still cross-validate it
    /// and K = 0, for the report.
    Fixed(MapOrder),
}

/// A structure of the maps: harmonics per joint and ridge weight.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapOrder {
    /// Harmonics per joint K.
    pub harmonics: usize,
    /// Ridge weight λ, relative to the mean squared norm of the map columns (module docs).
    pub ridge: f64,
}

/// Eq. 7.10 of errors [mm]: `mean(e²) + 0.5·max(e²) + 0.3·std(e²)` [mm²].
fn seed_cost(errors: &[f64]) -> f64 {
    let sq: Vec<f64> = errors.iter().map(|e| e * e).collect();
    let n = sq.len().max(1) as f64;
    let mean = sq.iter().sum::<f64>() / n;
    let max = sq.iter().copied().fold(0.0, f64::max);
    let std = (sq.iter().map(|s| (s - mean).powi(2)).sum::<f64>() / n).sqrt();
    mean + 0.5 * max + 0.3 * std
}

/// The maps fitted and how they were chosen.
#[derive(Debug, Clone, PartialEq)]
pub struct MapFit {
    /// `None` when K = 0 (geometry alone) won the cross-validation.
    pub maps: Option<JointMaps>,
    /// The (K, λ) fitted, with its cross-validated errors.
    pub chosen: MapCandidate,
    /// Geometry alone (K = 0), on the same folds.
    pub without_maps: MapCandidate,
    /// Every (K, λ) the cross-validation tried, K = 0 included.
    pub candidates: Vec<MapCandidate>,
    /// Poses the maps were fitted on.
    pub poses: usize,
    /// Joints whose map the measurements cannot see, not fitted.
    pub refused: Vec<RefusedMap>,
    /// The chosen maps and the geometry alone on the spatially blocked
    /// folds (none when they were not run).
    pub blocked: Option<BlockedMaps>,
}

/// The position noise σ per coordinate of position-only `data` [m] (module
/// docs): the RMS of the rows' standard deviations where given, else the RMS
/// of the geometry's position residual `r` over `rows − fitted` degrees of
/// freedom.
fn position_noise(r: &DVector<f64>, fitted: usize, data: &[Measurement]) -> f64 {
    let given: Vec<f64> = data
        .iter()
        .filter_map(|m| m.std.map(|s| s.position))
        .collect();
    if !given.is_empty() {
        return (given.iter().map(|s| s * s).sum::<f64>() / given.len() as f64).sqrt();
    }
    let dof = r.len().saturating_sub(fitted).max(1);
    (r.norm_squared() / dof as f64).sqrt()
}

/// The refusal of a joint seen through the RMS lever `lever` [m] with the
/// noise `noise` [m], `None` when its map may be fitted (module docs).
fn refusal(
    joint: usize,
    lever: f64,
    noise: f64,
    settings: &JointMapSettings,
) -> Option<RefusedMap> {
    let resolved = if lever > 0.0 {
        (noise / lever).min(std::f64::consts::PI)
    } else {
        std::f64::consts::PI
    };
    let tip = settings.production_tool_m * resolved;
    let bound = settings.max_unseen_tip_m.max(settings.noise_ratio * noise);
    let kind = if tip > bound {
        MapRefusal::AngleNotResolved
    } else if lever < settings.min_lever_m {
        MapRefusal::LeverBelowFloor
    } else {
        return None;
    };
    let (lever_mm, noise_mm, tool_mm) =
        (lever * 1e3, noise * 1e3, settings.production_tool_m * 1e3);
    let reason = match kind {
        MapRefusal::AngleNotResolved => format!(
            "joint {joint}'s angle moves the measured point by {lever_mm:.2} mm per radian (RMS over the poses) and no pose measured an orientation: with {noise_mm:.4} mm of position noise one pose resolves its angle only to {:.4}°, which would turn the tip of a production tool {tool_mm:.0} mm from the measured point by {:.3} mm unseen (more than {:.3} mm), so no map is fitted",
            resolved.to_degrees(),
            tip * 1e3,
            bound * 1e3
        ),
        MapRefusal::LeverBelowFloor => format!(
            "joint {joint}'s angle moves the measured point by only {lever_mm:.2} mm per radian (RMS over the poses, below the floor of {:.0} mm/rad) and no pose measured an orientation: a map of it would be nearly invisible to the measurements yet turn a production tool, so none is fitted",
            settings.min_lever_m * 1e3
        ),
    };
    Some(RefusedMap {
        joint,
        kind,
        lever_mm,
        min_lever_mm: settings.min_lever_m * 1e3,
        noise_mm,
        resolved_deg: resolved.to_degrees(),
        production_tool_mm: tool_mm,
        unseen_tip_mm: tip * 1e3,
        max_unseen_tip_mm: bound * 1e3,
        reason,
    })
}

/// RMS over the poses of the position rows' norm of each column of `jt`
/// (one column per joint angle, rows as `evaluate` stacks them) [m/rad];
/// `None` when some pose measured an orientation (every angle is then seen).
fn position_levers(jt: &DMatrix<f64>, data: &[Measurement]) -> Option<Vec<f64>> {
    if data.iter().any(|m| m.orientation.is_some()) || data.is_empty() {
        return None;
    }
    if data.iter().any(|m| m.std.is_some()) {
        // The rows of `jt` are weighted (`evaluate`): undo it pose by pose.
        let w = super::evaluate::row_weights(data, 1.0);
        return Some(
            (0..jt.ncols())
                .map(|i| {
                    let sum: f64 = (0..data.len())
                        .map(|p| (0..3).map(|k| jt[(3 * p + k, i)].powi(2)).sum::<f64>())
                        .zip(&w)
                        .map(|(s, (wp, _))| s / (wp * wp))
                        .sum();
                    (sum / data.len() as f64).sqrt()
                })
                .collect(),
        );
    }
    Some(
        (0..jt.ncols())
            .map(|i| (jt.column(i).norm_squared() / data.len() as f64).sqrt())
            .collect(),
    )
}

/// The joints (with their trained range) that get a map, and those refused
/// as unobservable (module docs), `noise` the position noise σ [m].
fn map_joints(
    jt: &DMatrix<f64>,
    joints_n: usize,
    data: &[Measurement],
    noise: f64,
    settings: &JointMapSettings,
) -> (Vec<(usize, [f64; 2])>, Vec<RefusedMap>) {
    let levers = position_levers(jt, data);
    let (mut joints, mut refused) = (Vec::new(), Vec::new());
    // `jt`'s first `joints_n` columns are the joint angles; the session
    // frames beyond the first add columns of their own after them.
    for i in 0..joints_n.min(jt.ncols()) {
        let lo = data.iter().map(|m| m.q[i]).fold(f64::INFINITY, f64::min);
        let hi = data
            .iter()
            .map(|m| m.q[i])
            .fold(f64::NEG_INFINITY, f64::max);
        if hi - lo < settings.min_range_rad {
            continue;
        }
        match levers
            .as_ref()
            .and_then(|l| refusal(i + 1, l[i], noise, settings))
        {
            Some(r) => refused.push(r),
            None => joints.push((i, [lo, hi])),
        }
    }
    (joints, refused)
}

/// Why the maps cannot be fitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MapFitError {
    /// The model has a closed loop; maps need a serial chain.
    #[error("joint maps need a serial chain (this model has a closed loop)")]
    ClosedLoop,
    /// Fewer poses than four per cross-validation fold.
    #[error("joint maps need at least {need} poses, got {got}")]
    TooFewPoses {
        /// Poses needed: four per fold.
        need: usize,
        /// Poses given.
        got: usize,
    },
    /// The model cannot be evaluated at some training pose, or the fit's ridge system cannot be
    /// solved.
    #[error("the model cannot be evaluated at some training pose")]
    NotEvaluable,
    /// No joint moves over `min_range_rad` in the training poses.
    #[error("no joint moves over {min_deg:.1}° in the training poses")]
    NoJointMoves {
        /// The least range a mapped joint must cover, `min_range_rad` [deg].
        min_deg: f64,
    },
    /// Every joint that moves enough has its map refused as not observable.
    #[error("no joint map is observable: {refused}")]
    NoObservableJoint {
        /// Each refused joint's [`RefusedMap::reason`], `; `-separated.
        refused: String,
    },
}

/// Poses of the design filled between two checks of `go` in [`build`].
const BUILD_CHECK_POSES: usize = 1000;

/// The design matrix of the maps on `data` (module docs); `Ok(None)` as soon
/// as `go()` returns false (it is asked after the Jacobians and every
/// [`BUILD_CHECK_POSES`] poses).
#[allow(clippy::too_many_arguments)]
fn build(
    model: &RobotModel,
    frames: &[Pose],
    ids: &[ParamId],
    data: &[Measurement],
    weight: f64,
    kmax: usize,
    settings: &JointMapSettings,
    go: &mut dyn FnMut() -> bool,
) -> Result<Option<Design>, MapFitError> {
    let n = model.dof();
    let geo_eval =
        evaluate(model, frames, ids, data, weight, true).ok_or(MapFitError::NotEvaluable)?;
    let theta: Vec<ParamId> = (0..n).map(|k| ParamId::new(ParamKind::Theta, k)).collect();
    let theta_eval =
        evaluate(model, frames, &theta, data, weight, true).ok_or(MapFitError::NotEvaluable)?;
    let (jg, jt) = (geo_eval.j.expect("asked"), theta_eval.j.expect("asked"));
    if !go() {
        return Ok(None);
    }
    let noise = position_noise(&geo_eval.r, jg.ncols(), data);
    let (joints, refused) = map_joints(&jt, n, data, noise, settings);
    if joints.is_empty() && !refused.is_empty() {
        return Err(MapFitError::NoObservableJoint {
            refused: refused
                .iter()
                .map(|r| r.reason.as_str())
                .collect::<Vec<_>>()
                .join("; "),
        });
    }
    if joints.is_empty() {
        return Err(MapFitError::NoJointMoves {
            min_deg: settings.min_range_rad.to_degrees(),
        });
    }
    let geo = jg.ncols();
    let rows = jg.nrows();
    let mut a = DMatrix::zeros(rows, geo + joints.len() * 2 * kmax);
    a.columns_mut(0, geo).copy_from(&jg);
    let mut pose_rows = Vec::with_capacity(data.len());
    let mut row = 0;
    let mut basis = vec![0.0; 2 * kmax];
    let mut design = Design {
        r: geo_eval.r,
        a: DMatrix::zeros(0, 0),
        geo,
        pose_rows: Vec::new(),
        weights: super::evaluate::row_weights(data, weight),
        joints,
        refused,
        kmax,
    };
    for (p, m) in data.iter().enumerate() {
        if p % BUILD_CHECK_POSES == BUILD_CHECK_POSES - 1 && !go() {
            return Ok(None);
        }
        let nr = if m.orientation.is_some() { 6 } else { 3 };
        pose_rows.push((row, nr));
        for (slot, (i, _)) in design.joints.iter().enumerate() {
            JointMap::basis(kmax, m.q[*i], &mut basis);
            for h in 1..=kmax {
                let (c, s) = (basis[h - 1], basis[kmax + h - 1]);
                let (cc, cs) = (design.col(slot, h, false), design.col(slot, h, true));
                for rr in row..row + nr {
                    let t = jt[(rr, *i)];
                    a[(rr, cc)] = t * c;
                    a[(rr, cs)] = t * s;
                }
            }
        }
        row += nr;
    }
    design.a = a;
    design.pose_rows = pose_rows;
    Ok(Some(design))
}

/// Position error norms [mm] of the poses `poses` after subtracting `a·x`,
/// and their orientation errors [deg] (the norm of the unweighted rotation
/// residual; `None` for a pose without a measured orientation).
fn held_out_errors(
    d: &Design,
    poses: &[usize],
    cols: &[usize],
    x: &DVector<f64>,
) -> (Vec<f64>, Vec<Option<f64>>) {
    let left = |rr: usize| {
        let fit: f64 = cols
            .iter()
            .zip(x.iter())
            .map(|(c, x)| d.a[(rr, *c)] * x)
            .sum();
        d.r[rr] - fit
    };
    let norm = |rows: std::ops::Range<usize>| rows.map(|rr| left(rr).powi(2)).sum::<f64>().sqrt();
    poses
        .iter()
        .map(|&p| {
            let (row, nr) = d.pose_rows[p];
            let (wp, wr) = d.weights[p];
            let angle = (nr == 6 && wr > 0.0).then(|| (norm(row + 3..row + 6) / wr).to_degrees());
            (norm(row..row + 3) / wp * 1e3, angle)
        })
        .unzip()
}

/// The candidates `(K, λ)` of the cross-validation: K = 0 (no maps), then
/// every affordable harmonic count of the settings with every ridge.
fn candidate_grid(
    settings: &JointMapSettings,
    affordable: impl Fn(usize) -> bool,
) -> Vec<(usize, f64)> {
    let mut ks: Vec<usize> = settings
        .harmonics
        .iter()
        .copied()
        .filter(|k| *k > 0 && affordable(*k))
        .collect();
    ks.sort_unstable();
    ks.dedup();
    let mut grid: Vec<(usize, f64)> = vec![(0, 0.0)];
    for k in &ks {
        for l in &settings.ridge {
            grid.push((*k, *l));
        }
    }
    grid
}

/// The candidates of a structure held fixed at `order`: K = 0 and `order`
/// with K lowered to the largest affordable harmonic count of the settings
/// (`MapStructure::Fixed`); K = 0 alone when none is affordable.
fn fixed_grid(
    settings: &JointMapSettings,
    order: MapOrder,
    affordable: impl Fn(usize) -> bool,
) -> Vec<(usize, f64)> {
    let k = if order.harmonics > 0 && affordable(order.harmonics) {
        Some(order.harmonics)
    } else {
        settings
            .harmonics
            .iter()
            .copied()
            .filter(|k| *k > 0 && *k < order.harmonics && affordable(*k))
            .max()
    };
    std::iter::once((0, 0.0))
        .chain(k.map(|k| (k, order.ridge)))
        .collect()
}

/// The maps of `k` harmonics the solution `x` (over the columns `cols` of
/// the design) holds, for a robot of `n` joints.
fn maps_of(
    d: &Design,
    cols: &[usize],
    x: &DVector<f64>,
    k: usize,
    n: usize,
    fade_rad: f64,
) -> JointMaps {
    let mut joints: Vec<Option<JointMap>> = vec![None; n];
    for (slot, (i, range)) in d.joints.iter().enumerate() {
        let mut map = JointMap::zero(k, *range, fade_rad);
        for h in 1..=k {
            let at = |sine: bool| {
                let c = d.col(slot, h, sine);
                let pos = cols.iter().position(|x| *x == c).expect("in cols");
                x[pos]
            };
            map.cos[h - 1] = at(false);
            map.sin[h - 1] = at(true);
        }
        joints[*i] = Some(map);
    }
    JointMaps { joints }
}

/// The design's normal equations on all poses and, per fold, on the fold's
/// poses alone (subtracted to fit without them).
struct CrossValidation<'a> {
    d: &'a Design,
    g: &'a DMatrix<f64>,
    b: &'a DVector<f64>,
    /// Column scales of the solve (the Gram diagonal's square roots).
    scale: &'a [f64],
    fold_poses: Vec<Vec<usize>>,
    fold_normals: Vec<(DMatrix<f64>, DVector<f64>)>,
}

impl CrossValidation<'_> {
    /// The held-out errors of `k` harmonics with ridge `ridge`, each fold
    /// fitted without its poses, the folds on up to `threads` threads and
    /// gathered in fold order: `Some(None)` when a fold's solve fails, `None`
    /// when `go` (after each fold) cancels.
    /// Every `(K, λ)` of `grid` cross-validated in order, progress counted
    /// in candidates of `grid.len() + 1` (`None`: stopped).
    fn all(
        &self,
        grid: &[(usize, f64)],
        threads: usize,
        progress: &mut dyn FnMut(usize, usize) -> bool,
    ) -> Option<Vec<MapCandidate>> {
        let total = grid.len() + 1;
        let mut out = Vec::new();
        for (done, &(k, ridge)) in grid.iter().enumerate() {
            out.extend(self.candidate(k, ridge, threads, &mut || progress(done, total))?);
            if !progress(done + 1, total) {
                return None;
            }
        }
        Some(out)
    }

    fn candidate(
        &self,
        k: usize,
        ridge: f64,
        threads: usize,
        go: &mut dyn FnMut() -> bool,
    ) -> Option<Option<MapCandidate>> {
        let d = self.d;
        let cols = d.columns(k);
        let fit_fold = |f: usize| {
            let (gf, bf) = &self.fold_normals[f];
            let x = solve(
                &(self.g - gf),
                &(self.b - bf),
                &cols,
                self.scale,
                d.geo,
                ridge,
            )?;
            Some(held_out_errors(d, &self.fold_poses[f], &cols, &x))
        };
        let per_fold = in_order(self.fold_poses.len(), threads, fit_fold);
        let mut errors = Vec::new();
        let mut angles = Vec::new();
        let mut ok = true;
        for fold in per_fold {
            match fold {
                Some((e, a)) => {
                    errors.extend(e);
                    angles.extend(a.into_iter().flatten());
                }
                None => ok = false,
            }
            if !go() {
                return None;
            }
        }
        Some(ok.then(|| MapCandidate {
            harmonics: k,
            ridge,
            cv_mean_mm: errors.iter().sum::<f64>() / errors.len() as f64,
            cv_max_mm: errors.iter().copied().fold(0.0, f64::max),
            cv_cost_mm2: seed_cost(&errors),
            cv_orientation_mean_deg:
                (!angles.is_empty()).then(|| angles.iter().sum::<f64>() / angles.len() as f64),
        }))
    }
}

/// `f(0)`, …, `f(n − 1)` on up to `threads` scoped threads, in index order.
/// Each value is computed by one call alone, so it does not depend on the
/// threads.
fn in_order<T: Send>(n: usize, threads: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    let threads = threads.clamp(1, n.max(1));
    if threads == 1 {
        return (0..n).map(f).collect();
    }
    let f = &f;
    std::thread::scope(|scope| {
        let workers: Vec<_> = (0..threads)
            .map(|t| {
                scope.spawn(move || {
                    (t..n)
                        .step_by(threads)
                        .map(|i| (i, f(i)))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        let mut out: Vec<Option<T>> = (0..n).map(|_| None).collect();
        for w in workers {
            for (i, v) in w.join().expect("a fold's fit panicked") {
                out[i] = Some(v);
            }
        }
        out.into_iter()
            .map(|v| v.expect("every fold is fitted"))
            .collect()
    })
}

/// Fits the maps of `model` (its own maps ignored) on `data` with the session
/// frames `frames` and the identified parameters `ids`: K and λ by
/// cross-validation, then the coefficients on all poses. `progress(done,
/// total)` after each candidate's fold and between the steps of building the
/// design and its normal equations (`done` = candidates done); false cancels
/// (`Ok(None)`). The blocked folds are drawn from the poses
/// (`compensate::blocked_fold_assignment`). `structure`
/// says whether K and λ are chosen here or held ([`MapStructure`]).
#[allow(clippy::too_many_arguments)]
pub fn fit_joint_maps(
    model: &RobotModel,
    frames: &[Pose],
    ids: &[ParamId],
    data: &[Measurement],
    orientation_weight: f64,
    settings: &JointMapSettings,
    structure: MapStructure,
    progress: &mut dyn FnMut(usize, usize) -> bool,
) -> Result<Option<MapFit>, MapFitError> {
    if model.closed_loop.is_some() {
        return Err(MapFitError::ClosedLoop);
    }
    let folds = settings.folds.max(2);
    if data.len() < 4 * folds {
        let (need, got) = (4 * folds, data.len());
        return Err(MapFitError::TooFewPoses { need, got });
    }
    let mut plain = model.clone();
    plain.joint_maps = None;
    let rows = super::evaluate::residual_rows(data);
    let n = model.dof();
    let geo_cols = ids.len() + frames.len().saturating_sub(1) * 6;
    let affordable =
        |k: usize| ((geo_cols + 2 * k * n) as f64) * settings.rows_per_unknown <= rows as f64;
    let grid = match structure {
        MapStructure::CrossValidated => candidate_grid(settings, affordable),
        MapStructure::Fixed(order) => fixed_grid(settings, order, affordable),
    };
    let kmax = grid.iter().map(|c| c.0).max().unwrap_or(0);
    let total = grid.len() + 1;
    let mut go = || progress(0, total);
    let Some(d) = build(
        &plain,
        frames,
        ids,
        data,
        orientation_weight,
        kmax.max(1),
        settings,
        &mut go,
    )?
    else {
        return Ok(None);
    };
    let Some(g) = gram_checked(&d.a, &mut go) else {
        return Ok(None);
    };
    let b = d.a.tr_mul(&d.r);
    let scale: Vec<f64> = (0..g.ncols())
        .map(|c| Some(g[(c, c)].sqrt()).filter(|s| *s > 0.0).unwrap_or(1.0))
        .collect();
    // Folds dealt by the poses themselves, not by a seed (`folds`).
    let fold_poses = folds::folds_by_pose(data, folds);
    let Some(fold_normals) = fold_poses
        .iter()
        .map(|p| normal_of(&d, p, &mut go).filter(|_| go()))
        .collect::<Option<Vec<_>>>()
    else {
        return Ok(None);
    };
    let cv = CrossValidation {
        d: &d,
        g: &g,
        b: &b,
        scale: &scale,
        fold_poses,
        fold_normals,
    };
    let Some(candidates) = cv.all(&grid, settings.parallel.threads(), progress) else {
        return Ok(None);
    };
    let (chosen, without_maps) = choose(&candidates, structure)?;
    let maps = if chosen.harmonics == 0 {
        None
    } else {
        let cols = d.columns(chosen.harmonics);
        let x =
            solve(&g, &b, &cols, &scale, d.geo, chosen.ridge).ok_or(MapFitError::NotEvaluable)?;
        Some(maps_of(
            &d,
            &cols,
            &x,
            chosen.harmonics,
            n,
            settings.fade_rad,
        ))
    };
    let input = blocked::BlockedInput {
        d: &d,
        g: &g,
        b: &b,
        scale: &scale,
        data,
        fade_rad: settings.fade_rad,
    };
    let regions = settings.blocked_folds;
    let pair = (chosen.harmonics, chosen.ridge);
    let mut go = || progress(total, total);
    let Some(blocked) = blocked::blocked_errors(&input, regions, pair, &mut go) else {
        return Ok(None);
    };
    if !progress(total, total) {
        return Ok(None);
    }
    Ok(Some(MapFit {
        blocked,
        maps,
        chosen,
        without_maps,
        candidates,
        poses: data.len(),
        refused: d.refused.clone(),
    }))
}

/// The chosen candidate and the one without maps (K = 0). Cross-validated:
/// the lowest held-out eq. 7.10 cost (K = 0 is a candidate); a held
/// structure is taken whatever its cost (K = 0 when a fold could not solve
/// it).
fn choose(
    candidates: &[MapCandidate],
    structure: MapStructure,
) -> Result<(MapCandidate, MapCandidate), MapFitError> {
    let without_maps = candidates
        .iter()
        .find(|c| c.harmonics == 0)
        .cloned()
        .ok_or(MapFitError::NotEvaluable)?;
    let chosen = match structure {
        MapStructure::CrossValidated => candidates
            .iter()
            .min_by(|a, b| a.cv_cost_mm2.total_cmp(&b.cv_cost_mm2))
            .cloned()
            .expect("K = 0 is a candidate"),
        MapStructure::Fixed(_) => candidates
            .iter()
            .rev()
            .find(|c| c.harmonics > 0)
            .unwrap_or(&without_maps)
            .clone(),
    };
    Ok((chosen, without_maps))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A held structure keeps its harmonics when the poses afford them,
    /// else the largest of the settings' counts below that they afford,
    /// else none; K = 0 is always a candidate, the ridge is kept.
    #[test]
    fn a_held_structure_is_lowered_to_what_the_poses_afford() {
        let s = JointMapSettings::default();
        let order = MapOrder {
            harmonics: 60,
            ridge: 0.1,
        };
        assert_eq!(fixed_grid(&s, order, |_| true), [(0, 0.0), (60, 0.1)]);
        assert_eq!(fixed_grid(&s, order, |k| k <= 30), [(0, 0.0), (20, 0.1)]);
        assert_eq!(fixed_grid(&s, order, |k| k < 10), [(0, 0.0)]);
    }

    /// The rule on hand-computed figures (defaults: ℓ = 250 mm, 0.5 mm
    /// unseen at the tip, 20 mm floor).
    #[test]
    fn a_map_is_refused_by_what_one_pose_resolves_then_by_the_floor() {
        let s = JointMapSettings::default();
        // 100 mm lever, 0.1 mm noise: 1 mrad resolved, 0.25 mm at the tip.
        assert_eq!(refusal(6, 0.1, 1e-4, &s), None);
        // 0.4 mm noise: 4 mrad, 1 mm at the tip, above 0.5 mm and 2σ = 0.8 mm.
        let r = refusal(6, 0.1, 4e-4, &s).unwrap();
        assert_eq!(r.kind, MapRefusal::AngleNotResolved);
        assert!((r.resolved_deg - 4e-3f64.to_degrees()).abs() < 1e-12);
        assert!((r.unseen_tip_mm - 1.0).abs() < 1e-12);
        assert!((r.noise_mm - 0.4).abs() < 1e-12 && (r.lever_mm - 100.0).abs() < 1e-12);
        // 10 mm lever, 1 µm noise: 0.1 mrad, 0.025 mm at the tip, but the
        // lever is below the 20 mm floor.
        let r = refusal(6, 0.01, 1e-6, &s).unwrap();
        assert_eq!(r.kind, MapRefusal::LeverBelowFloor);
        assert!((r.unseen_tip_mm - 0.025).abs() < 1e-12);
        // 1 mm noise through a 400 mm lever: 0.625 mm at the tip, above
        // 0.5 mm but below twice the noise (ℓ/L = 0.625): fitted; through
        // 100 mm (2.5 mm, above 2 mm): refused, the bound 2 mm.
        assert_eq!(refusal(2, 0.4, 1e-3, &s), None);
        let r = refusal(2, 0.1, 1e-3, &s).unwrap();
        assert_eq!(r.kind, MapRefusal::AngleNotResolved);
        assert!((r.max_unseen_tip_mm - 2.0).abs() < 1e-12);
        assert!((r.unseen_tip_mm - 2.5).abs() < 1e-12);
        // A point on the axis resolves nothing: capped at 180°.
        let r = refusal(6, 0.0, 1e-5, &s).unwrap();
        assert_eq!(r.kind, MapRefusal::AngleNotResolved);
        assert_eq!(r.resolved_deg, 180.0);
        let names: Vec<_> = MapRefusal::ALL.iter().map(|k| k.name()).collect();
        for k in MapRefusal::ALL {
            assert_eq!(serde_json::to_value(k).unwrap(), k.name());
        }
        assert_eq!(names, ["angle_not_resolved", "lever_below_floor"]);
    }
}
