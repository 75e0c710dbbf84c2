//! An MLP's size and inputs ([`MlpSpec`]), and the thesis's networks.

use crate::model::calibrated::mlp::Features;
use serde::{Deserialize, Serialize};

/// Network size and inputs.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MlpSpec {
    /// Tansig units in the hidden layer.
    pub hidden: usize,
    /// The inputs beyond the joint angles (their sines and cosines, the payload).
    pub features: Features,
}

impl MlpSpec {
    /// The SKCM-NN network of ch. 4: 20 tansig units, here on the joint angles
    /// and their sines and cosines (18-20-3): a gear transmission error
    /// `A·sin(q + φ)` is linear in those, and on the compensator study
    /// (tests/compensate.rs) the validation gain over SKCM rises from 27 % with
    /// the thesis's 6-20-3 to 46 %.
    pub const SKCM_NN: MlpSpec = MlpSpec {
        hidden: 20,
        features: Features {
            sin_cos: true,
            payload: false,
        },
    };
    /// The thesis's 6-20-3 of ch. 4 (joint angles only).
    pub const SEED_6_20_3: MlpSpec = MlpSpec {
        hidden: 20,
        features: Features::JOINTS,
    };
    /// The thesis's IWO / TLBO network of ch. 5–6: 6-5-3 (53 weights) on the
    /// joint angles.
    pub const SMALL: MlpSpec = MlpSpec {
        hidden: 5,
        features: Features::JOINTS,
    };
    /// The SKCM-IWONN and SKCM-TLBONN network: 18-40-3 on the joint angles and
    /// their sines and cosines, its output layer solved by least squares for
    /// every candidate ([`OutputLayer::LeastSquares`]), so the population
    /// searches the 760 hidden weights and biases. On the compensator study
    /// (`cargo run --release -p robocal-core --example compare_trainers`)
    /// the thesis's 6-5-3 with every weight searched could not lift TLBO above
    /// −9 % against SKCM nor IWO above −1 %, and even LM backpropagation on
    /// 6-5-3 stops at −12 %: five units are too few for this residual.
    pub const POPULATION: MlpSpec = MlpSpec {
        hidden: 40,
        features: Features {
            sin_cos: true,
            payload: false,
        },
    };
}
