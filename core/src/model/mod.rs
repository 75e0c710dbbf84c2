//! The robot model: geometry, compliance, inertia, limits, parameter vector and
//! the JSON description.

// `missing_docs` is warned module by module rather than on the whole
// floor: the external axes' models (`external`) are not documented item
// by item yet.
#[warn(missing_docs)]
pub mod bounds;
#[warn(missing_docs)]
pub mod calibrated;
#[warn(missing_docs)]
pub mod description;
#[warn(missing_docs)]
pub mod error;
#[warn(missing_docs)]
pub mod export;
pub mod external;
#[warn(missing_docs)]
pub mod joint_map_table;
#[warn(missing_docs)]
pub mod joint_maps;
#[warn(missing_docs)]
pub mod kinematics;
#[warn(missing_docs)]
pub mod load;
#[warn(missing_docs)]
pub mod orientation;
#[warn(missing_docs)]
pub mod params;
#[warn(missing_docs)]
pub mod pose;
#[warn(missing_docs)]
pub mod presets;
#[warn(missing_docs)]
pub mod robot;

pub use description::ModelDescription;
pub use error::ModelError;
pub use joint_maps::{
    fade_weight, Coverage, JointMap, JointMapDescription, JointMapError, JointMaps,
    JointMapsDescription, MapTaylor,
};
pub use params::{ParamId, ParamKind, ParamLayout};
pub use pose::Pose;
pub use presets::preset;
pub use robot::{ClosedLoop, Link, Payload, RobotModel, Tool};
