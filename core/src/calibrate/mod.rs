//! Calibrate: identify a robot's model from its measurements (`identify`:
//! registration, identifiability, the model-based methods, joint maps, the
//! calibrated model file) and train the learned compensator for what the
//! model leaves (`compensate`).

pub mod compensate;
pub mod external;
pub mod identify;
pub mod pose_key;
