//! Training the multilayer perceptron family (SKCM-NN, SKCM-IWONN,
//! SKCM-TLBONN; thesis ch. 4–6; the network: `model::calibrated::mlp`): its
//! trainers (`train`: LM backpropagation, IWO, TLBO over one flat weight
//! vector) and its entry in the training table (`family`).

mod family;
mod train;

pub use train::{
    IwoSettings, LmTrainSettings, MlpSettings, MlpSpec, OutputLayer, TlboTrainSettings, Trainer,
};
