//! The typed view of a stored calibration report: what the page reads from the
//! JSON form of [`crate::calibrate::identify::CalibrationReport`].
//!
//! Deserialisation is lenient on purpose: a stored report outlives the code
//! that wrote it. Every field has a default, a non-finite number (written as
//! `null`) reads as `None`, and a part that does not parse (e.g. an
//! identifiability summary of another shape) is dropped, so the page shows
//! what it can and says what is missing. The format version says which parts
//! to expect: 1 (no `format_version` field) holds error norms only; 2 adds
//! per-pose error vectors, positions, session names and pose sources; 3 the
//! compensator training pool, the compensators and `auto`'s choice; 4 the
//! orientation errors of sets that measured orientation.

use crate::calibrate::identify::identifiability::IdentifiabilityReport;
use crate::calibrate::identify::{
    FailedMethod, LmReport, Method, MethodWarning, ParamEstimate, PoseSources,
    REPORT_FORMAT_VERSION,
};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Deserializer};
use std::collections::BTreeMap;

/// A part that parses or is `None` (never an error for the whole report).
fn lenient<'de, D: Deserializer<'de>, T: DeserializeOwned>(d: D) -> Result<Option<T>, D::Error> {
    let v = serde_json::Value::deserialize(d)?;
    Ok(serde_json::from_value(v).ok())
}

/// A list whose unparsable items are dropped.
fn lenient_list<'de, D: Deserializer<'de>, T: DeserializeOwned>(d: D) -> Result<Vec<T>, D::Error> {
    let v = serde_json::Value::deserialize(d)?;
    Ok(match v {
        serde_json::Value::Array(items) => items
            .into_iter()
            .filter_map(|i| serde_json::from_value(i).ok())
            .collect(),
        _ => Vec::new(),
    })
}

fn version_one() -> u32 {
    1
}

/// The report as the page reads it.
#[derive(Debug, Clone, Default, Deserialize)]
pub struct ReportView {
    /// The report's format version (1 when the field is absent).
    #[serde(default = "version_one")]
    pub format_version: u32,
    /// The robot model's name.
    #[serde(default)]
    pub robot: String,
    /// Identification poses used.
    #[serde(default)]
    pub identification_poses: Option<usize>,
    /// Validation poses given.
    #[serde(default)]
    pub validation_poses: Option<usize>,
    /// Each session's registration, in session order.
    #[serde(default, deserialize_with = "lenient_list")]
    pub registration: Vec<RegistrationView>,
    /// Which parameters were identified (`None`: absent or of another shape).
    #[serde(default, deserialize_with = "lenient")]
    pub identifiability: Option<IdentifiabilityReport>,
    /// Errors of the nominal model after registration.
    #[serde(default)]
    pub nominal: SetsView,
    /// By the name the report stored (a method of another version too).
    #[serde(default)]
    pub methods: BTreeMap<String, MethodView>,
    /// Methods that failed, with their reasons.
    #[serde(default, deserialize_with = "lenient_list")]
    pub failed: Vec<FailedMethod>,
    /// Names of the tracker sessions by index (empty: unnamed).
    #[serde(default)]
    pub session_names: Vec<String>,
    /// Where each pose came from (format 2; `None`: unknown).
    #[serde(default, deserialize_with = "lenient")]
    pub pose_sources: Option<PoseSources>,
}

/// Registration of one session (only the RMS is shown).
#[derive(Debug, Clone, Deserialize)]
pub struct RegistrationView {
    /// The 0-based tracker session.
    pub session: usize,
    /// RMS distance of the nominal model after the registration [mm].
    #[serde(default)]
    pub rms_mm: Option<f64>,
}

/// Errors of a model on the identification and validation sets.
#[derive(Debug, Clone, Default, Deserialize)]
pub struct SetsView {
    /// Errors on the identification set.
    #[serde(default)]
    pub identification: Option<SetView>,
    /// Errors on the validation set, when one was given.
    #[serde(default)]
    pub validation: Option<SetView>,
}

/// Errors on one set; `None` entries are poses the model could not predict.
#[derive(Debug, Clone, Default, Deserialize)]
pub struct SetView {
    /// Poses in the set.
    #[serde(default)]
    pub n: Option<usize>,
    /// Mean position error [mm].
    #[serde(default)]
    pub mean_mm: Option<f64>,
    /// Largest position error [mm].
    #[serde(default)]
    pub max_mm: Option<f64>,
    /// Standard deviation of the position errors (n − 1) [mm].
    #[serde(default)]
    pub std_mm: Option<f64>,
    /// RMS position error [mm].
    #[serde(default)]
    pub rms_mm: Option<f64>,
    /// 95th percentile of the position errors [mm].
    #[serde(default)]
    pub p95_mm: Option<f64>,
    /// Orientation statistics [deg] (format 4; none when the set measured no
    /// orientation).
    #[serde(default)]
    pub orientation_n: Option<usize>,
    /// Mean orientation error [deg].
    #[serde(default)]
    pub orientation_mean_deg: Option<f64>,
    /// Largest orientation error [deg].
    #[serde(default)]
    pub orientation_max_deg: Option<f64>,
    /// Standard deviation of the orientation errors (n − 1) [deg].
    #[serde(default)]
    pub orientation_std_deg: Option<f64>,
    /// RMS orientation error [deg].
    #[serde(default)]
    pub orientation_rms_deg: Option<f64>,
    /// 95th percentile of the orientation errors [deg].
    #[serde(default)]
    pub orientation_p95_deg: Option<f64>,
    /// Position error norm per pose [mm].
    #[serde(default)]
    pub errors_mm: Vec<Option<f64>>,
    /// Error vector `measured − predicted` per pose, registered base frame of its session [mm]
    /// (format 2).
    #[serde(default)]
    pub errors_xyz_mm: Vec<[Option<f64>; 3]>,
    /// Measured position per pose, registered base frame of its session [mm] (format 2).
    #[serde(default)]
    pub positions_mm: Vec<[Option<f64>; 3]>,
}

impl SetView {
    /// The finite error norms.
    pub fn finite(&self) -> Vec<f64> {
        self.errors_mm
            .iter()
            .flatten()
            .copied()
            .filter(|v| v.is_finite())
            .collect()
    }
    /// Signed errors along one axis (0 = x), finite ones only.
    pub fn axis(&self, k: usize) -> Vec<f64> {
        self.errors_xyz_mm
            .iter()
            .filter_map(|v| v[k])
            .filter(|v| v.is_finite())
            .collect()
    }
}

/// The result of one method.
#[derive(Debug, Clone, Default, Deserialize)]
pub struct MethodView {
    /// How the method's least-squares fit ended (`None`: absent or unreadable).
    #[serde(default, deserialize_with = "lenient")]
    pub solver: Option<LmReport>,
    /// Errors on the identification and validation sets.
    #[serde(flatten)]
    pub sets: SetsView,
    /// The identified parameters in display units.
    #[serde(default, deserialize_with = "lenient_list")]
    pub parameters: Vec<ParamEstimate>,
    /// Identified joint stiffness 1/c per joint [N·m/rad] (`None`: not identified).
    #[serde(default)]
    pub stiffness_nm_per_rad: Vec<Option<f64>>,
    /// The TLBO search's convergence (SKCM-C by TLBO only).
    #[serde(default, deserialize_with = "lenient")]
    pub tlbo: Option<TlboView>,
    /// Physically implausible or doubtful results.
    #[serde(default, deserialize_with = "lenient_list")]
    pub warnings: Vec<MethodWarning>,
    /// Errors on the compensator training pool (format 3).
    #[serde(default, deserialize_with = "lenient")]
    pub training: Option<SetView>,
    /// The compensator's network, training and base errors (format 3).
    #[serde(default, deserialize_with = "lenient")]
    pub compensator: Option<CompensatorView>,
    /// What `auto` chose and why.
    #[serde(default, deserialize_with = "lenient")]
    pub auto: Option<AutoView>,
}

/// Statistics only (mm).
#[derive(Debug, Clone, Default, Deserialize)]
pub struct StatsView {
    /// Mean position error [mm].
    #[serde(default)]
    pub mean_mm: Option<f64>,
    /// Largest position error [mm].
    #[serde(default)]
    pub max_mm: Option<f64>,
}

/// Cross-validated errors of the base and the compensated model.
#[derive(Debug, Clone, Default, Deserialize)]
pub struct CvView {
    /// Number of random folds.
    #[serde(default)]
    pub folds: Option<usize>,
    /// The base alone, out of fold.
    #[serde(default)]
    pub base: StatsView,
    /// The compensated model, out of fold.
    #[serde(default)]
    pub compensated: StatsView,
    /// The spatially blocked folds, when they ran.
    #[serde(default, deserialize_with = "lenient_list")]
    pub blocked: Vec<BlockedView>,
}

/// The training run of a compensator.
#[derive(Debug, Clone, Default, Deserialize)]
pub struct TrainView {
    /// The trainer: `lm`, `iwo`, `tlbo`, `rbf` or `gp`.
    #[serde(default)]
    pub trainer: String,
    /// Epochs, iterations or generations run (RBF: units; GP: candidates fitted).
    #[serde(default)]
    pub epochs: Option<usize>,
    /// Why it stopped, in words.
    #[serde(default)]
    pub stop: String,
}

/// A compensator method's network, training and base errors (format 3).
#[derive(Debug, Clone, Default, Deserialize)]
pub struct CompensatorView {
    /// The model-based method under it.
    #[serde(default)]
    pub base: String,
    /// The network's family.
    #[serde(default)]
    pub kind: String,
    /// Hidden units (MLP) or radial units (RBF).
    #[serde(default)]
    pub units: Option<usize>,
    /// Inputs of the network, in words.
    #[serde(default)]
    pub inputs: String,
    /// The training run on the whole pool.
    #[serde(default)]
    pub training: TrainView,
    /// Which poses trained it: `training` or `identification`.
    #[serde(default)]
    pub trained_on: String,
    /// Poses that trained it.
    #[serde(default)]
    pub training_poses: Option<usize>,
    /// Cross-validation on the training pool, when it ran.
    #[serde(default, deserialize_with = "lenient")]
    pub cross_validation: Option<CvView>,
    /// The base alone on the identification set.
    #[serde(default)]
    pub base_identification: Option<StatsView>,
    /// The base alone on the validation set.
    #[serde(default)]
    pub base_validation: Option<StatsView>,
    /// The base alone on the training pool, when it is a set of its own.
    #[serde(default)]
    pub base_training: Option<StatsView>,
    /// Each joint's trained range [deg].
    #[serde(default, deserialize_with = "lenient_list")]
    pub trained_ranges_deg: Vec<[f64; 2]>,
    /// Width beyond the trained ranges over which the correction fades to zero [deg].
    #[serde(default)]
    pub fade_deg: Option<f64>,
    /// The expected errors checked on the validation set, for compensators that give one.
    #[serde(default, deserialize_with = "lenient")]
    pub uncertainty: Option<UncertaintyView>,
    /// What the compensator does to orientation (format 4).
    #[serde(default)]
    pub orientation_note: Option<String>,
    /// Whether it has an orientation part, and why (format 4).
    #[serde(default, deserialize_with = "lenient")]
    pub orientation_part: Option<OrientationPartView>,
}

/// A compensator's orientation part: its status and why.
#[derive(Debug, Clone, Default, Deserialize)]
pub struct OrientationPartView {
    /// `trained`, `not_measured`, `too_few_poses`, `training_failed` or `not_kept`.
    #[serde(default)]
    pub status: String,
    /// Why, in words.
    #[serde(default)]
    pub reason: String,
}

/// The expected errors checked on the validation set.
#[derive(Debug, Clone, Default, Deserialize)]
pub struct UncertaintyView {
    /// Validation poses compared.
    #[serde(default)]
    pub poses: Option<usize>,
    /// Mean expected error `u` [mm].
    #[serde(default)]
    pub mean_expected_mm: Option<f64>,
    /// RMS of the validation errors over RMS of `u` (1: calibrated).
    #[serde(default)]
    pub rms_ratio: Option<f64>,
    /// Share of poses with `e > u` (Gaussian: 0.392).
    #[serde(default)]
    pub above_expected: Option<f64>,
    /// Share of poses with `e > 2u` (Gaussian: 0.0074).
    #[serde(default)]
    pub above_twice_expected: Option<f64>,
}

/// A region of joint space held out whole in cross-validation.
#[derive(Debug, Clone, Default, Deserialize)]
pub struct BlockedView {
    /// Poses in the region.
    #[serde(default)]
    pub poses: Option<usize>,
    /// Centre of the region, model-convention joints [rad].
    #[serde(default)]
    pub centre: Vec<f64>,
    /// Mean error of the base on the region [mm].
    #[serde(default)]
    pub base_mean_mm: Option<f64>,
    /// Mean error after compensation, trained without the region [mm].
    #[serde(default)]
    pub compensated_mean_mm: Option<f64>,
}

/// What `auto` chose and why.
#[derive(Debug, Clone, Default, Deserialize)]
pub struct AutoView {
    /// The method whose model `auto` delivers.
    #[serde(default)]
    pub chosen: String,
    /// The choice in words.
    #[serde(default)]
    pub reason: String,
    /// How the rule between the options decided (absent in older reports).
    #[serde(default, deserialize_with = "lenient")]
    pub decision: Option<AutoDecisionView>,
}

/// `auto`'s decision: the tie, the step that decided, the runner-up and the
/// margin.
#[derive(Debug, Clone, Default, Deserialize)]
pub struct AutoDecisionView {
    /// Whether another option's cross-validated mean was within `tie_margin` of the lowest.
    #[serde(default)]
    pub tie: bool,
    /// What the deciding step compares.
    #[serde(default)]
    pub step_label: String,
    /// The best of the options the deciding step removed.
    #[serde(default)]
    pub runner_up: Option<String>,
    /// By how much the winner led the runner-up at the deciding step, in `margin_unit`.
    #[serde(default)]
    pub margin: f64,
    /// Unit of `margin`: `mm`, `physics rank` or `fitted quantities`.
    #[serde(default)]
    pub margin_unit: String,
    /// The runner-up's cross-validated mean less the winner's [mm].
    #[serde(default)]
    pub mean_margin_mm: f64,
    /// The relative margin within which figures are a tie.
    #[serde(default)]
    pub tie_margin: f64,
    /// The better base that took over from an option on the weaker one, if it did.
    #[serde(default)]
    pub fallback: Option<BaseFallbackView>,
    /// The blocked-fold veto's checks (absent in older reports).
    #[serde(default)]
    pub blocked_checks: Vec<BlockedCheckView>,
}

/// One option checked by the blocked-fold veto.
#[derive(Debug, Clone, Default, Deserialize)]
pub struct BlockedCheckView {
    /// The option checked (the method it delivers).
    #[serde(default)]
    pub option: String,
    /// Its base alone (KM or SKCM).
    #[serde(default)]
    pub base: String,
    /// `passed`, `blocked_mean` or `blocked_max`.
    #[serde(default)]
    pub verdict: String,
    /// What the verdict says, in words.
    #[serde(default)]
    pub verdict_label: String,
    /// Clusters of joint space held out.
    #[serde(default)]
    pub regions: usize,
    /// Poses the clusters held.
    #[serde(default)]
    pub poses: usize,
    /// The option over the clusters, each pose once.
    #[serde(default)]
    pub option_blocked: BlockedFiguresView,
    /// The base over the clusters, each pose once.
    #[serde(default)]
    pub base_blocked: BlockedFiguresView,
    /// Edges of the joints' drawn ranges held out (absent in older reports).
    #[serde(default)]
    pub edges: usize,
    /// The edge where the option fared worst against its base.
    #[serde(default, deserialize_with = "lenient")]
    pub worst_edge: Option<EdgeFiguresView>,
}

/// The option and its base at one edge of a joint's drawn range [mm].
#[derive(Debug, Clone, Default, Deserialize)]
pub struct EdgeFiguresView {
    /// The joint (1-based).
    #[serde(default)]
    pub joint: usize,
    /// `low` or `high` end of the joint's drawn range.
    #[serde(default)]
    pub side: String,
    /// Poses held out at that edge.
    #[serde(default)]
    pub poses: usize,
    /// The option's held-out errors there.
    #[serde(default)]
    pub option: BlockedFiguresView,
    /// The base's held-out errors there.
    #[serde(default)]
    pub base: BlockedFiguresView,
}

/// Held-out errors on the blocked regions [mm].
#[derive(Debug, Clone, Copy, Default, Deserialize)]
pub struct BlockedFiguresView {
    /// Mean held-out error [mm].
    #[serde(default)]
    pub mean_mm: f64,
    /// Largest held-out error [mm].
    #[serde(default)]
    pub max_mm: f64,
}

/// The better base that took over from an option on the weaker one.
#[derive(Debug, Clone, Default, Deserialize)]
pub struct BaseFallbackView {
    /// The option the tie rule chose among all.
    #[serde(default)]
    pub instead_of: String,
    /// The base under it.
    #[serde(default)]
    pub weaker_base: String,
    /// The base that beats it outside the trained region.
    #[serde(default)]
    pub better_base: String,
    /// The weaker base alone [mm], measured as `measured_by` says.
    #[serde(default)]
    pub weaker_mm: f64,
    /// The better base alone [mm], measured as `measured_by` says.
    #[serde(default)]
    pub better_mm: f64,
    /// What the two figures measure, in words.
    #[serde(default)]
    pub measured_by: String,
}

/// TLBO convergence (cost per generation).
#[derive(Debug, Clone, Deserialize)]
pub struct TlboView {
    /// Generations run.
    #[serde(default)]
    pub generations: Option<usize>,
    /// Cost evaluations.
    #[serde(default)]
    pub evaluations: Option<usize>,
    /// Best eq. 7.10 cost after each generation [mm²] (`None`: not finite).
    #[serde(default)]
    pub history: Vec<Option<f64>>,
}

/// How the page treats the report's format version.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// The current version: everything is expected.
    Current,
    /// An older version: parts it did not hold are said to be missing.
    Older(u32),
    /// A newer version than this program knows: shown as far as understood.
    Newer(u32),
}

impl ReportView {
    /// Reads a stored report.
    pub fn from_json(v: &serde_json::Value) -> Result<ReportView, serde_json::Error> {
        ReportView::deserialize(v)
    }

    /// How the page treats this report's format version.
    pub fn format(&self) -> Format {
        use std::cmp::Ordering::*;
        match self.format_version.cmp(&REPORT_FORMAT_VERSION) {
            Equal => Format::Current,
            Less => Format::Older(self.format_version),
            Greater => Format::Newer(self.format_version),
        }
    }

    /// The methods in the thesis's order ([`Method::THESIS`]: KM, SKCM, SKCM-C),
    /// then any other by name.
    pub fn ordered_methods(&self) -> Vec<(&str, &MethodView)> {
        let rank = |k: &str| {
            Method::THESIS
                .iter()
                .position(|m| m.name() == k)
                .unwrap_or(Method::THESIS.len())
        };
        let mut v: Vec<(&str, &MethodView)> =
            self.methods.iter().map(|(k, m)| (k.as_str(), m)).collect();
        v.sort_by(|a, b| rank(a.0).cmp(&rank(b.0)).then(a.0.cmp(b.0)));
        v
    }

    /// The best method, as [`crate::calibrate::identify::CalibrationReport::best_method`]:
    /// smallest validation mean, identification mean without a validation set.
    pub fn best(&self) -> Option<&str> {
        self.methods
            .iter()
            .filter_map(|(k, m)| Some((k.as_str(), best_key(m)?)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(k, _)| k)
    }

    /// The name of session `i` as the measurement sets name it.
    pub fn session_name(&self, i: usize) -> String {
        self.session_names
            .get(i)
            .cloned()
            .unwrap_or_else(|| format!("session {}", i + 1))
    }
}

/// The ranking key of "best": validation mean, else identification mean.
pub fn best_key(m: &MethodView) -> Option<f64> {
    let mean = |s: &Option<SetView>| s.as_ref().and_then(|s| s.mean_mm);
    mean(&m.sets.validation).or_else(|| mean(&m.sets.identification))
}
