//! robocal-core: the numerical core of robocal.
//!
//! Flow: measure (`measure`, `sim`) → calibrate (`identify`) → solve
//! (`compensate`, `ik`); `study` runs the seed's §7.4 simulation study. Every
//! function takes the model and the joint values as arguments; there is no
//! hidden mutable chain state, and nothing here touches HTTP, a database, the
//! async runtime or the file system. `csv_text` reads the CSV texts of
//! measurement and target files for both.

pub mod cell;
pub mod check;
pub mod compensate;
pub mod csv_text;
pub mod export;
pub mod identify;
pub mod ik;
pub mod iso9283;
pub mod kinematics;
pub mod measure;
pub mod model;
pub mod optim;
pub mod plan;
pub mod program;
pub mod sim;
pub mod stats;
pub mod study;
