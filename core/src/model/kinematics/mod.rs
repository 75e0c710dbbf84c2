//! Kinematics: forward kinematics, Jacobians, closed loop and gravity torques.
//! Pure functions of a `RobotModel` and joint values; no hidden state.

pub mod chain;
pub mod gravity;
pub mod jacobian;
pub mod loop_closure;
pub mod prepared;

pub use chain::{chain, fk, Chain, KinematicsError};
pub use gravity::{deflected_joints, gravity_torques, gravity_torques_of};
pub use jacobian::{geometric_jacobian, identification_jacobian, param_column};
pub use loop_closure::LoopPartials;
pub use prepared::PreparedChain;
