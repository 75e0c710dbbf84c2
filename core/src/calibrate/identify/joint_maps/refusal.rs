//! Why a joint's map is refused: the observability rule of `joint_maps`
//! (module docs there; lever arm `L_i` [m/rad], noise σ [m], figures in mm
//! and degrees as reported).

use serde::{Deserialize, Serialize};

/// Why a joint's map was refused (module docs): a closed set whose
/// snake-case names the report serialises.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MapRefusal {
    /// The angle one pose resolves, `σ / L_i`, would move a production
    /// tool's tip by more than `max_unseen_tip_m` and `noise_ratio·σ` unseen.
    AngleNotResolved,
    /// The lever arm `L_i` is below the floor `min_lever_m`.
    LeverBelowFloor,
}

impl MapRefusal {
    /// Every rule, in the order the module docs give them.
    pub const ALL: [MapRefusal; 2] = [MapRefusal::AngleNotResolved, MapRefusal::LeverBelowFloor];

    /// The serialised name.
    pub fn name(self) -> &'static str {
        match self {
            MapRefusal::AngleNotResolved => "angle_not_resolved",
            MapRefusal::LeverBelowFloor => "lever_below_floor",
        }
    }
}

/// A joint whose map was refused: the measurements do not see its angle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RefusedMap {
    /// Joint number (1-based).
    pub joint: usize,
    /// Which rule refused it (module docs).
    pub kind: MapRefusal,
    /// RMS lever arm from the joint's axis to the measured point over the
    /// poses [mm].
    pub lever_mm: f64,
    /// The floor of the lever [mm].
    pub min_lever_mm: f64,
    /// The position noise σ per coordinate the rule used [mm].
    pub noise_mm: f64,
    /// The angle one pose resolves, `σ / L_i`, at most 180° [deg].
    pub resolved_deg: f64,
    /// A production tool's tip distance from the measured point, `ℓ` [mm].
    pub production_tool_mm: f64,
    /// What an angle error of `resolved_deg` moves that tip by, unseen [mm].
    pub unseen_tip_mm: f64,
    /// The bound on `unseen_tip_mm`, `max(max_unseen_tip_m, noise_ratio·σ)`
    /// [mm].
    pub max_unseen_tip_mm: f64,
    /// The refusal in words, with those figures, for the report.
    pub reason: String,
}
