//! One method's run: [`run`] dispatches on the table's [`Run`], with what
//! every method needs ([`Context`]), the fits and compensators shared by the
//! methods of one calibration ([`Cache`]) and the progress of the method's
//! share of the bar ([`MethodProgress`]).

use super::auto::run_auto;
use super::compensated::{run_compensated, train_network, Trained};
use super::maps::run_maps;
use super::{Base, Method, MethodError, MethodFailure, Network, Run};
use crate::calibrate::identify::identifiability::DroppedParam;
use crate::calibrate::identify::joint_maps::MapFit;
use crate::calibrate::identify::least_squares::Fit;
use crate::calibrate::identify::options::{CalibrationOptions, Progress};
use crate::calibrate::identify::report::{AutoSummary, TlboSummary};
use crate::measure::Measurement;
use crate::model::kinematics::Chain;
use crate::model::{ParamId, RobotModel};
use std::collections::BTreeMap;

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
    pub fn pool(&self) -> (&[Measurement], &'static str) {
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

/// A trained compensator on top of the fit of its base.
pub(crate) struct AppliedCompensator {
    pub method: Method,
    pub base: Base,
    pub trained: Trained,
}

/// Runs `method` (its row's [`Run`]).
pub(crate) fn run(
    method: Method,
    ctx: &Context,
    cache: &mut Cache,
    progress: &MethodProgress,
) -> Result<Outcome, MethodError> {
    let mut lm = |it: usize, rms: f64| progress.lm(it, rms);
    match method.row().run {
        Run::Km => cache.base_fit(ctx, Base::Km, &mut lm).map(Outcome::plain),
        Run::Skcm => cache.base_fit(ctx, Base::Skcm, &mut lm).map(Outcome::plain),
        Run::SkcmTlbo => {
            let warm = match &cache.km {
                Some(f) => f.clone(),
                None => ctx.km(&mut lm)?,
            };
            ctx.skcm_tlbo(&warm, &mut |gen, best| progress.generation(gen, best))
                .map(Outcome::plain)
        }
        Run::SkcmPayload => cache
            .base_fit(ctx, Base::Skcm, &mut lm)
            .and_then(|s| ctx.skcm_payload(&s.fit, &mut lm))
            .map(Outcome::plain),
        Run::Maps(base) => run_maps(ctx, cache, base, &mut |f, it, loss| {
            progress.fraction(f, it, loss)
        }),
        Run::Compensated(c) => run_compensated(ctx, cache, method, c, &mut |f, it, loss| {
            progress.fraction(f, it, loss)
        }),
        Run::Auto => run_auto(ctx, cache, &mut |f, it, loss| {
            progress.fraction(f, it, loss)
        }),
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
    fn say(&self, iteration: usize, percent: f64, rms_mm: Option<f64>) -> bool {
        (self.sink)(&Progress {
            phase: self.method.name().to_string(),
            iteration,
            percent,
            rms_mm,
        })
    }

    /// LM iteration `it` of at most `LmSettings::max_iterations`.
    pub fn lm(&self, it: usize, rms: f64) -> bool {
        let max_it = self.opts.lm.max_iterations.max(1) as f64;
        self.say(
            it,
            self.start + self.span * (it as f64 / max_it).min(1.0),
            Some(rms),
        )
    }

    /// TLBO generation `gen` (0-based) with the best eq. 7.10 cost [mm²].
    pub fn generation(&self, gen: usize, best: f64) -> bool {
        let generations = self.opts.tlbo.generations.max(1) as f64;
        self.say(
            gen,
            self.start + self.span * (gen as f64 + 1.0) / generations,
            Some(best.sqrt()),
        )
    }

    /// A fraction in [0, 1] of the method done.
    pub fn fraction(&self, f: f64, it: usize, loss: Option<f64>) -> bool {
        self.say(it, self.start + self.span * f.clamp(0.0, 1.0), loss)
    }
}

/// Fits and trained compensators shared by the methods of one run: a base or
/// a compensator needed by several methods is computed once (a failure too).
#[derive(Default)]
pub(crate) struct Cache {
    km: Option<Fit>,
    skcm: Option<Result<MethodFit, MethodFailure>>,
    trained: BTreeMap<(Method, usize), Result<Trained, MethodFailure>>,
    /// Joint-map fits per base (`km-maps` and `auto` share them).
    pub(super) maps: Vec<(Base, Result<MethodFit, MethodFailure>)>,
}

impl Cache {
    /// The fit of a base method, computed on first use.
    pub fn base_fit(
        &mut self,
        ctx: &Context,
        base: Base,
        progress: &mut dyn FnMut(usize, f64) -> bool,
    ) -> Result<MethodFit, MethodError> {
        match base {
            Base::Km => {
                let fit = match &self.km {
                    Some(f) => f.clone(),
                    None => self.km.insert(ctx.km(progress)?).clone(),
                };
                Ok(MethodFit {
                    fit,
                    ids: ctx.kept_geo.clone(),
                    tlbo: None,
                    not_identified: vec![],
                    maps: None,
                })
            }
            Base::KmMaps | Base::SkcmMaps => {
                let inner = if base == Base::KmMaps {
                    Base::Km
                } else {
                    Base::Skcm
                };
                run_maps(ctx, self, inner, &mut |_, it, l| {
                    progress(it, l.unwrap_or(f64::NAN))
                })
                .map(|o| o.fit)
            }
            Base::Skcm => {
                let skcm = match &self.skcm {
                    Some(r) => r,
                    None => match ctx.skcm(progress) {
                        Ok(mf) => self.skcm.insert(Ok(mf)),
                        Err(MethodError::Failed(f)) => self.skcm.insert(Err(f)),
                        Err(MethodError::Cancelled) => return Err(MethodError::Cancelled),
                    },
                };
                skcm.clone().map_err(MethodError::Failed)
            }
        }
    }

    /// `method`'s compensator `network` on the fit `base` and the training
    /// pool, with `folds`-fold cross-validation, trained on first use.
    pub fn trained(
        &mut self,
        ctx: &Context,
        method: Method,
        network: Network,
        base: &Fit,
        folds: usize,
        progress: &mut dyn FnMut(usize, usize, f64) -> bool,
    ) -> Result<Trained, MethodError> {
        if let Some(t) = self.trained.get(&(method, folds)) {
            return t.clone().map_err(MethodError::Failed);
        }
        let r = match train_network(network, base, ctx, folds, progress) {
            Err(MethodError::Cancelled) => return Err(MethodError::Cancelled),
            Err(MethodError::Failed(f)) => Err(f),
            Ok(t) => Ok(t),
        };
        self.trained.insert((method, folds), r.clone());
        r.map_err(MethodError::Failed)
    }
}
