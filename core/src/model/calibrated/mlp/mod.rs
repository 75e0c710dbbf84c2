//! The multilayer perceptron family (SKCM-NN, SKCM-IWONN, SKCM-TLBONN; thesis
//! ch. 4–6): the network and its prediction (`model`) and its entry in the
//! stored compensators' table (`family`). Its trainers are
//! `calibrate::compensate::mlp`.

mod family;
pub mod model;

pub use model::{Features, Mlp, Normalisation, Shape};
