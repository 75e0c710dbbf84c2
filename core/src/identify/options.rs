//! What a calibration runs and with which settings: the methods, the solver
//! settings, the compensator settings, the plausibility range of identified
//! stiffness, and the progress reported while it runs.
//!
//! Units: SI inside (N·m/rad for stiffness, rad for deflections); the report
//! speaks mm and deg.

use super::identifiability::IdentifiabilitySettings;
use super::least_squares::LmSettings;
use crate::compensate::{
    CompensatorSpec, IwoSettings, LmTrainSettings, MlpSpec, RbfSettings, TlboTrainSettings, Trainer,
};
use crate::optim::TlboSettings;
use serde::{Deserialize, Serialize};

/// A calibration method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Kinematic calibration, §2.2.
    Km,
    /// Simultaneous kinematic and compliance calibration, §2.3.
    Skcm,
    /// SKCM with the compliance searched by TLBO, ch. 7.
    SkcmTlbo,
    /// SKCM with the payload's centre of mass identified jointly (beyond the
    /// seed, which assumes it known).
    SkcmPayload,
    /// KM, then an RBF network on the gravity torques (ch. 3).
    KmRbf,
    /// SKCM, then an MLP trained by LM backpropagation (ch. 4).
    SkcmNn,
    /// SKCM, then the 6-5-3 MLP trained by invasive weed optimisation (ch. 5).
    SkcmIwonn,
    /// SKCM, then the 6-5-3 MLP trained by TLBO (ch. 6).
    SkcmTlbonn,
    /// The base (KM or SKCM) with the compensator chosen by cross-validated
    /// error, or the base alone when no compensator is better on both mean and
    /// max (`compensate::select`).
    Auto,
}

const KNOWN: &str =
    "km, skcm, skcm-tlbo, skcm-payload, km-rbf, skcm-nn, skcm-iwonn, skcm-tlbonn, auto, all";

impl Method {
    /// Every method (`--method all`, the `compare` table).
    pub const ALL: [Method; 9] = [
        Method::Km,
        Method::Skcm,
        Method::SkcmTlbo,
        Method::SkcmPayload,
        Method::KmRbf,
        Method::SkcmNn,
        Method::SkcmIwonn,
        Method::SkcmTlbonn,
        Method::Auto,
    ];
    /// The model-based methods (no compensator).
    pub const MODEL_BASED: [Method; 4] = [
        Method::Km,
        Method::Skcm,
        Method::SkcmTlbo,
        Method::SkcmPayload,
    ];
    /// The seed's three methods (the default of `robocal calibrate`).
    pub const SEED: [Method; 3] = [Method::Km, Method::Skcm, Method::SkcmTlbo];
    /// The methods with a learned compensator.
    pub const COMPENSATED: [Method; 4] = [
        Method::KmRbf,
        Method::SkcmNn,
        Method::SkcmIwonn,
        Method::SkcmTlbonn,
    ];

    pub fn name(&self) -> &'static str {
        match self {
            Method::Km => "km",
            Method::Skcm => "skcm",
            Method::SkcmTlbo => "skcm-tlbo",
            Method::SkcmPayload => "skcm-payload",
            Method::KmRbf => "km-rbf",
            Method::SkcmNn => "skcm-nn",
            Method::SkcmIwonn => "skcm-iwonn",
            Method::SkcmTlbonn => "skcm-tlbonn",
            Method::Auto => "auto",
        }
    }

    /// The model-based method a compensator method builds on.
    pub fn base(&self) -> Option<Method> {
        match self {
            Method::KmRbf => Some(Method::Km),
            Method::SkcmNn | Method::SkcmIwonn | Method::SkcmTlbonn => Some(Method::Skcm),
            _ => None,
        }
    }

    /// Whether the method identifies joint compliance (needs gravity torques).
    /// `auto` decides for itself which bases it can run.
    pub fn uses_compliance(&self) -> bool {
        match self {
            Method::Km | Method::KmRbf | Method::Auto => false,
            m => m.base().is_none_or(|b| b.uses_compliance()),
        }
    }

    /// Whether the method needs gravity torques on some joint (compliance, or
    /// the torque-input RBF).
    pub fn uses_torques(&self) -> bool {
        self.uses_compliance() || *self == Method::KmRbf
    }

    pub fn parse(s: &str) -> Option<Method> {
        match s.trim().to_ascii_lowercase().as_str() {
            "km" => Some(Method::Km),
            "skcm" => Some(Method::Skcm),
            "skcm-tlbo" | "skcm-c" | "skcm_tlbo" | "tlbo" => Some(Method::SkcmTlbo),
            "skcm-payload" | "skcm_payload" => Some(Method::SkcmPayload),
            "km-rbf" | "km_rbf" => Some(Method::KmRbf),
            "skcm-nn" | "skcm_nn" => Some(Method::SkcmNn),
            "skcm-iwonn" | "skcm_iwonn" => Some(Method::SkcmIwonn),
            "skcm-tlbonn" | "skcm_tlbonn" => Some(Method::SkcmTlbonn),
            "auto" => Some(Method::Auto),
            _ => None,
        }
    }

    /// Parses a comma-separated list, naming any unknown entry; `all` stands
    /// for every method ([`Method::ALL`]).
    pub fn parse_list(s: &str) -> Result<Vec<Method>, String> {
        let mut out = Vec::new();
        for part in s.split(',').filter(|p| !p.trim().is_empty()) {
            if part.trim().eq_ignore_ascii_case("all") {
                for m in Method::ALL {
                    if !out.contains(&m) {
                        out.push(m);
                    }
                }
                continue;
            }
            let m = Method::parse(part)
                .ok_or_else(|| format!("unknown method `{}` (known: {KNOWN})", part.trim()))?;
            if !out.contains(&m) {
                out.push(m);
            }
        }
        if out.is_empty() {
            return Err(format!("no method given (known: {KNOWN})"));
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
    /// Identified joint stiffness outside `[low, high]` [N·m/rad] is reported as
    /// a warning (physically implausible for an industrial joint).
    pub plausible_stiffness_nm_per_rad: [f64; 2],
    /// Training, cross-validation and choice of the learned compensators.
    #[serde(default)]
    pub compensator: CompensatorOptions,
}

/// Settings of the compensator methods (`km-rbf`, `skcm-nn`, `skcm-iwonn`,
/// `skcm-tlbonn`) and of `auto`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct CompensatorOptions {
    /// Seed of every random draw of the compensators (initial weights,
    /// held-out splits, folds).
    pub seed: u64,
    /// Folds of the cross-validation on the training pool (reported for every
    /// compensator method; `auto` chooses by it). 0 skips it for the explicit
    /// methods (`auto` then uses 5).
    pub cv_folds: usize,
    /// `auto` takes a compensator only when its cross-validated mean is at
    /// least this fraction below its base's (and its max not above).
    pub min_gain: f64,
    /// With fewer training poses `auto` keeps the base without training.
    pub min_training_poses: usize,
    /// The compensator methods `auto` considers.
    pub auto_candidates: Vec<Method>,
    pub rbf: RbfSettings,
    /// Network of SKCM-NN.
    pub nn: MlpSpec,
    pub lm: LmTrainSettings,
    /// Network of SKCM-IWONN and SKCM-TLBONN (`MlpSpec::POPULATION`).
    pub small: MlpSpec,
    pub iwo: IwoSettings,
    pub tlbo: TlboTrainSettings,
}

impl Default for CompensatorOptions {
    fn default() -> Self {
        CompensatorOptions {
            seed: 1,
            cv_folds: 5,
            min_gain: 0.05,
            min_training_poses: 20,
            auto_candidates: Method::COMPENSATED.to_vec(),
            rbf: RbfSettings::default(),
            nn: MlpSpec::SKCM_NN,
            lm: LmTrainSettings::default(),
            small: MlpSpec::POPULATION,
            iwo: IwoSettings::default(),
            tlbo: TlboTrainSettings::default(),
        }
    }
}

impl CompensatorOptions {
    /// The compensator of a compensator method.
    pub fn spec(&self, method: Method) -> Option<CompensatorSpec> {
        Some(match method {
            Method::KmRbf => CompensatorSpec::Rbf(self.rbf.clone()),
            Method::SkcmNn => CompensatorSpec::Mlp {
                spec: self.nn,
                trainer: Trainer::Lm(self.lm.clone()),
            },
            Method::SkcmIwonn => CompensatorSpec::Mlp {
                spec: self.small,
                trainer: Trainer::Iwo(self.iwo.clone()),
            },
            Method::SkcmTlbonn => CompensatorSpec::Mlp {
                spec: self.small,
                trainer: Trainer::Tlbo(self.tlbo.clone()),
            },
            _ => return None,
        })
    }

    /// Epochs / iterations / generations a training run of `method` may take
    /// at most (for progress percentages).
    pub fn max_epochs(&self, method: Method) -> usize {
        match method {
            Method::KmRbf => (self.rbf.max_neurons + 1) * (self.rbf.spreads.len() + 1),
            Method::SkcmNn => self.lm.max_epochs,
            Method::SkcmIwonn => self.iwo.iterations,
            Method::SkcmTlbonn => self.tlbo.generations,
            _ => 1,
        }
        .max(1)
    }
}

impl Default for CalibrationOptions {
    fn default() -> Self {
        CalibrationOptions {
            methods: Method::SEED.to_vec(),
            register: true,
            lm: LmSettings::default(),
            tlbo: TlboSettings::default(),
            identifiability: IdentifiabilitySettings::default(),
            max_nominal_rms_mm: 250.0,
            tlbo_max_deflection_rad: 0.01,
            plausible_stiffness_nm_per_rad: [1e3, 1e9],
            compensator: CompensatorOptions::default(),
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
