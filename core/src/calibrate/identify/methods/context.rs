//! What every method of one calibration shares: its inputs ([`Context`], data
//! in the registered base frame, SI units), a model-based fit before it is
//! reported ([`MethodFit`]), what a method delivers ([`Outcome`]) and the
//! progress of its share of the bar ([`MethodProgress`]).

use super::trained::AppliedCompensator;
use super::{Method, MethodFailure};
use crate::calibrate::identify::identifiability::DroppedParam;
use crate::calibrate::identify::joint_maps::MapFit;
use crate::calibrate::identify::least_squares::Fit;
use crate::calibrate::identify::options::CalibrationOptions;
use crate::calibrate::identify::progress::{Fold, Phase, Progress};
use crate::calibrate::identify::report::{AutoSummary, TlboSummary};
use crate::measure::Measurement;
use crate::model::kinematics::Chain;
use crate::model::{ParamId, RobotModel};

/// What every method needs. Data are in the registered base frame.
pub(crate) struct Context<'a> {
    pub nominal: &'a RobotModel,
    /// The nominal model with zero compliance: every method's start.
    pub start: RobotModel,
    pub ident: &'a [Measurement],
    /// Forward kinematics of `ident` at its commanded joints on the nominal
    /// geometry (that of `start`), for the first evaluation of a fit from `start`.
    pub ident_chains: &'a [Chain],
    pub valid: &'a [Measurement],
    /// The compensators' training poses (Q2; empty: none given).
    pub training: &'a [Measurement],
    pub sessions: usize,
    pub kept_geo: Vec<ParamId>,
    pub kept_c: Vec<ParamId>,
    /// Why gravity loads no joint, if so (no compliance, no torque inputs).
    pub gravity: Option<MethodFailure>,
    pub opts: &'a CalibrationOptions,
}

impl Context<'_> {
    /// The compensators' training pool and its set's name: Q2, else Q1.
    pub(crate) fn pool(&self) -> (&[Measurement], &'static str) {
        if self.training.is_empty() {
            (self.ident, "identification")
        } else {
            (self.training, "training")
        }
    }
}

/// A model-based fit before it is reported.
#[derive(Clone)]
pub(crate) struct MethodFit {
    pub fit: Fit,
    pub ids: Vec<ParamId>,
    pub tlbo: Option<TlboSummary>,
    /// Parameters the method considered but could not identify.
    pub not_identified: Vec<DroppedParam>,
    /// The joint maps' fit and choice (joint-map methods).
    pub maps: Option<MapFit>,
}

/// What a method delivers before it is reported.
pub(crate) struct Outcome {
    pub fit: MethodFit,
    pub compensator: Option<AppliedCompensator>,
    pub auto: Option<AutoSummary>,
}

impl Outcome {
    pub(crate) fn plain(fit: MethodFit) -> Self {
        Outcome {
            fit,
            compensator: None,
            auto: None,
        }
    }
}

/// One step of a method's progress within its own share of the bar.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Step {
    /// The method's work done, in [0, 1].
    pub fraction: f64,
    pub iteration: usize,
    pub loss: Option<f64>,
    /// The candidate worked on (`auto`).
    pub candidate: Option<Method>,
    /// The cross-validation training under way.
    pub fold: Option<Fold>,
}

impl Step {
    /// A step at `fraction` with no candidate and no fold.
    pub(crate) fn plain(fraction: f64, iteration: usize, loss: Option<f64>) -> Self {
        Step {
            fraction,
            iteration,
            loss,
            candidate: None,
            fold: None,
        }
    }
}

/// Progress of one method over its span of the bar [%], reported under its
/// name.
pub(crate) struct MethodProgress<'a> {
    pub method: Method,
    /// Where its span starts and how wide it is [%].
    pub start: f64,
    pub span: f64,
    pub opts: &'a CalibrationOptions,
    pub sink: &'a dyn Fn(&Progress) -> bool,
}

impl MethodProgress<'_> {
    /// LM iteration `it` of at most `LmSettings::max_iterations`.
    pub(crate) fn lm(&self, it: usize, rms: f64) -> bool {
        let max_it = self.opts.lm.max_iterations.max(1) as f64;
        self.fraction(it as f64 / max_it, it, Some(rms))
    }

    /// TLBO generation `gen` (0-based) with the best eq. 7.10 cost [mm²].
    pub(crate) fn generation(&self, gen: usize, best: f64) -> bool {
        let generations = self.opts.tlbo.generations.max(1) as f64;
        self.fraction((gen as f64 + 1.0) / generations, gen, Some(best.sqrt()))
    }

    /// A fraction in [0, 1] of the method done.
    pub(crate) fn fraction(&self, f: f64, it: usize, loss: Option<f64>) -> bool {
        self.step(&Step::plain(f, it, loss))
    }

    /// A step of the method, with its candidate and fold.
    pub(crate) fn step(&self, s: &Step) -> bool {
        let f = if s.fraction.is_finite() {
            s.fraction.clamp(0.0, 1.0)
        } else {
            0.0
        };
        (self.sink)(&Progress {
            iteration: s.iteration,
            rms_mm: s.loss,
            candidate: s.candidate,
            fold: s.fold,
            ..Progress::at(Phase::Method(self.method), self.start + self.span * f)
        })
    }
}
