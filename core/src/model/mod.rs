//! The robot model: geometry, compliance, inertia, limits, parameter vector and
//! the JSON description.

pub mod bounds;
pub mod calibrated;
pub mod description;
pub mod error;
pub mod export;
pub mod external;
pub mod joint_map_table;
pub mod joint_maps;
pub mod kinematics;
pub mod load;
pub mod orientation;
pub mod params;
pub mod pose;
pub mod presets;
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
