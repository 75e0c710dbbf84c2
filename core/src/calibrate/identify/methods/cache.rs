//! Fits and trained compensators shared by the methods of one calibration
//! ([`Cache`]): a base or a compensator several methods need is computed
//! once, and a failure is kept as a result too. The model-based bases are
//! fitted here; a joint-map base by [`super::maps::base_fit`] and a
//! compensator by [`super::compensated::trained`], each into its slot.

use super::context::{Context, MethodFit};
use super::trained::Trained;
use super::{Base, Method, MethodError, MethodFailure};
use crate::calibrate::identify::joint_maps::MapStructure;
use crate::calibrate::identify::least_squares::Fit;
use std::collections::BTreeMap;

/// Fits and trained compensators shared by the methods of one run: a base or
/// a compensator needed by several methods is computed once (a failure too).
#[derive(Default)]
pub(crate) struct Cache {
    km: Option<Fit>,
    skcm: Option<Result<MethodFit, MethodFailure>>,
    pub(super) trained: BTreeMap<(Method, usize), Result<Trained, MethodFailure>>,
    /// Joint-map fits per base and structure (`km-maps` and `auto` share
    /// the cross-validated ones).
    pub(super) maps: Vec<(Base, MapStructure, Result<MethodFit, MethodFailure>)>,
}

impl Cache {
    /// The bases it holds a fit (or failure) of and the compensators, with
    /// their folds, it holds a training of (for `plan::Planner`).
    pub(crate) fn held(&self) -> (Vec<Base>, Vec<(Method, usize)>) {
        let mut bases = Vec::new();
        if self.km.is_some() {
            bases.push(Base::Km);
        }
        if self.skcm.is_some() {
            bases.push(Base::Skcm);
        }
        // A structure held fixed is a refit of the veto, not the method's fit.
        for (b, ..) in self
            .maps
            .iter()
            .filter(|(_, s, _)| *s == MapStructure::CrossValidated)
        {
            bases.push(if *b == Base::Km {
                Base::KmMaps
            } else {
                Base::SkcmMaps
            });
        }
        (bases, self.trained.keys().copied().collect())
    }

    /// The KM fit, if a method has computed it.
    pub(crate) fn km(&self) -> Option<&Fit> {
        self.km.as_ref()
    }

    /// The KM fit, computed on first use.
    pub(crate) fn km_fit(
        &mut self,
        ctx: &Context,
        progress: &mut dyn FnMut(usize, f64) -> bool,
    ) -> Result<MethodFit, MethodError> {
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

    /// The SKCM fit, computed on first use (a failure is kept).
    pub(crate) fn skcm_fit(
        &mut self,
        ctx: &Context,
        progress: &mut dyn FnMut(usize, f64) -> bool,
    ) -> Result<MethodFit, MethodError> {
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
