//! What a calibration runs and with which settings: the methods, the solver
//! settings, the compensator settings, the plausibility range of identified
//! stiffness (the progress reported while it runs is `super::progress`).
//!
//! Two types: [`CalibrationSettings`], what a user chooses (the HTTP request,
//! the command line and a stored job all convert into it once), and
//! [`CalibrationOptions`], everything a calibration reads, which
//! [`CalibrationSettings::options`] alone builds from the settings.
//!
//! Units: SI inside (N·m/rad for stiffness, rad for deflections); the report
//! speaks mm and deg.

use super::identifiability::IdentifiabilitySettings;
use super::joint_maps::JointMapSettings;
use super::least_squares::LmSettings;
pub use super::methods::Method;
pub use super::progress::Progress;
use crate::calibrate::compensate::select::Parallelism;
use crate::calibrate::compensate::{
    GpSettings, IwoSettings, LmTrainSettings, MlpSpec, RbfSettings, TlboTrainSettings,
};
use crate::optim::TlboSettings;
use serde::{Deserialize, Serialize};

/// What a user chooses of a calibration: the methods and the settings a
/// request, a command line or a stored job may set. Every field has the
/// default of [`CalibrationSettings::default`] (the core's own), so a stored
/// form written before a field existed still reads; an unknown field is
/// refused.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CalibrationSettings {
    /// The methods to run and compare, in order.
    pub methods: Vec<Method>,
    /// Register the measurement frame in closed form first (off only when
    /// the data is already in the base frame and should stay there exactly).
    pub register: bool,
    /// Seed of every random choice: the TLBO search and the compensators'
    /// initial weights, subsamples and folds.
    pub seed: u64,
    /// Levenberg–Marquardt iteration limit of the identification.
    pub max_iterations: usize,
    /// TLBO population (skcm-tlbo).
    pub population: usize,
    /// TLBO generations (skcm-tlbo).
    pub generations: usize,
    /// Folds of the compensators' cross-validation on the training pool
    /// ([`CompensatorOptions::cv_folds`]).
    pub cv_folds: usize,
    /// Spatially blocked folds run with the cross-validation
    /// ([`CompensatorOptions::blocked_folds`]).
    pub blocked_folds: usize,
    /// The fraction within which `auto`'s options tie
    /// ([`CompensatorOptions::tie_margin`]).
    pub tie_margin: f64,
    /// The joint-map and compensator methods `auto` considers.
    pub auto_candidates: Vec<Method>,
}

impl Default for CalibrationSettings {
    /// The core's defaults: [`Method::THESIS`], registration on, seed 0, and
    /// each setting as [`CalibrationOptions::default`] holds it.
    fn default() -> Self {
        let d = CalibrationOptions::default();
        CalibrationSettings {
            methods: d.methods,
            register: d.register,
            seed: d.tlbo.seed,
            max_iterations: d.lm.max_iterations,
            population: d.tlbo.population,
            generations: d.tlbo.generations,
            cv_folds: d.compensator.cv_folds,
            blocked_folds: d.compensator.blocked_folds,
            tie_margin: d.compensator.tie_margin,
            auto_candidates: d.compensator.auto_candidates,
        }
    }
}

impl CalibrationSettings {
    /// The options a calibration runs with: these settings where they act
    /// (the one seed seeds both the TLBO search and the compensators), the
    /// core's defaults elsewhere, and the threads its cross-validations
    /// (the compensators' and the joint maps') run on (`parallel`: the
    /// caller's, never a user's stored choice).
    pub fn options(&self, parallel: Parallelism) -> CalibrationOptions {
        let d = CalibrationOptions::default();
        CalibrationOptions {
            methods: self.methods.clone(),
            register: self.register,
            lm: LmSettings {
                max_iterations: self.max_iterations,
                ..d.lm
            },
            tlbo: TlboSettings {
                population: self.population,
                generations: self.generations,
                seed: self.seed,
            },
            compensator: CompensatorOptions {
                seed: self.seed,
                cv_folds: self.cv_folds,
                blocked_folds: self.blocked_folds,
                tie_margin: self.tie_margin,
                auto_candidates: self.auto_candidates.clone(),
                parallel,
                ..d.compensator
            },
            joint_maps: JointMapSettings {
                parallel,
                ..d.joint_maps
            },
            ..d
        }
    }
}

/// Everything a calibration reads; built from [`CalibrationSettings`] by
/// [`CalibrationSettings::options`], or whole by the core's tests and
/// benches.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CalibrationOptions {
    /// The methods to run, in the order given.
    pub methods: Vec<Method>,
    /// Register the measurement frame in closed form first (off only when the
    /// data is already in the base frame and should stay there exactly).
    pub register: bool,
    /// Levenberg–Marquardt settings of every model-based fit.
    pub lm: LmSettings,
    /// TLBO settings of SKCM-C's compliance search (`skcm-tlbo`, ch. 7).
    pub tlbo: TlboSettings,
    /// Which parameters are identified (`identifiability`).
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
    /// The joint-map methods' fit ([`Method::JOINT_MAPS`]).
    #[serde(default)]
    pub joint_maps: JointMapSettings,
}

/// Settings of the compensator methods ([`Method::COMPENSATED`]) and of `auto`.
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
    /// Spatially blocked folds run with the cross-validation (whole regions
    /// of joint space held out, `compensate::select`); `auto` rejects a
    /// compensator that makes any of them worse than its base. 0 skips them.
    pub blocked_folds: usize,
    /// `auto` takes a compensator only when its cross-validated mean is at
    /// least this fraction below its base's (and its max not above).
    pub min_gain: f64,
    /// `auto`'s options whose cross-validated means differ by less than this
    /// fraction (relative to the lower) are a tie, broken by the blocked
    /// folds, the max, the physics of the base and the count of fitted
    /// quantities (`methods::ties`); the later steps compare within the
    /// same margin. The default is `min_gain`'s: a difference `auto` would
    /// not take a compensator for does not choose between options either.
    pub tie_margin: f64,
    /// With fewer training poses `auto` keeps the base without training.
    pub min_training_poses: usize,
    /// The joint-map and compensator methods `auto` considers.
    pub auto_candidates: Vec<Method>,
    /// The RBF compensator (`Network::Rbf`).
    pub rbf: RbfSettings,
    /// Network of SKCM-NN (`MlpSize::Nn` in the method table).
    pub nn: MlpSpec,
    /// LM backpropagation of SKCM-NN's network (`MlpTrainer::Lm`).
    pub lm: LmTrainSettings,
    /// Network of SKCM-IWONN and SKCM-TLBONN (`MlpSize::Small` in the
    /// method table; `MlpSpec::POPULATION`).
    pub small: MlpSpec,
    /// Invasive weed optimisation of SKCM-IWONN's network (`MlpTrainer::Iwo`).
    pub iwo: IwoSettings,
    /// TLBO of SKCM-TLBONN's network (`MlpTrainer::Tlbo`).
    pub tlbo: TlboTrainSettings,
    /// The Gaussian-process compensator (`Network::Gp`).
    pub gp: GpSettings,
    /// The networks (MLP, RBF) train and cross-validate on at most this many
    /// poses of the pool, a seeded subsample beyond it: their training grows
    /// with the square of the poses, the Gaussian process's linearly (it takes
    /// every pose). 0: no limit.
    pub max_network_poses: usize,
    /// Threads the trainings of one cross-validation (its folds and the
    /// final training) run on; results do not depend on it. Set by the
    /// caller (the service shares the cores among its calibration workers),
    /// not by a request.
    #[serde(skip)]
    pub parallel: Parallelism,
}

impl Default for CompensatorOptions {
    fn default() -> Self {
        CompensatorOptions {
            seed: 1,
            cv_folds: 5,
            blocked_folds: 4,
            min_gain: 0.05,
            tie_margin: 0.05,
            min_training_poses: 20,
            auto_candidates: Method::JOINT_MAPS
                .iter()
                .chain(&Method::COMPENSATED)
                .copied()
                .collect(),
            rbf: RbfSettings::default(),
            nn: MlpSpec::SKCM_NN,
            lm: LmTrainSettings::default(),
            small: MlpSpec::POPULATION,
            iwo: IwoSettings::default(),
            tlbo: TlboTrainSettings::default(),
            gp: GpSettings::default(),
            max_network_poses: 1000,
            parallel: Parallelism::default(),
        }
    }
}

impl CompensatorOptions {
    /// Trainings of one cross-validated compensator: the random folds, the
    /// blocked ones and the final training.
    pub fn cv_stages(&self, folds: usize) -> usize {
        if folds == 0 {
            1
        } else {
            folds + self.blocked_folds + 1
        }
    }
}

impl Default for CalibrationOptions {
    fn default() -> Self {
        CalibrationOptions {
            methods: Method::THESIS.to_vec(),
            register: true,
            lm: LmSettings::default(),
            tlbo: TlboSettings::default(),
            identifiability: IdentifiabilitySettings::default(),
            max_nominal_rms_mm: 250.0,
            tlbo_max_deflection_rad: 0.01,
            plausible_stiffness_nm_per_rad: [1e3, 1e9],
            compensator: CompensatorOptions::default(),
            joint_maps: JointMapSettings::default(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each setting lands where the calibration reads it, and nothing else
    /// moves from the core's defaults.
    #[test]
    fn the_settings_build_the_options_they_name() {
        let s = CalibrationSettings {
            methods: vec![Method::Skcm, Method::Km],
            register: false,
            seed: 42,
            max_iterations: 7,
            population: 12,
            generations: 3,
            cv_folds: 2,
            blocked_folds: 0,
            tie_margin: 0.2,
            auto_candidates: vec![Method::KmMaps],
        };
        let o = s.options(Parallelism { threads: 3 });
        let d = CalibrationOptions::default();
        let want = CalibrationOptions {
            methods: vec![Method::Skcm, Method::Km],
            register: false,
            lm: LmSettings {
                max_iterations: 7,
                ..d.lm.clone()
            },
            tlbo: TlboSettings {
                population: 12,
                generations: 3,
                seed: 42,
            },
            compensator: CompensatorOptions {
                seed: 42,
                cv_folds: 2,
                blocked_folds: 0,
                tie_margin: 0.2,
                auto_candidates: vec![Method::KmMaps],
                parallel: Parallelism { threads: 3 },
                ..d.compensator.clone()
            },
            joint_maps: JointMapSettings {
                parallel: Parallelism { threads: 3 },
                ..d.joint_maps.clone()
            },
            ..d
        };
        assert_eq!(o, want);
    }

    /// The default settings are the core's defaults but for the one seed,
    /// which seeds the compensators too (the options' own default is 1).
    #[test]
    fn the_default_settings_are_the_core_defaults_with_one_seed() {
        let o = CalibrationSettings::default().options(Parallelism::default());
        let d = CalibrationOptions::default();
        assert_eq!(d.compensator.seed, 1);
        let want = CalibrationOptions {
            compensator: CompensatorOptions {
                seed: 0,
                ..d.compensator.clone()
            },
            ..d
        };
        assert_eq!(o, want);
    }

    /// A stored form that names no setting reads as the defaults; one that
    /// names an unknown field is refused.
    #[test]
    fn the_stored_settings_fill_defaults_and_refuse_unknown_fields() {
        let s: CalibrationSettings = serde_json::from_str(r#"{"seed": 5}"#).unwrap();
        assert_eq!(
            s,
            CalibrationSettings {
                seed: 5,
                ..CalibrationSettings::default()
            }
        );
        assert!(serde_json::from_str::<CalibrationSettings>(r#"{"sed": 5}"#).is_err());
    }
}
