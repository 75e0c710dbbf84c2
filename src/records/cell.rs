//! The cell around a robot as stored: tools and work objects, the frame each
//! pose is given in, what a put did.

use super::Json;
use crate::solve::cell::file::PoseMmDeg;
use crate::solve::cell::LoadDescription;
use sqlx::FromRow;

/// Tool or work object.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CellKind {
    /// A production tool (TCP in the flange frame).
    Tool,
    /// A work object (user frame).
    WorkObject,
}

/// The frame an item's pose is given in: a tool's in the flange frame, a work
/// object's in the robot base or the measurement frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ItemFrame {
    /// The flange frame (a tool's).
    Flange,
    /// The robot base frame (a work object's).
    Base,
    /// The measurement (tracker) frame of the calibration (a work object's).
    Measurement,
    /// The positioner's face plate (a work object's): only a program filter
    /// given the positioner places it (`core::program::axes`).
    FacePlate,
}

/// A tool or work object to store.
#[derive(Debug, Clone, PartialEq)]
pub struct NewCellItem {
    /// The item's name, unique per robot and kind regardless of ASCII case.
    pub name: String,
    /// The controller's number (KUKA `TOOL_DATA[n]`/`BASE_DATA[n]`, Fanuc `UTOOL`/`UFRAME`), if
    /// any.
    pub number: Option<i64>,
    /// The frame `pose` is given in.
    pub frame: ItemFrame,
    /// Frame → item (mm, deg).
    pub pose: PoseMmDeg,
    /// A tool's load (None for work objects and tools without one).
    pub load: Option<LoadDescription>,
}

/// A stored tool or work object.
#[derive(Debug, Clone, FromRow)]
pub struct CellItemRow {
    /// The item's name.
    pub name: String,
    /// The controller's number, if any.
    pub number: Option<i64>,
    /// The frame the pose is given in.
    pub frame: ItemFrame,
    /// Frame → item (mm, deg).
    pub pose_json: Json<PoseMmDeg>,
    /// A tool's load, if it has one.
    pub load_json: Option<Json<LoadDescription>>,
    /// When it was first stored (UTC, RFC 3339).
    pub created_at: String,
    /// When it was last replaced (UTC, RFC 3339).
    pub updated_at: String,
}

/// What a put did: the item as stored, and whether it is new.
#[derive(Debug, Clone)]
pub struct CellPut {
    /// The item as stored.
    pub row: CellItemRow,
    /// Whether the put created it (`false`: it replaced one).
    pub created: bool,
}
