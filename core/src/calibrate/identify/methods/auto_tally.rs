//! What `auto` weighs and gathers while it runs: the options (a base, its
//! joint maps and kept compensator, with their cross-validated figures in mm
//! and degrees) and the tally of progress, candidates and notes. Shared by
//! `auto` (which fills it) and `auto_choice` (which decides on it).

use super::context::{MethodFit, Step};
use super::plan::Planner;
use super::trained::AppliedCompensator;
use super::{Base, Method};
use crate::calibrate::identify::report::{AutoCandidate, OrientationPart};
/// Orientation means within this relative margin of each other count as
/// equal (the fit's noise); a larger excess is a loss `auto` does not accept.
pub(crate) const ORIENTATION_SLACK: f64 = 0.02;

/// One base as `auto` weighs it.
pub(super) struct BaseOption {
    pub base: Base,
    /// The joint-map method whose fit this is, if any.
    pub maps: Option<Method>,
    pub fit: MethodFit,
    /// The compensator `choose` kept, if any.
    pub compensator: Option<AppliedCompensator>,
    /// Cross-validated mean on the pool [mm] (the base's residual mean when
    /// nothing was trained).
    pub mean_mm: f64,
    /// Cross-validated max on the pool [mm] (the base's residual max when
    /// nothing was trained).
    pub max_mm: f64,
    /// Mean over the spatially blocked folds [mm] (`ties::Contender`).
    pub blocked_mm: Option<f64>,
    /// The base alone on the pool [mm]: its residual mean (base options
    /// only, `auto_choice`'s fallback).
    pub alone_mm: Option<f64>,
    /// Orientation mean of the option [deg]: the fit's on the pool, or the
    /// kept orientation part's cross-validated mean (none without
    /// orientation measurements).
    pub orientation_deg: Option<f64>,
    /// The kept compensator's orientation part, where orientation was
    /// measured.
    pub orientation_part: Option<OrientationPart>,
    pub reason: String,
}

/// What `auto` gathers while it runs: the progress bar's position, the
/// options it weighs, the candidates it lists and its notes.
pub(super) struct Tally<'p> {
    pub progress: &'p mut dyn FnMut(&Step) -> bool,
    /// Units of work done (`plan::Planner`), of `total`; `plan` knows what
    /// is done or cached.
    pub done: f64,
    pub total: f64,
    pub plan: Planner,
    pub notes: Vec<String>,
    pub candidates: Vec<AutoCandidate>,
    pub options: Vec<BaseOption>,
    /// Per base (KM, SKCM) whose joint maps ran, the mean of its geometry
    /// alone on the maps' spatially blocked folds [mm].
    pub geometry_blocked: Vec<(Base, f64)>,
    /// Options the blocked-fold veto set aside (`auto_choice::apply_veto`).
    pub vetoed: Vec<usize>,
}
