//! Automatic identifiability analysis (docs/design.md "Identifiability").
//!
//! Nothing is hard-coded: the stacked identification Jacobian (eq. 4.9 with
//! β, base, tool, loop and compliance columns) is built over the actual poses,
//! each column is scaled to unit norm, the numerical rank comes from the SVD,
//! and parameters are then taken greedily in a preference order (a pivoted
//! Gram–Schmidt QR): a column whose component orthogonal to the columns already
//! kept is below `dependency_tolerance` is dependent and dropped, and one below
//! `near_dependency_tolerance` (default 1e-3, i.e. a multiple correlation with
//! the kept columns above 0.9999995) is nearly dependent and dropped too: its σ
//! would be over 1000× that of an independent column. The order
//! prefers the parameters nearest the tool, which reproduces the thesis's choices
//! (§2.2: keep d3 over d2, the tool's z over d6, the tool's x, y over θ6).
//!
//! Reported: kept and dropped parameters with the reason and the kept
//! parameters each dropped one depends on, the condition number of the scaled
//! kept Jacobian, the observability index O1 of Borm & Meng
//! (`(σ1⋯σL)^(1/L)/√m`, m poses), and (after a fit) standard deviations and
//! strongly correlated pairs.
//!
//! Computation: the Jacobian (rows × candidates, thousands of rows) is
//! reduced to the triangular factor R of its QR (`triangular_factor`; the
//! calibration builds R block by block, `checks::stacked_factor`, without
//! forming the Jacobian); column norms, the SVDs, the Gram–Schmidt pass and the
//! dependency least squares then run on R's columns, which have the same
//! singular values and inner products.

use crate::model::{ParamId, ParamKind, RobotModel};
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// Identifiability settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IdentifiabilitySettings {
    /// A column whose norm is below this fraction of the largest column norm has
    /// no effect on the measurements.
    pub zero_column_tolerance: f64,
    /// Relative residual norm (of a unit column after projection on the kept
    /// ones) below which the column counts as dependent.
    pub dependency_tolerance: f64,
    /// |correlation| above which a pair is reported as strongly correlated.
    pub correlation_threshold: f64,
    /// Near-dependence: a column whose independent part (relative residual after
    /// projection on the kept ones, `√(1 − R²)` with R the multiple correlation)
    /// is below this is fixed at nominal. Its σ would be at least `1/tol` times
    /// what the same column alone would give, and it would raise the condition
    /// number by about that factor.
    #[serde(default = "default_near_dependency_tolerance")]
    pub near_dependency_tolerance: f64,
}

fn default_near_dependency_tolerance() -> f64 {
    1e-3
}

impl Default for IdentifiabilitySettings {
    fn default() -> Self {
        IdentifiabilitySettings {
            zero_column_tolerance: 1e-9,
            dependency_tolerance: 1e-6,
            correlation_threshold: 0.95,
            near_dependency_tolerance: default_near_dependency_tolerance(),
        }
    }
}

/// Why a parameter is not identified.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DropKind {
    /// Fixed by design (e.g. the loop's scale).
    Fixed,
    /// Its column is zero: no effect on the measured quantities.
    NoEffect,
    /// Linearly dependent on kept parameters (numerically exact).
    Dependent,
    /// Nearly dependent: its independent part is below
    /// `near_dependency_tolerance`.
    NearlyDependent,
}

/// A parameter that is not identified, and why.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DroppedParam {
    /// The parameter's name (`ParamId::name`).
    pub name: String,
    /// Why it is not identified.
    pub kind: DropKind,
    /// The reason in words, for the report.
    pub reason: String,
    /// Kept parameters it is (linearly) dependent on.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub depends_on: Vec<String>,
}

/// A strongly correlated pair of identified parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CorrelatedPair {
    /// Name of the first parameter.
    pub a: String,
    /// Name of the second parameter.
    pub b: String,
    /// Their correlation coefficient from the fit's covariance (|ρ| above `correlation_threshold`).
    pub correlation: f64,
}

/// The identifiability report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IdentifiabilityReport {
    /// Number of poses and residual rows used.
    pub poses: usize,
    /// Residual rows of the stacked Jacobian.
    pub rows: usize,
    /// Candidate parameters considered.
    pub candidates: usize,
    /// Numerical rank of the scaled candidate Jacobian.
    pub rank: usize,
    /// Names of the identified parameters, in the layout order.
    pub kept: Vec<String>,
    /// The parameters not identified, with why.
    pub dropped: Vec<DroppedParam>,
    /// σ_max/σ_min of the scaled kept Jacobian.
    pub condition_number: f64,
    /// Borm & Meng's O1 of the scaled kept Jacobian.
    pub observability_o1: f64,
    /// Parameter standard deviations after the fit, by name, in mm, deg or rad/(N·m).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub std_devs: Vec<(String, f64)>,
    /// Pairs of identified parameters whose |correlation| is above `correlation_threshold`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub correlated_pairs: Vec<CorrelatedPair>,
    /// With orientation rows: the kept parameters that the same poses without
    /// their orientations would not identify (typically d6, θ6 and the tool
    /// frame's rotation), found by analysing the position rows alone.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub identifiable_by_orientation: Vec<String>,
    /// With position-only data: the parameters the same poses would identify
    /// with measured orientations and do not without (typically the tool
    /// frame's rotation `tool_rx, tool_ry, tool_rz`). A production tool's tip
    /// away from the measured point depends on them, so its error there is
    /// unknown; the report names them.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub unseen_tool_tip_terms: Vec<String>,
}

impl IdentifiabilityReport {
    /// Number of parameters dropped as nearly (not exactly) dependent.
    pub fn near_dependent(&self) -> usize {
        self.dropped
            .iter()
            .filter(|d| d.kind == DropKind::NearlyDependent)
            .count()
    }
}

/// Preference rank: lower is considered first (kept when dependent). Tool first,
/// then links from the tip to the base, loop lengths, compliance last.
fn preference(id: &ParamId, n: usize) -> (usize, usize, usize) {
    use ParamKind::*;
    let within = |k: ParamKind| match k {
        Theta => 0,
        D => 1,
        A => 2,
        Alpha => 3,
        Beta => 4,
        B => 5,
        _ => 6,
    };
    match id.kind {
        ToolX | ToolY | ToolZ | ToolRx | ToolRy | ToolRz => (0, 0, id.kind as usize),
        LoopL3 | LoopL4 | LoopL5 => (1, 0, id.kind as usize),
        Compliance => (3, id.link, 0),
        PayloadX | PayloadY | PayloadZ | PayloadMass => (4, 0, id.kind as usize),
        k => (2, n - id.link, within(k)),
    }
}

/// Result of the analysis: the kept parameters (in the layout order) and the report.
#[derive(Debug, Clone)]
pub struct Analysis {
    /// The identified parameters, in the layout order.
    pub kept: Vec<ParamId>,
    /// What the analysis found.
    pub report: IdentifiabilityReport,
}

/// The upper-triangular factor R of the Householder QR `j = Q·R` (min(rows,
/// cols) × cols; `j` itself when it has no more rows than columns). Q has
/// orthonormal columns, so R has the singular values of `j` (to rounding of
/// the order ε‖j‖ per column, as the SVD of `j` itself) and the same inner
/// products between columns, hence the same column norms and, scaled, the
/// same scaled columns' inner products (`j·D = Q·(R·D)`): the rank, the
/// Gram–Schmidt residuals, the dependencies and the condition number all
/// follow from R's short columns. One QR replaces an SVD of the rows × cols
/// matrix for each of these (several for a robot with dependent candidates),
/// the bulk of the analysis's time on a large pose set.
/// The singular values of `m` (descending), with nalgebra's SVD capped in
/// iterations: it loops for ever on a NaN entry. A matrix with a non-finite
/// entry, or one that does not converge, gives all zeros (rank 0), so a caller
/// that has not refused such a matrix before gets a bounded, empty answer.
pub(crate) fn singular_values(m: DMatrix<f64>) -> DVector<f64> {
    let k = m.nrows().min(m.ncols());
    if m.iter().any(|v| !v.is_finite()) {
        return DVector::zeros(k);
    }
    m.try_svd(false, false, 5.0 * f64::EPSILON, svd_iterations(k))
        .map_or_else(|| DVector::zeros(k), |s| s.singular_values)
}

/// An iteration cap for an SVD of `k` singular values: converging ones take
/// a few sweeps per value.
pub(crate) fn svd_iterations(k: usize) -> usize {
    200 * (k + 1)
}

pub(crate) fn triangular_factor(js: DMatrix<f64>) -> DMatrix<f64> {
    if js.ncols() == 0 || js.nrows() <= js.ncols() {
        return js;
    }
    js.qr().r()
}

/// Analyses the identification Jacobian `j` (rows × candidates) of `candidates`.
/// `fixed` parameters are reported as dropped with their reason and not considered.
pub fn analyse(
    model: &RobotModel,
    j: &DMatrix<f64>,
    candidates: &[ParamId],
    fixed: &[(ParamId, String)],
    poses: usize,
    settings: &IdentifiabilitySettings,
) -> Analysis {
    let f = triangular_factor(j.clone());
    analyse_factor(model, &f, j.nrows(), candidates, fixed, poses, settings)
}

/// [`analyse`] from a factor `f` of the Jacobian: any matrix with the
/// Jacobian's column inner products (`fᵀf = jᵀj`), such as its triangular
/// factor (`triangular_factor`, `checks::stacked_factor`: the fast path) or the
/// `rows` × candidates Jacobian itself (the general path).
pub(crate) fn analyse_factor(
    model: &RobotModel,
    j: &DMatrix<f64>,
    rows: usize,
    candidates: &[ParamId],
    fixed: &[(ParamId, String)],
    poses: usize,
    settings: &IdentifiabilitySettings,
) -> Analysis {
    let n = model.dof();
    let norms: Vec<f64> = j.column_iter().map(|c| c.norm()).collect();
    let max_norm = norms.iter().cloned().fold(0.0, f64::max);
    let mut dropped: Vec<DroppedParam> = fixed
        .iter()
        .map(|(id, why)| DroppedParam {
            name: id.name(),
            kind: DropKind::Fixed,
            reason: why.clone(),
            depends_on: vec![],
        })
        .collect();
    let mut live = Vec::new();
    for (c, id) in candidates.iter().enumerate() {
        if norms[c] <= settings.zero_column_tolerance * max_norm || norms[c] == 0.0 {
            let reason = if id.kind == ParamKind::Compliance {
                "gravity puts no torque on this joint in these poses".to_string()
            } else {
                "no effect on the measured quantities".to_string()
            };
            dropped.push(DroppedParam {
                name: id.name(),
                kind: DropKind::NoEffect,
                reason,
                depends_on: vec![],
            });
        } else {
            live.push(c);
        }
    }
    // Scaled candidate matrix (of the factor's short columns on the fast
    // path) and its rank.
    let mut rf = DMatrix::zeros(j.nrows(), live.len());
    for (k, &c) in live.iter().enumerate() {
        rf.set_column(k, &(j.column(c) / norms[c]));
    }
    let rank = if live.is_empty() {
        0
    } else {
        let sv = singular_values(rf.clone());
        let smax = sv.max();
        sv.iter().filter(|s| **s > smax * 1e-9).count()
    };
    // Greedy pivoted Gram–Schmidt in preference order.
    let mut order: Vec<usize> = (0..live.len()).collect();
    order.sort_by_key(|&k| preference(&candidates[live[k]], n));
    let mut basis: Vec<DVector<f64>> = Vec::new();
    let mut kept_local: Vec<usize> = Vec::new();
    for &k in &order {
        let mut v: DVector<f64> = rf.column(k).into_owned();
        for _ in 0..2 {
            for b in &basis {
                let d = b.dot(&v);
                v.axpy(-d, b, 1.0);
            }
        }
        let res = v.norm();
        if res > settings.dependency_tolerance && res >= settings.near_dependency_tolerance {
            basis.push(v / res);
            kept_local.push(k);
        } else {
            let name_of = |kk: usize| candidates[live[kk]].name();
            dropped.push(dependent(&rf, &kept_local, k, res, &name_of, settings));
        }
    }
    // Kept parameters in layout order (`live` is increasing, so sorting the
    // local indices sorts the candidates).
    kept_local.sort_unstable();
    let kept: Vec<ParamId> = kept_local.iter().map(|&k| candidates[live[k]]).collect();
    let mut jk = DMatrix::zeros(rf.nrows(), kept_local.len());
    for (i, &k) in kept_local.iter().enumerate() {
        jk.set_column(i, &rf.column(k));
    }
    let (cond, o1) = if kept.is_empty() {
        (f64::INFINITY, 0.0)
    } else {
        let sv = singular_values(jk);
        let smax = sv.max();
        let smin = sv.min();
        let l = sv.len() as f64;
        let log_mean = sv.iter().map(|s| s.max(1e-300).ln()).sum::<f64>() / l;
        (smax / smin, log_mean.exp() / (poses.max(1) as f64).sqrt())
    };
    Analysis {
        report: IdentifiabilityReport {
            poses,
            rows,
            candidates: candidates.len(),
            rank,
            kept: kept.iter().map(|i| i.name()).collect(),
            dropped,
            condition_number: cond,
            observability_o1: o1,
            std_devs: vec![],
            correlated_pairs: vec![],
            identifiable_by_orientation: vec![],
            unseen_tool_tip_terms: vec![],
        },
        kept,
    }
}

/// The dropped entry of scaled column `k` of `rf`, whose part independent of
/// the kept columns `kept` has norm `res`: dependent or nearly so, naming
/// the kept parameters (`name_of` a local index) that explain it by least
/// squares on their columns.
fn dependent(
    rf: &DMatrix<f64>,
    kept: &[usize],
    k: usize,
    res: f64,
    name_of: &dyn Fn(usize) -> String,
    settings: &IdentifiabilitySettings,
) -> DroppedParam {
    // Which kept parameters explain it: least squares on the kept columns.
    let mut kmat = DMatrix::zeros(rf.nrows(), kept.len());
    for (i, &kk) in kept.iter().enumerate() {
        kmat.set_column(i, &rf.column(kk));
    }
    let target: DVector<f64> = rf.column(k).into_owned();
    let values = kmat.ncols().min(kmat.nrows());
    let coef = kmat
        .clone()
        .try_svd(true, true, 5.0 * f64::EPSILON, svd_iterations(values))
        .and_then(|s| s.solve(&target, 1e-12).ok())
        .unwrap_or_else(|| DVector::zeros(kept.len()));
    let cmax = coef.iter().fold(0.0_f64, |a, c| a.max(c.abs()));
    let depends_on = kept
        .iter()
        .zip(coef.iter())
        .filter(|(_, c)| c.abs() > 0.1 * cmax)
        .map(|(&kk, _)| name_of(kk))
        .collect::<Vec<_>>();
    let (kind, reason) = if res <= settings.dependency_tolerance {
        (
            DropKind::Dependent,
            "linearly dependent on kept parameters".to_string(),
        )
    } else {
        (
            DropKind::NearlyDependent,
            format!(
                "nearly dependent on kept parameters: only {res:.1e} of its scaled column is independent of them (threshold {:.0e}), so its σ would be some {:.0}× larger; fixed at nominal",
                settings.near_dependency_tolerance,
                1.0 / res
            ),
        )
    };
    DroppedParam {
        name: name_of(k),
        kind,
        reason,
        depends_on,
    }
}

/// Standard deviations (display units) and strongly correlated pairs from a covariance.
pub fn uncertainty(
    ids: &[ParamId],
    cov: &DMatrix<f64>,
    threshold: f64,
) -> (Vec<(String, f64)>, Vec<CorrelatedPair>) {
    let sd: Vec<f64> = (0..ids.len())
        .map(|i| cov[(i, i)].max(0.0).sqrt())
        .collect();
    let std_devs = ids
        .iter()
        .zip(&sd)
        .map(|(id, s)| (id.name(), id.to_display(*s)))
        .collect();
    let mut pairs = Vec::new();
    for a in 0..ids.len() {
        for b in a + 1..ids.len() {
            if sd[a] > 0.0 && sd[b] > 0.0 {
                let rho = cov[(a, b)] / (sd[a] * sd[b]);
                if rho.abs() > threshold {
                    pairs.push(CorrelatedPair {
                        a: ids[a].name(),
                        b: ids[b].name(),
                        correlation: rho,
                    });
                }
            }
        }
    }
    (std_devs, pairs)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibrate::identify::checks::{stacked_factor, stacked_jacobian};
    use crate::measure::{to_measurements, Measurement};
    use crate::model::{preset, ParamLayout};
    use crate::sim::{perturb_geometry, random_configurations, ErrorMagnitudes, TrueRobot};
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    fn data(name: &str, poses: usize, seed: u64) -> (RobotModel, Vec<Measurement>) {
        let nominal = preset(name).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let tm = perturb_geometry(&nominal, &ErrorMagnitudes::from_mm_deg(0.5, 0.05), &mut rng);
        let qs = random_configurations(&nominal, poses, &mut rng);
        let rows = TrueRobot::new(tm)
            .measure(&qs, Some(nominal.payload.mass), None, &mut rng)
            .unwrap();
        let m = to_measurements(&nominal, &rows, nominal.payload.mass);
        (nominal, m)
    }

    /// The fast path (everything on the triangular factor built block by
    /// block) against the general path (SVDs and Gram–Schmidt on the full
    /// scaled matrix): the same rank, kept and dropped parameters with the
    /// same reasons and dependencies, and the same condition number and O1 to
    /// rounding. Open chains with dependent parameters and columns without
    /// effect (UR5, YS100 with compliance), a closed loop (HH800), several
    /// blocks (300 poses), and a pose set with fewer rows than candidates.
    #[test]
    fn triangular_factor_path_matches_the_full_matrix() {
        for (name, poses) in [("ur5", 300), ("ys100", 200), ("hh800", 150), ("ys100", 8)] {
            let (nominal, ident) = data(name, poses, 11);
            let mut ids = ParamLayout::geometric(&nominal).ids;
            ids.extend((0..nominal.dof()).map(|k| ParamId::new(ParamKind::Compliance, k)));
            let j = stacked_jacobian(&nominal, &ids, &ident);
            let (f, rows) = stacked_factor(&nominal, &ids, &ident, None);
            assert_eq!((rows, f.ncols()), j.shape());
            assert!(f.nrows() <= f.ncols() && f.nrows() <= rows);
            let s = IdentifiabilitySettings::default();
            let n = ident.len();
            let fast = analyse_factor(&nominal, &f, rows, &ids, &[], n, &s);
            let full = analyse_factor(&nominal, &j, rows, &ids, &[], n, &s);
            // The public entry point: one QR of the whole matrix.
            let whole = analyse(&nominal, &j, &ids, &[], n, &s);
            assert_eq!(whole.report.kept, full.report.kept, "{name}");
            let (a, b) = (&fast.report, &full.report);
            assert_eq!(fast.kept, full.kept, "{name}");
            assert_eq!(a.rank, b.rank, "{name}");
            assert_eq!(a.kept, b.kept, "{name}");
            assert_eq!(a.dropped.len(), b.dropped.len(), "{name}");
            for (x, y) in a.dropped.iter().zip(&b.dropped) {
                assert_eq!(
                    (&x.name, x.kind, &x.depends_on),
                    (&y.name, y.kind, &y.depends_on)
                );
            }
            assert!(
                !a.dropped.is_empty() && a.rank < ids.len(),
                "{name}: nothing dependent"
            );
            let rel = |x: f64, y: f64| (x - y).abs() / y.abs();
            assert!(
                rel(a.condition_number, b.condition_number) < 1e-9,
                "{name}: {} vs {}",
                a.condition_number,
                b.condition_number
            );
            assert!(
                rel(a.observability_o1, b.observability_o1) < 1e-9,
                "{name}: {} vs {}",
                a.observability_o1,
                b.observability_o1
            );
        }
    }
}
