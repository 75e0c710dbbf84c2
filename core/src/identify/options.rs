//! What a calibration runs and with which settings: the methods, the solver
//! settings, the plausibility range of identified stiffness, and the progress
//! reported while it runs.
//!
//! Units: SI inside (N·m/rad for stiffness, rad for deflections); the report
//! speaks mm and deg.

use super::identifiability::IdentifiabilitySettings;
use super::least_squares::LmSettings;
use super::tlbo::TlboSettings;
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
}

const KNOWN: &str = "km, skcm, skcm-tlbo, skcm-payload";

impl Method {
    /// Every method.
    pub const ALL: [Method; 4] = [
        Method::Km,
        Method::Skcm,
        Method::SkcmTlbo,
        Method::SkcmPayload,
    ];
    /// The seed's three methods (the default of `robocal calibrate`).
    pub const SEED: [Method; 3] = [Method::Km, Method::Skcm, Method::SkcmTlbo];

    pub fn name(&self) -> &'static str {
        match self {
            Method::Km => "km",
            Method::Skcm => "skcm",
            Method::SkcmTlbo => "skcm-tlbo",
            Method::SkcmPayload => "skcm-payload",
        }
    }

    /// Whether the method identifies joint compliance (needs gravity torques).
    pub fn uses_compliance(&self) -> bool {
        *self != Method::Km
    }

    pub fn parse(s: &str) -> Option<Method> {
        match s.trim().to_ascii_lowercase().as_str() {
            "km" => Some(Method::Km),
            "skcm" => Some(Method::Skcm),
            "skcm-tlbo" | "skcm-c" | "skcm_tlbo" | "tlbo" => Some(Method::SkcmTlbo),
            "skcm-payload" | "skcm_payload" => Some(Method::SkcmPayload),
            _ => None,
        }
    }

    /// Parses a comma-separated list, naming any unknown entry.
    pub fn parse_list(s: &str) -> Result<Vec<Method>, String> {
        let mut out = Vec::new();
        for part in s.split(',').filter(|p| !p.trim().is_empty()) {
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
