//! The cell around a robot as stored: tools and work objects, the frame each
//! pose is given in, what a put did.

use super::Json;
use crate::solve::cell::file::PoseMmDeg;
use crate::solve::cell::LoadDescription;
use sqlx::FromRow;

/// Tool or work object.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CellKind {
    Tool,
    WorkObject,
}

/// The frame an item's pose is given in: a tool's in the flange frame, a work
/// object's in the robot base or the measurement frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ItemFrame {
    Flange,
    Base,
    Measurement,
}

/// A tool or work object to store.
#[derive(Debug, Clone, PartialEq)]
pub struct NewCellItem {
    pub name: String,
    pub number: Option<i64>,
    pub frame: ItemFrame,
    pub pose: PoseMmDeg,
    /// A tool's load (None for work objects and tools without one).
    pub load: Option<LoadDescription>,
}

/// A stored tool or work object.
#[derive(Debug, Clone, FromRow)]
pub struct CellItemRow {
    pub name: String,
    pub number: Option<i64>,
    pub frame: ItemFrame,
    pub pose_json: Json<PoseMmDeg>,
    pub load_json: Option<Json<LoadDescription>>,
    pub created_at: String,
    pub updated_at: String,
}

/// What a put did: the item as stored, and whether it is new.
#[derive(Debug, Clone)]
pub struct CellPut {
    pub row: CellItemRow,
    pub created: bool,
}
