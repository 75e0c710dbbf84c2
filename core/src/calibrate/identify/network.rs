//! A compensator method's network as its row of the method table names it
//! (`methods::METHODS`, `Run::Compensated`): the family, and for an MLP its
//! size and trainer ([`Network`]). [`Network::spec`] reads that network's
//! settings ([`CompensatorSpec`], one variant per family of the compensator
//! table, `compensate::family`) from a calibration's [`CompensatorOptions`]:
//! the row says which settings, the options hold their values.

use super::options::CompensatorOptions;
use crate::calibrate::compensate::{CompensatorSpec, MlpSettings, Trainer};

/// Which network a compensator method trains: a column of the method table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Network {
    /// RBF on the gravity torques (ch. 3), the options' `rbf`.
    Rbf,
    /// An MLP of the options' size `size`, trained by `trainer`.
    Mlp {
        /// The options' MLP shape it has.
        size: MlpSize,
        /// The trainer that finds its weights.
        trainer: MlpTrainer,
    },
    /// The sparse Gaussian process on the joints (`compensate::gp`), the
    /// options' `gp`.
    Gp,
}

/// Which of the options' MLP shapes a method's network has.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MlpSize {
    /// The options' `nn` (SKCM-NN's network).
    Nn,
    /// The options' `small` (the network the population methods train).
    Small,
}

/// Which trainer finds an MLP's weights, with the options' settings of it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MlpTrainer {
    /// LM backpropagation (ch. 4), the options' `lm`.
    Lm,
    /// Invasive weed optimisation (ch. 5), the options' `iwo`.
    Iwo,
    /// TLBO (ch. 6), the options' `tlbo`.
    Tlbo,
}

impl Network {
    /// The network's family and trainer with their settings from `options`.
    pub fn spec(self, options: &CompensatorOptions) -> CompensatorSpec {
        let o = options;
        match self {
            Network::Rbf => CompensatorSpec::Rbf(o.rbf.clone()),
            Network::Mlp { size, trainer } => CompensatorSpec::Mlp(MlpSettings {
                spec: match size {
                    MlpSize::Nn => o.nn,
                    MlpSize::Small => o.small,
                },
                trainer: match trainer {
                    MlpTrainer::Lm => Trainer::Lm(o.lm.clone()),
                    MlpTrainer::Iwo => Trainer::Iwo(o.iwo.clone()),
                    MlpTrainer::Tlbo => Trainer::Tlbo(o.tlbo.clone()),
                },
            }),
            Network::Gp => CompensatorSpec::Gp(o.gp.clone()),
        }
    }

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
    use crate::calibrate::identify::methods::{Method, Run, METHODS};

    /// The networks the method table names, each once, in the table's order.
    fn networks() -> Vec<(Method, Network)> {
        METHODS
            .iter()
            .filter_map(|r| match r.run {
                Run::Compensated(c) => Some((r.method, c.network)),
                _ => None,
            })
            .collect()
    }

    /// Each method's network is the one its documentation names (the
    /// spec's short label: `rbf`, `nn`, `iwonn`, `tlbonn`, `gp`) and takes
    /// settings that allow some training.
    #[test]
    fn every_compensated_method_trains_the_network_it_names() {
        let o = CompensatorOptions::default();
        let labels: Vec<(&str, &str)> = networks()
            .into_iter()
            .map(|(m, n)| {
                assert!(n.max_epochs(&o) > 0, "{m}");
                (m.name(), n.spec(&o).label())
            })
            .collect();
        assert_eq!(
            labels,
            [
                ("km-rbf", "rbf"),
                ("skcm-nn", "nn"),
                ("skcm-iwonn", "iwonn"),
                ("skcm-tlbonn", "tlbonn"),
                ("km-gp", "gp"),
                ("skcm-gp", "gp"),
                ("km-maps-gp", "gp"),
                ("skcm-maps-gp", "gp"),
            ]
        );
    }

    /// Each row reads its own settings: changing the options' small MLP
    /// changes the specs of the methods whose column names it, and only
    /// those; likewise the LM trainer's settings.
    #[test]
    fn each_row_reads_the_settings_its_column_names() {
        let o = CompensatorOptions::default();
        let moved_by = |changed: &CompensatorOptions| -> Vec<Method> {
            networks()
                .into_iter()
                .filter(|(_, n)| n.spec(&o) != n.spec(changed))
                .map(|(m, _)| m)
                .collect()
        };
        let mut small = o.clone();
        small.small.hidden += 1;
        assert_eq!(moved_by(&small), [Method::SkcmIwonn, Method::SkcmTlbonn]);
        let mut nn = o.clone();
        nn.nn.hidden += 1;
        assert_eq!(moved_by(&nn), [Method::SkcmNn]);
        let mut gp = o.clone();
        gp.gp = crate::calibrate::compensate::GpSettings {
            inducing: o.gp.inducing + 1,
            ..o.gp.clone()
        };
        assert_eq!(
            moved_by(&gp),
            [
                Method::KmGp,
                Method::SkcmGp,
                Method::KmMapsGp,
                Method::SkcmMapsGp
            ]
        );
    }
}
