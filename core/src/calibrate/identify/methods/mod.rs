//! The calibration methods as one table, [`METHODS`]: per method its name and
//! aliases, display label, a description, what it fits, whether it identifies
//! compliance or needs gravity torques, its share of the progress bar and how
//! it runs ([`Run`]; a compensator method's base and network, the network
//! naming which of the options' settings it trains with, `network::Network`). Every list of methods derives from it: [`Method::ALL`]
//! and the groups, parsing with aliases, the command line's values, the
//! report's labels and (checked by a test) the spec's enums.
//!
//! The methods themselves: `model_based` (KM §2.2, SKCM §2.3, SKCM-C by TLBO
//! ch. 7, SKCM-payload), `compensated` (a learned compensator on a base,
//! ch. 3–6), `maps` (joint maps), `auto`; `run` dispatches one method, `cache`
//! shares fits and compensators between the methods of a calibration, `plan`
//! sizes their work for the progress bar,
//! `context` holds what they all read and `trained` a trained compensator;
//! `veto` and `delivered` judge `auto`'s choice as delivered on blocked regions;
//! `report` turns a fit into its report.

mod auto;
mod auto_choice;
mod auto_tally;
mod cache;
mod compensated;
mod context;
mod delivered;
mod failure;
#[cfg(test)]
mod fixture;
mod maps;
mod model_based;
mod orientation_part;
mod plan;
mod regions;
mod report;
mod run;
pub mod ties;
mod trained;
pub mod veto;

pub(crate) use failure::MethodError;
pub use failure::MethodFailure;

use super::network::{MlpSize, MlpTrainer, Network};
pub(crate) use cache::Cache;
pub(crate) use context::{Context, MethodProgress};
pub(crate) use plan::Planner;
pub(crate) use run::run;

use serde::{Deserialize, Serialize};
use std::borrow::Borrow;
use std::cmp::Ordering;
use std::fmt;
use std::hash::{Hash, Hasher};

/// Generates [`Method`] (one variant per row, serialised as its name) and
/// [`METHODS`] (its rows, in the same order) from one list.
macro_rules! method_table {
    ($(
        $variant:ident {
            name: $name:literal,
            aliases: [$($alias:literal),* $(,)?],
            label: $label:literal,
            description: $description:literal,
            $($field:ident: $value:expr),+ $(,)?
        }
    )+) => {
        /// A calibration method: one row of [`METHODS`].
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
        pub enum Method {
            $(#[doc = $description] #[serde(rename = $name)] $variant,)+
        }

        /// Every method, in the order of [`Method::ALL`].
        pub const METHODS: [MethodRow; [$($name),+].len()] = [$(
            MethodRow {
                method: Method::$variant,
                name: $name,
                aliases: &[$($alias),*],
                label: $label,
                description: $description,
                $($field: $value),+
            },
        )+];
    };
}

// `weight`: each method's processor time over SKCM's on the shipped UR5 data,
// measured on 2026-11-29 with `scripts/method_weights.py --deadline 600`
// (`robocal calibrate --model ur5 --identify …grid_cleaned.csv --validate
// …random_cleaned.csv --method M --cv-folds 5 --threads 1 --seed 1`, the dev
// build, whose profile optimises the core and every dependency; one method a
// run): SKCM 0.046 s; `skcm-tlbo`'s without KM's warm start, extrapolated from
// 53 % of its bar. `skcm-iwonn` and `skcm-tlbonn` measured to their end on
// the same build on 2026-11-29 with `scripts/method_weights.py --methods
// skcm-iwonn,skcm-tlbonn --repeat 10` (131.8 s and 323.4 s, over the SKCM
// figure above so that every weight has one unit). Not measured:
// `skcm-payload` (it does not run on this data: kept at twice SKCM's).
// `auto`'s is the sum of what it plans with both bases (plan.rs).
method_table! {
    Km {
        name: "km",
        aliases: [],
        label: "KM",
        description: "Kinematic calibration (thesis §2.2): LM on the identifiable geometric parameters.",
        fits: "geometry",
        compliance: Compliance::No,
        torques: false,
        thesis: true,
        weight: 0.33,
        run: Run::Km,
    }
    Skcm {
        name: "skcm",
        aliases: [],
        label: "SKCM",
        description: "Simultaneous kinematic and compliance calibration (§2.3): KM with the joint compliance, c ≥ 0.",
        fits: "geometry and joint compliance",
        compliance: Compliance::Yes,
        torques: true,
        thesis: true,
        weight: 1.0,
        run: Run::Skcm,
    }
    SkcmTlbo {
        name: "skcm-tlbo",
        aliases: ["skcm-c", "skcm_tlbo", "tlbo"],
        label: "SKCM-C (TLBO)",
        description: "SKCM-C (ch. 7): the compliance searched by TLBO around an inner KM.",
        fits: "joint compliance by TLBO, then geometry",
        compliance: Compliance::Yes,
        torques: true,
        thesis: true,
        weight: 1700.0,
        run: Run::SkcmTlbo,
    }
    SkcmPayload {
        name: "skcm-payload",
        aliases: ["skcm_payload"],
        label: "SKCM-payload",
        description: "SKCM with the payload's centre of mass (and mass offset) identified jointly (beyond the thesis).",
        fits: "geometry, joint compliance and the payload",
        compliance: Compliance::Yes,
        torques: true,
        thesis: false,
        weight: 2.0,
        run: Run::SkcmPayload,
    }
    KmMaps {
        name: "km-maps",
        aliases: ["km_maps"],
        label: "KM+maps",
        description: "KM, then per-joint angle error maps (a Fourier series of each joint's own angle, confined to its trained range) fitted jointly with the linearised geometry and chosen by cross-validation; the geometry refitted with them (beyond the thesis).",
        fits: "geometry and per-joint angle error maps",
        compliance: Compliance::No,
        torques: false,
        thesis: false,
        weight: 97.0,
        run: Run::Maps(Base::Km),
    }
    SkcmMaps {
        name: "skcm-maps",
        aliases: ["skcm_maps"],
        label: "SKCM+maps",
        description: "SKCM, then per-joint angle error maps as km-maps, the geometry and compliance refitted with them (beyond the thesis).",
        fits: "geometry, joint compliance and per-joint angle error maps",
        compliance: Compliance::Yes,
        torques: true,
        thesis: false,
        weight: 100.0,
        run: Run::Maps(Base::Skcm),
    }
    KmRbf {
        name: "km-rbf",
        aliases: ["km_rbf"],
        label: "KM-RBF",
        description: "KM, then an RBF network on the gravity torques (ch. 3).",
        fits: "KM, then a residual network",
        compliance: Compliance::No,
        torques: true,
        thesis: false,
        weight: 57.0,
        run: Run::Compensated(Compensated { base: Base::Km, network: Network::Rbf }),
    }
    SkcmNn {
        name: "skcm-nn",
        aliases: ["skcm_nn"],
        label: "SKCM-NN",
        description: "SKCM, then an MLP trained by LM backpropagation (ch. 4).",
        fits: "SKCM, then a residual network",
        compliance: Compliance::Yes,
        torques: true,
        thesis: false,
        weight: 680.0,
        run: Run::Compensated(Compensated {
            base: Base::Skcm,
            network: Network::Mlp { size: MlpSize::Nn, trainer: MlpTrainer::Lm },
        }),
    }
    SkcmIwonn {
        name: "skcm-iwonn",
        aliases: ["skcm_iwonn"],
        label: "SKCM-IWONN",
        description: "SKCM, then an 18-40-3 MLP (the thesis's 6-5-3, widened) trained by invasive weed optimisation (ch. 5).",
        fits: "SKCM, then a residual network",
        compliance: Compliance::Yes,
        torques: true,
        thesis: false,
        weight: 2900.0,
        run: Run::Compensated(Compensated {
            base: Base::Skcm,
            network: Network::Mlp { size: MlpSize::Small, trainer: MlpTrainer::Iwo },
        }),
    }
    SkcmTlbonn {
        name: "skcm-tlbonn",
        aliases: ["skcm_tlbonn"],
        label: "SKCM-TLBONN",
        description: "SKCM, then an 18-40-3 MLP (the thesis's 6-5-3, widened) trained by TLBO (ch. 6).",
        fits: "SKCM, then a residual network",
        compliance: Compliance::Yes,
        torques: true,
        thesis: false,
        weight: 7000.0,
        run: Run::Compensated(Compensated {
            base: Base::Skcm,
            network: Network::Mlp { size: MlpSize::Small, trainer: MlpTrainer::Tlbo },
        }),
    }
    KmGp {
        name: "km-gp",
        aliases: ["km_gp"],
        label: "KM-GP",
        description: "KM, then a sparse Gaussian process on the joints with per-joint length scales, which also gives an expected error per pose (beyond the thesis).",
        fits: "KM, then a residual Gaussian process",
        compliance: Compliance::No,
        torques: false,
        thesis: false,
        weight: 380.0,
        run: Run::Compensated(Compensated { base: Base::Km, network: Network::Gp }),
    }
    SkcmGp {
        name: "skcm-gp",
        aliases: ["skcm_gp"],
        label: "SKCM-GP",
        description: "SKCM, then a sparse Gaussian process on the joints as km-gp (beyond the thesis).",
        fits: "SKCM, then a residual Gaussian process",
        compliance: Compliance::Yes,
        torques: true,
        thesis: false,
        weight: 380.0,
        run: Run::Compensated(Compensated { base: Base::Skcm, network: Network::Gp }),
    }
    KmMapsGp {
        name: "km-maps-gp",
        aliases: ["km_maps_gp"],
        label: "KM+maps-GP",
        description: "km-maps, then a sparse Gaussian process on what the maps leave, as km-gp (beyond the thesis).",
        fits: "KM with joint maps, then a residual Gaussian process",
        compliance: Compliance::No,
        torques: false,
        thesis: false,
        weight: 450.0,
        run: Run::Compensated(Compensated { base: Base::KmMaps, network: Network::Gp }),
    }
    SkcmMapsGp {
        name: "skcm-maps-gp",
        aliases: ["skcm_maps_gp"],
        label: "SKCM+maps-GP",
        description: "skcm-maps, then a sparse Gaussian process on what the maps leave, as km-gp (beyond the thesis).",
        fits: "SKCM with joint maps, then a residual Gaussian process",
        compliance: Compliance::Yes,
        torques: true,
        thesis: false,
        weight: 450.0,
        run: Run::Compensated(Compensated { base: Base::SkcmMaps, network: Network::Gp }),
    }
    Auto {
        name: "auto",
        aliases: [],
        label: "auto",
        description: "The base (KM or SKCM) with the compensator or the joint maps chosen by cross-validated error, or the base alone when none is better on both mean and max.",
        fits: "what the method it chooses fits",
        compliance: Compliance::IfLoaded,
        torques: false,
        thesis: false,
        weight: 12000.0,
        run: Run::Auto,
    }
}

/// One row of [`METHODS`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MethodRow {
    /// The method this row describes.
    pub method: Method,
    /// The name in requests, reports and model files.
    pub name: &'static str,
    /// Other names [`Method::parse`] accepts.
    pub aliases: &'static [&'static str],
    /// Display name in tables and the HTML report.
    pub label: &'static str,
    /// What the method does, in a sentence (also the [`Method`] variant's doc).
    pub description: &'static str,
    /// What the method identifies.
    pub fits: &'static str,
    /// Whether the method identifies joint compliance.
    pub compliance: Compliance,
    /// Needs gravity torques on some joint (compliance, or torque inputs).
    pub torques: bool,
    /// One of the thesis's three compared methods (the command line's default).
    pub thesis: bool,
    /// Measured time relative to SKCM's (comment above the table), for the
    /// progress percentage and its time left.
    pub weight: f64,
    /// How the method runs.
    pub run: Run,
}

/// Whether a method identifies joint compliance.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Compliance {
    /// Never: the joints are taken as rigid.
    No,
    /// Always (the method needs gravity torques).
    Yes,
    /// Only when gravity loads a joint (`auto` then also weighs SKCM).
    IfLoaded,
}

/// How a method runs ([`run`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Run {
    /// KM: LM on the identifiable geometric parameters (§2.2).
    Km,
    /// SKCM: LM on the geometry and the joint compliance, c ≥ 0 (§2.3).
    Skcm,
    /// SKCM-C: the compliance searched by TLBO around an inner KM (ch. 7).
    SkcmTlbo,
    /// SKCM with the payload's centre of mass (and mass offset) identified jointly.
    SkcmPayload,
    /// Joint angle error maps on a base (`maps`).
    Maps(Base),
    /// A learned compensator trained on the residuals of a base (`compensated`).
    Compensated(Compensated),
    /// The base alone, with its joint maps or with a compensator, chosen by cross-validated
    /// error (`auto`).
    Auto,
}

/// A compensator method: its network on the residuals of its base.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Compensated {
    /// The model-based method whose residuals the network is trained on.
    pub base: Base,
    /// The network and which of the options' settings it trains with
    /// ([`Network::spec`]).
    pub network: Network,
}

/// A model-based method a compensator builds on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Base {
    /// KM (`km`).
    Km,
    /// SKCM (`skcm`).
    Skcm,
    /// KM with its joint maps (`km-maps`).
    KmMaps,
    /// SKCM with its joint maps (`skcm-maps`).
    SkcmMaps,
}

impl Base {
    /// The method of this base, as run on its own.
    pub const fn method(self) -> Method {
        match self {
            Base::Km => Method::Km,
            Base::Skcm => Method::Skcm,
            Base::KmMaps => Method::KmMaps,
            Base::SkcmMaps => Method::SkcmMaps,
        }
    }
}

/// Which methods a group holds.
#[derive(Clone, Copy)]
enum Group {
    ModelBased,
    Thesis,
    JointMaps,
    Compensated,
}

const fn in_group(row: &MethodRow, group: Group) -> bool {
    match group {
        Group::ModelBased => !matches!(row.run, Run::Compensated(_) | Run::Auto | Run::Maps(_)),
        Group::Thesis => row.thesis,
        Group::JointMaps => matches!(row.run, Run::Maps(_)),
        Group::Compensated => matches!(row.run, Run::Compensated(_)),
    }
}

const fn group_len(group: Group) -> usize {
    let (mut i, mut n) = (0, 0);
    while i < METHODS.len() {
        if in_group(&METHODS[i], group) {
            n += 1;
        }
        i += 1;
    }
    n
}

const fn group<const N: usize>(group: Group) -> [Method; N] {
    let mut out = [Method::Km; N];
    let (mut i, mut n) = (0, 0);
    while i < METHODS.len() {
        if in_group(&METHODS[i], group) {
            out[n] = METHODS[i].method;
            n += 1;
        }
        i += 1;
    }
    assert!(n == N);
    out
}

const fn all() -> [Method; METHODS.len()] {
    let mut out = [Method::Km; METHODS.len()];
    let mut i = 0;
    while i < METHODS.len() {
        out[i] = METHODS[i].method;
        i += 1;
    }
    out
}

impl Method {
    /// Every method (`all`, the `compare` table).
    pub const ALL: [Method; METHODS.len()] = all();
    /// The model-based methods (no compensator, no joint maps).
    pub const MODEL_BASED: [Method; group_len(Group::ModelBased)] = group(Group::ModelBased);
    /// The thesis's three methods (the default of `robocal calibrate`).
    pub const THESIS: [Method; group_len(Group::Thesis)] = group(Group::Thesis);
    /// The joint-map methods.
    pub const JOINT_MAPS: [Method; group_len(Group::JointMaps)] = group(Group::JointMaps);
    /// The methods with a learned compensator.
    pub const COMPENSATED: [Method; group_len(Group::Compensated)] = group(Group::Compensated);

    /// The method's row of [`METHODS`].
    pub const fn row(self) -> &'static MethodRow {
        const TABLE: &[MethodRow] = &METHODS;
        &TABLE[self as usize]
    }

    /// The name in requests, reports and model files (`km`, `skcm-tlbo`, …).
    pub const fn name(self) -> &'static str {
        self.row().name
    }

    /// Display name (`KM`, `SKCM-C (TLBO)`, …).
    pub const fn label(self) -> &'static str {
        self.row().label
    }

    /// The compensator of a compensator method.
    pub const fn compensated(self) -> Option<Compensated> {
        match self.row().run {
            Run::Compensated(c) => Some(c),
            _ => None,
        }
    }

    /// The model-based method a compensator method builds on.
    pub const fn base(self) -> Option<Method> {
        match self.compensated() {
            Some(c) => Some(c.base.method()),
            None => None,
        }
    }

    /// Whether the method identifies joint compliance (needs gravity torques).
    /// `auto` decides for itself which bases it can run.
    pub fn uses_compliance(self) -> bool {
        self.row().compliance == Compliance::Yes
    }

    /// Whether the method needs gravity torques on some joint (compliance, or
    /// the torque-input RBF).
    pub const fn uses_torques(self) -> bool {
        self.row().torques
    }

    /// The method of exactly this name (no alias, case-sensitive), as reports
    /// store it.
    pub fn from_name(name: &str) -> Option<Method> {
        METHODS.iter().find(|r| r.name == name).map(|r| r.method)
    }

    /// The method of a name or alias, case-insensitive, blanks trimmed.
    pub fn parse(s: &str) -> Option<Method> {
        let s = s.trim().to_ascii_lowercase();
        METHODS
            .iter()
            .find(|r| r.name == s || r.aliases.contains(&s.as_str()))
            .map(|r| r.method)
    }

    /// The methods of `choices` in order, each once, `all` expanded to
    /// [`Method::ALL`].
    pub fn select(
        choices: impl IntoIterator<Item = MethodChoice>,
    ) -> Result<Vec<Method>, MethodListError> {
        let mut out = Vec::new();
        for choice in choices {
            let methods = match choice {
                MethodChoice::All => &Method::ALL[..],
                MethodChoice::One(m) => &[m][..],
            };
            for m in methods {
                if !out.contains(m) {
                    out.push(*m);
                }
            }
        }
        if out.is_empty() {
            return Err(MethodListError::Empty);
        }
        Ok(out)
    }

    /// [`Method::select`] of a list of names (blank entries skipped), naming
    /// any unknown entry.
    pub fn parse_names<S: AsRef<str>>(
        names: impl IntoIterator<Item = S>,
    ) -> Result<Vec<Method>, MethodListError> {
        let mut choices = Vec::new();
        for name in names {
            if !name.as_ref().trim().is_empty() {
                choices.push(MethodChoice::parse(name.as_ref())?);
            }
        }
        Method::select(choices)
    }

    /// [`Method::parse_names`] of a comma-separated list.
    pub fn parse_list(s: &str) -> Result<Vec<Method>, MethodListError> {
        Method::parse_names(s.split(','))
    }
}

/// An entry of a method list: one method, or `all` for every one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MethodChoice {
    /// The one method named.
    One(Method),
    /// Every method, [`Method::ALL`].
    All,
}

impl MethodChoice {
    /// A name or alias ([`Method::parse`]) or `all`.
    pub fn parse(s: &str) -> Result<MethodChoice, MethodListError> {
        if s.trim().eq_ignore_ascii_case("all") {
            return Ok(MethodChoice::All);
        }
        Method::parse(s)
            .map(MethodChoice::One)
            .ok_or_else(|| MethodListError::Unknown {
                name: s.trim().to_string(),
            })
    }
}

/// A method list that names no method, or a name that is none.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum MethodListError {
    /// An entry is neither a method's name or alias nor `all`.
    #[error("unknown method `{name}` (known: {})", known())]
    Unknown {
        /// The entry, blanks trimmed.
        name: String,
    },
    /// The list names no method (it is empty or blank).
    #[error("no method given (known: {})", known())]
    Empty,
}

/// The names a method list takes: every method's, then `all`.
fn known() -> String {
    let mut names: Vec<&str> = METHODS.iter().map(|r| r.name).collect();
    names.push("all");
    names.join(", ")
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

// Methods compare and hash by name, so a map keyed by method iterates (and
// serialises) in the order of their names and can be looked up by name.
impl Ord for Method {
    fn cmp(&self, other: &Self) -> Ordering {
        self.name().cmp(other.name())
    }
}

impl PartialOrd for Method {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Hash for Method {
    fn hash<H: Hasher>(&self, state: &mut H) {
        self.name().hash(state);
    }
}

impl Borrow<str> for Method {
    fn borrow(&self) -> &str {
        self.name()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    #[test]
    fn rows_are_in_variant_order_with_unique_names() {
        let mut seen: Vec<&str> = Vec::new();
        for (i, r) in METHODS.iter().enumerate() {
            assert_eq!(r.method as usize, i);
            assert_eq!(r.method.row(), r);
            for n in std::iter::once(&r.name).chain(r.aliases) {
                assert!(!seen.contains(n), "{n} twice");
                assert_eq!(*n, n.to_ascii_lowercase());
                assert_ne!(*n, "all");
                seen.push(n);
                assert_eq!(
                    Method::parse(&format!(" {} ", n.to_uppercase())),
                    Some(r.method)
                );
            }
            assert_eq!(Method::from_name(r.name), Some(r.method));
            assert_eq!(serde_json::to_value(r.method).unwrap(), r.name);
            let back: Method = serde_json::from_value(r.name.into()).unwrap();
            assert_eq!(back, r.method);
            assert!(r.weight > 0.0);
        }
        assert_eq!(Method::from_name("KM"), None);
        assert_eq!(Method::from_name("tlbo"), None);
    }

    /// The weights are the methods' measured times over SKCM's (the comment
    /// above the table): each is its measured ratio to two significant
    /// figures, so they order the methods as measured; `auto`, which runs the
    /// others, weighs most.
    #[test]
    fn weights_order_the_methods_as_measured() {
        // Processor seconds per method, `scripts/method_weights.py` on
        // 2026-11-29 (`skcm-tlbo` extrapolated from 53 % of its bar).
        const MEASURED: [(Method, f64); 13] = [
            (Method::Km, 0.015),
            (Method::Skcm, 0.046),
            (Method::SkcmTlbo, 76.583),
            (Method::KmMaps, 4.479),
            (Method::SkcmMaps, 4.614),
            (Method::KmRbf, 2.619),
            (Method::SkcmNn, 31.236),
            (Method::SkcmIwonn, 131.780),
            (Method::SkcmTlbonn, 323.388),
            (Method::KmGp, 17.433),
            (Method::SkcmGp, 17.277),
            (Method::KmMapsGp, 20.527),
            (Method::SkcmMapsGp, 20.558),
        ];
        let of = |m: Method| MEASURED.iter().find(|(n, _)| *n == m).unwrap().1;
        let (km, skcm) = (of(Method::Km), of(Method::Skcm));
        for (m, s) in MEASURED {
            let ratio = if m == Method::SkcmTlbo {
                (s - km) / skcm
            } else {
                s / skcm
            };
            let w = m.row().weight;
            assert!(
                (w - ratio).abs() <= 0.05 * ratio,
                "{m}: weight {w}, measured {ratio}"
            );
        }
        for (a, sa) in MEASURED {
            for (b, sb) in MEASURED {
                if sa > 1.2 * sb {
                    assert!(
                        a.row().weight > b.row().weight,
                        "{a} measured slower than {b}"
                    );
                }
            }
        }
        for r in &METHODS {
            if r.method != Method::Auto {
                assert!(Method::Auto.row().weight > r.weight, "{}", r.name);
            }
        }
    }

    /// What a method needs follows from what it builds on: a compensator
    /// method identifies compliance exactly when its base does, and every
    /// method that identifies compliance needs gravity torques.
    #[test]
    fn needs_are_consistent_with_the_base() {
        for r in &METHODS {
            if let Some(base) = r.method.base() {
                assert_eq!(base.compensated(), None);
                assert_eq!(r.compliance, base.row().compliance, "{}", r.name);
            }
            if r.compliance == Compliance::Yes {
                assert!(r.torques, "{}", r.name);
            }
        }
        assert!(Method::KmRbf.uses_torques() && !Method::KmRbf.uses_compliance());
        assert!(!Method::Auto.uses_torques() && !Method::Auto.uses_compliance());
    }

    /// The groups split the table: model-based, joint maps, compensated, and
    /// `auto`.
    #[test]
    fn groups() {
        assert_eq!(Method::THESIS, [Method::Km, Method::Skcm, Method::SkcmTlbo]);
        assert_eq!(Method::JOINT_MAPS, [Method::KmMaps, Method::SkcmMaps]);
        for m in Method::ALL {
            let model_based = Method::MODEL_BASED.contains(&m);
            let compensated = Method::COMPENSATED.contains(&m);
            let maps = Method::JOINT_MAPS.contains(&m);
            assert_eq!(compensated, m.compensated().is_some(), "{m}");
            assert_eq!(m.base().is_some(), compensated, "{m}");
            assert_eq!(
                model_based,
                !compensated && !maps && m != Method::Auto,
                "{m}"
            );
        }
        assert!(Method::MODEL_BASED.starts_with(&Method::THESIS));
        assert!(Method::MODEL_BASED.contains(&Method::SkcmPayload));
        assert_eq!(Method::SkcmNn.base(), Some(Method::Skcm));
        assert_eq!(Method::KmRbf.base(), Some(Method::Km));
        assert_eq!(
            Method::COMPENSATED.len(),
            8,
            "KM-RBF, SKCM-NN, -IWONN, -TLBONN, KM-GP, SKCM-GP and the GPs on the maps"
        );
    }

    #[test]
    fn lists_parse_with_aliases_and_all() {
        assert_eq!(
            Method::parse_list(" tlbo, KM,,km ").unwrap(),
            vec![Method::SkcmTlbo, Method::Km]
        );
        assert_eq!(
            Method::parse_list("km,all").unwrap()[..2],
            [Method::Km, Method::Skcm]
        );
        assert_eq!(Method::parse_list("all").unwrap(), Method::ALL.to_vec());
        let e = Method::parse_list("km,nope").unwrap_err().to_string();
        assert!(
            e.starts_with("unknown method `nope` (known: km, skcm, skcm-tlbo, ")
                && e.ends_with(", auto, all)"),
            "{e}"
        );
        assert!(METHODS.iter().all(|r| e.contains(&format!(" {},", r.name))));
        assert_eq!(Method::parse_names([" ", ""]), Err(MethodListError::Empty));
        assert_eq!(
            Method::parse_names(["km,skcm"]),
            Err(MethodListError::Unknown {
                name: "km,skcm".into()
            })
        );
    }

    /// A map keyed by method keeps the order and the lookups of one keyed by
    /// name.
    #[test]
    fn maps_keyed_by_method_order_by_name() {
        let by_method: BTreeMap<Method, usize> = Method::ALL
            .iter()
            .enumerate()
            .map(|(i, m)| (*m, i))
            .collect();
        let by_name: BTreeMap<&str, usize> = Method::ALL
            .iter()
            .enumerate()
            .map(|(i, m)| (m.name(), i))
            .collect();
        assert!(by_method
            .iter()
            .map(|(m, i)| (m.name(), *i))
            .eq(by_name.iter().map(|(n, i)| (*n, *i))));
        assert_eq!(by_method["skcm-tlbo"], 2);
        assert_eq!(
            serde_json::to_string(&by_method).unwrap(),
            serde_json::to_string(&by_name).unwrap()
        );
    }
}
