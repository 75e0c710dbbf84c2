//! The cell file: tools and work objects in boundary units (mm, degrees; the
//! rotation `Rz(rz)·Ry(ry)·Rx(rx)` of `rpy_deg = [rx, ry, rz]`, as a model
//! file's tool). A tool may carry a `load` (kg, mm; centre of mass in the
//! flange or the tool frame, converted once to the flange frame).

use super::{Cell, LoadDescription, Tool, WorkObject, WorkObjectFrame};
use crate::model::pose::rpy_matrix;
use crate::model::Pose;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// A pose in boundary units.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PoseMmDeg {
    /// Position [mm].
    pub xyz_mm: [f64; 3],
    /// Rotation `[rx, ry, rz]` [deg], applied as `Rz(rz)·Ry(ry)·Rx(rx)` (zero
    /// when absent).
    #[serde(default)]
    pub rpy_deg: [f64; 3],
}

impl PoseMmDeg {
    /// The pose in SI units (values taken as they are; see [`Self::to_pose`]).
    pub fn pose(&self) -> Pose {
        let [rx, ry, rz] = self.rpy_deg.map(f64::to_radians);
        Pose::new(rpy_matrix(rx, ry, rz), Vector3::from(self.xyz_mm) * 1e-3)
    }

    /// The pose in SI units, or which item has a value that is not finite.
    pub fn to_pose(&self, what: &str) -> Result<Pose, CellFileError> {
        if !self
            .xyz_mm
            .iter()
            .chain(&self.rpy_deg)
            .all(|v| v.is_finite())
        {
            return Err(CellFileError::NotFinite(what.to_string()));
        }
        Ok(self.pose())
    }
}

/// A tool of the cell file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ToolDescription {
    /// The tool's name.
    pub name: String,
    /// The controller's number (KUKA `TOOL_DATA[n]`, Fanuc `UT`), if any.
    #[serde(default)]
    pub number: Option<u32>,
    /// Flange → TCP, as `xyz_mm` and `rpy_deg` at the tool's top level.
    #[serde(flatten)]
    pub tcp: PoseMmDeg,
    /// The load the tool carries (`cell::load`), if stated.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub load: Option<LoadDescription>,
}

/// A work object of the cell file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WorkObjectDescription {
    /// The work object's name.
    pub name: String,
    /// The controller's number (KUKA `BASE_DATA[n]`, Fanuc `UF`), if any.
    #[serde(default)]
    pub number: Option<u32>,
    /// The frame the pose is given in (`base` by default).
    #[serde(default)]
    pub frame: WorkObjectFrame,
    /// Frame → work object, as `xyz_mm` and `rpy_deg` at the top level.
    #[serde(flatten)]
    pub pose: PoseMmDeg,
}

/// The cell file.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CellDescription {
    /// The production tools.
    #[serde(default)]
    pub tools: Vec<ToolDescription>,
    /// The work objects (user frames).
    #[serde(default)]
    pub work_objects: Vec<WorkObjectDescription>,
}

/// Why a cell file is not one.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CellFileError {
    /// The text is not a cell file's JSON (the parser's message).
    #[error("cell file: {0}")]
    Json(String),
    /// A pose of the named item has a value that is not finite.
    #[error("cell file: {0} has a value that is not finite")]
    NotFinite(String),
    /// The named tool's load is invalid (the tool's name, then why).
    #[error("cell file: tool {0}: {1}")]
    Load(String, String),
}

impl CellDescription {
    /// Parses a cell file's JSON text.
    pub fn from_json(text: &str) -> Result<Self, CellFileError> {
        serde_json::from_str(text).map_err(|e| CellFileError::Json(e.to_string()))
    }

    /// The cell in SI units.
    pub fn to_cell(&self) -> Result<Cell, CellFileError> {
        let tools = self
            .tools
            .iter()
            .map(|t| {
                let tcp = t.tcp.to_pose(&format!("tool {}", t.name))?;
                let load = t
                    .load
                    .as_ref()
                    .map(|l| l.to_load(&tcp))
                    .transpose()
                    .map_err(|e| CellFileError::Load(t.name.clone(), e))?;
                Ok(Tool {
                    name: t.name.clone(),
                    number: t.number,
                    tcp,
                    load,
                })
            })
            .collect::<Result<_, CellFileError>>()?;
        let work_objects = self
            .work_objects
            .iter()
            .map(|w| {
                Ok(WorkObject {
                    name: w.name.clone(),
                    number: w.number,
                    frame: w.frame,
                    pose: w.pose.to_pose(&format!("work object {}", w.name))?,
                })
            })
            .collect::<Result<_, CellFileError>>()?;
        Ok(Cell {
            tools,
            work_objects,
        })
    }
}
