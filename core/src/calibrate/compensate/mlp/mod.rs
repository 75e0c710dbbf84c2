//! The multilayer perceptron family (SKCM-NN, SKCM-IWONN, SKCM-TLBONN; thesis
//! ch. 4–6): the network and its prediction (`model`), its trainers
//! (`train`: LM backpropagation, IWO, TLBO over one flat weight vector) and
//! its entry in the compensator table (`family`).

mod family;
mod model;
mod train;

pub use model::{Features, Mlp, Normalisation, Shape};
pub use train::{
    IwoSettings, LmTrainSettings, MlpSettings, MlpSpec, OutputLayer, TlboTrainSettings, Trainer,
};
