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
    #[serde(default = "version_one")]
    pub format_version: u32,
    #[serde(default)]
    pub robot: String,
    #[serde(default)]
    pub identification_poses: Option<usize>,
    #[serde(default)]
    pub validation_poses: Option<usize>,
    #[serde(default, deserialize_with = "lenient_list")]
    pub registration: Vec<RegistrationView>,
    #[serde(default, deserialize_with = "lenient")]
    pub identifiability: Option<IdentifiabilityReport>,
    #[serde(default)]
    pub nominal: SetsView,
    /// By the name the report stored (a method of another version too).
    #[serde(default)]
    pub methods: BTreeMap<String, MethodView>,
    #[serde(default, deserialize_with = "lenient_list")]
    pub failed: Vec<FailedMethod>,
    #[serde(default)]
    pub session_names: Vec<String>,
    #[serde(default, deserialize_with = "lenient")]
    pub pose_sources: Option<PoseSources>,
}

/// Registration of one session (only the RMS is shown).
#[derive(Debug, Clone, Deserialize)]
pub struct RegistrationView {
    pub session: usize,
    #[serde(default)]
    pub rms_mm: Option<f64>,
}

/// Errors of a model on the identification and validation sets.
#[derive(Debug, Clone, Default, Deserialize)]
pub struct SetsView {
    #[serde(default)]
    pub identification: Option<SetView>,
    #[serde(default)]
    pub validation: Option<SetView>,
}

/// Errors on one set; `None` entries are poses the model could not predict.
#[derive(Debug, Clone, Default, Deserialize)]
pub struct SetView {
    #[serde(default)]
    pub n: Option<usize>,
    #[serde(default)]
    pub mean_mm: Option<f64>,
    #[serde(default)]
    pub max_mm: Option<f64>,
    #[serde(default)]
    pub std_mm: Option<f64>,
    #[serde(default)]
    pub rms_mm: Option<f64>,
    #[serde(default)]
    pub p95_mm: Option<f64>,
    /// Orientation statistics [deg] (format 4; none when the set measured no
    /// orientation).
    #[serde(default)]
    pub orientation_n: Option<usize>,
    #[serde(default)]
    pub orientation_mean_deg: Option<f64>,
    #[serde(default)]
    pub orientation_max_deg: Option<f64>,
    #[serde(default)]
    pub orientation_std_deg: Option<f64>,
    #[serde(default)]
    pub orientation_rms_deg: Option<f64>,
    #[serde(default)]
    pub orientation_p95_deg: Option<f64>,
    #[serde(default)]
    pub errors_mm: Vec<Option<f64>>,
    #[serde(default)]
    pub errors_xyz_mm: Vec<[Option<f64>; 3]>,
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
    #[serde(default, deserialize_with = "lenient")]
    pub solver: Option<LmReport>,
    #[serde(flatten)]
    pub sets: SetsView,
    #[serde(default, deserialize_with = "lenient_list")]
    pub parameters: Vec<ParamEstimate>,
    #[serde(default)]
    pub stiffness_nm_per_rad: Vec<Option<f64>>,
    #[serde(default, deserialize_with = "lenient")]
    pub tlbo: Option<TlboView>,
    #[serde(default, deserialize_with = "lenient_list")]
    pub warnings: Vec<MethodWarning>,
    /// Errors on the compensator training pool (format 3).
    #[serde(default, deserialize_with = "lenient")]
    pub training: Option<SetView>,
    #[serde(default, deserialize_with = "lenient")]
    pub compensator: Option<CompensatorView>,
    #[serde(default, deserialize_with = "lenient")]
    pub auto: Option<AutoView>,
}

/// Statistics only (mm).
#[derive(Debug, Clone, Default, Deserialize)]
pub struct StatsView {
    #[serde(default)]
    pub mean_mm: Option<f64>,
    #[serde(default)]
    pub max_mm: Option<f64>,
}

/// Cross-validated errors of the base and the compensated model.
#[derive(Debug, Clone, Default, Deserialize)]
pub struct CvView {
    #[serde(default)]
    pub folds: Option<usize>,
    #[serde(default)]
    pub base: StatsView,
    #[serde(default)]
    pub compensated: StatsView,
    #[serde(default, deserialize_with = "lenient_list")]
    pub blocked: Vec<BlockedView>,
}

/// The training run of a compensator.
#[derive(Debug, Clone, Default, Deserialize)]
pub struct TrainView {
    #[serde(default)]
    pub trainer: String,
    #[serde(default)]
    pub epochs: Option<usize>,
    #[serde(default)]
    pub stop: String,
}

/// A compensator method's network, training and base errors (format 3).
#[derive(Debug, Clone, Default, Deserialize)]
pub struct CompensatorView {
    #[serde(default)]
    pub base: String,
    #[serde(default)]
    pub kind: String,
    #[serde(default)]
    pub units: Option<usize>,
    #[serde(default)]
    pub inputs: String,
    #[serde(default)]
    pub training: TrainView,
    #[serde(default)]
    pub trained_on: String,
    #[serde(default)]
    pub training_poses: Option<usize>,
    #[serde(default, deserialize_with = "lenient")]
    pub cross_validation: Option<CvView>,
    #[serde(default)]
    pub base_identification: Option<StatsView>,
    #[serde(default)]
    pub base_validation: Option<StatsView>,
    #[serde(default)]
    pub base_training: Option<StatsView>,
    #[serde(default, deserialize_with = "lenient_list")]
    pub trained_ranges_deg: Vec<[f64; 2]>,
    #[serde(default)]
    pub fade_deg: Option<f64>,
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
    #[serde(default)]
    pub status: String,
    #[serde(default)]
    pub reason: String,
}

/// The expected errors checked on the validation set.
#[derive(Debug, Clone, Default, Deserialize)]
pub struct UncertaintyView {
    #[serde(default)]
    pub poses: Option<usize>,
    #[serde(default)]
    pub mean_expected_mm: Option<f64>,
    #[serde(default)]
    pub rms_ratio: Option<f64>,
    #[serde(default)]
    pub above_expected: Option<f64>,
    #[serde(default)]
    pub above_twice_expected: Option<f64>,
}

/// A region of joint space held out whole in cross-validation.
#[derive(Debug, Clone, Default, Deserialize)]
pub struct BlockedView {
    #[serde(default)]
    pub poses: Option<usize>,
    #[serde(default)]
    pub centre: Vec<f64>,
    #[serde(default)]
    pub base_mean_mm: Option<f64>,
    #[serde(default)]
    pub compensated_mean_mm: Option<f64>,
}

/// What `auto` chose and why.
#[derive(Debug, Clone, Default, Deserialize)]
pub struct AutoView {
    #[serde(default)]
    pub chosen: String,
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
    #[serde(default)]
    pub tie: bool,
    #[serde(default)]
    pub step_label: String,
    #[serde(default)]
    pub runner_up: Option<String>,
    #[serde(default)]
    pub margin: f64,
    #[serde(default)]
    pub margin_unit: String,
    #[serde(default)]
    pub mean_margin_mm: f64,
    #[serde(default)]
    pub tie_margin: f64,
    #[serde(default)]
    pub fallback: Option<BaseFallbackView>,
    /// The blocked-fold veto's checks (absent in older reports).
    #[serde(default)]
    pub blocked_checks: Vec<BlockedCheckView>,
}

/// One option checked by the blocked-fold veto.
#[derive(Debug, Clone, Default, Deserialize)]
pub struct BlockedCheckView {
    #[serde(default)]
    pub option: String,
    #[serde(default)]
    pub base: String,
    #[serde(default)]
    pub verdict: String,
    #[serde(default)]
    pub verdict_label: String,
    #[serde(default)]
    pub regions: usize,
    #[serde(default)]
    pub poses: usize,
    #[serde(default)]
    pub option_blocked: BlockedFiguresView,
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
    #[serde(default)]
    pub joint: usize,
    #[serde(default)]
    pub side: String,
    #[serde(default)]
    pub poses: usize,
    #[serde(default)]
    pub option: BlockedFiguresView,
    #[serde(default)]
    pub base: BlockedFiguresView,
}

/// Held-out errors on the blocked regions [mm].
#[derive(Debug, Clone, Copy, Default, Deserialize)]
pub struct BlockedFiguresView {
    #[serde(default)]
    pub mean_mm: f64,
    #[serde(default)]
    pub max_mm: f64,
}

/// The better base that took over from an option on the weaker one.
#[derive(Debug, Clone, Default, Deserialize)]
pub struct BaseFallbackView {
    #[serde(default)]
    pub instead_of: String,
    #[serde(default)]
    pub weaker_base: String,
    #[serde(default)]
    pub better_base: String,
    #[serde(default)]
    pub weaker_mm: f64,
    #[serde(default)]
    pub better_mm: f64,
    #[serde(default)]
    pub measured_by: String,
}

/// TLBO convergence (cost per generation).
#[derive(Debug, Clone, Deserialize)]
pub struct TlboView {
    #[serde(default)]
    pub generations: Option<usize>,
    #[serde(default)]
    pub evaluations: Option<usize>,
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
