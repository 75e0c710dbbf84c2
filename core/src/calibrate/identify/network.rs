//! The compensator networks as one table: per network its documentation and
//! how its family's settings ([`CompensatorSpec`], one variant per family of
//! the compensator table, `compensate::family`) come from a calibration's
//! [`CompensatorOptions`]. [`Network`], [`Network::ALL`], [`Network::spec`]
//! and [`Network::max_epochs`] derive from it; a method names its network in
//! its row of the method table (`Run::Compensated`).

use super::options::CompensatorOptions;
use crate::calibrate::compensate::{CompensatorSpec, MlpSettings, Trainer};

/// Generates [`Network`] (one variant per row), [`Network::ALL`] and
/// [`Network::spec`] (each row's settings from the options `o`).
macro_rules! network_table {
    ($(
        $(#[doc = $doc:literal])+
        $variant:ident => |$o:ident| $spec:expr
    ),+ $(,)?) => {
        /// A compensator network and its trainer: one row of the network table.
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        pub enum Network {
            $($(#[doc = $doc])+ $variant,)+
        }

        impl Network {
            /// Every network, in the table's order.
            pub const ALL: [Network; [$(stringify!($variant)),+].len()] = [$(Network::$variant),+];

            /// The network's family and trainer with their settings from `options`.
            pub fn spec(self, options: &CompensatorOptions) -> CompensatorSpec {
                match self {
                    $(Network::$variant => {
                        let $o = options;
                        $spec
                    })+
                }
            }
        }
    };
}

network_table! {
    /// RBF on the gravity torques (ch. 3).
    Rbf => |o| CompensatorSpec::Rbf(o.rbf.clone()),
    /// MLP trained by LM backpropagation (ch. 4), the network `nn`.
    LmMlp => |o| CompensatorSpec::Mlp(MlpSettings {
        spec: o.nn,
        trainer: Trainer::Lm(o.lm.clone()),
    }),
    /// The small MLP trained by invasive weed optimisation (ch. 5), `small`.
    IwoMlp => |o| CompensatorSpec::Mlp(MlpSettings {
        spec: o.small,
        trainer: Trainer::Iwo(o.iwo.clone()),
    }),
    /// The small MLP trained by TLBO (ch. 6), `small`.
    TlboMlp => |o| CompensatorSpec::Mlp(MlpSettings {
        spec: o.small,
        trainer: Trainer::Tlbo(o.tlbo.clone()),
    }),
    /// The sparse Gaussian process on the joints (`compensate::gp`).
    Gp => |o| CompensatorSpec::Gp(o.gp.clone()),
}

impl Network {
    /// Epochs / iterations / generations a training run may take at most
    /// with `options` (for progress percentages; its family's
    /// [`CompensatorSpec::max_epochs`]).
    pub fn max_epochs(self, options: &CompensatorOptions) -> usize {
        self.spec(options).max_epochs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibrate::identify::methods::{Run, METHODS};

    #[test]
    fn every_network_is_some_methods_and_takes_its_settings() {
        let o = CompensatorOptions::default();
        for n in Network::ALL {
            assert!(
                METHODS
                    .iter()
                    .any(|r| matches!(r.run, Run::Compensated(c) if c.network == n)),
                "{n:?} is no method's network"
            );
            assert!(n.max_epochs(&o) > 0, "{n:?}");
        }
        // Each row reads its own settings: changing them changes its spec only.
        let mut changed = o.clone();
        changed.small.hidden += 1;
        let moved: Vec<Network> = Network::ALL
            .into_iter()
            .filter(|n| n.spec(&o) != n.spec(&changed))
            .collect();
        assert_eq!(moved, vec![Network::IwoMlp, Network::TlboMlp]);
    }
}
