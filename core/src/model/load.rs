//! A tool's load: the mass it carries and where its centre of mass is.
//!
//! Frames: a [`Load`] holds its centre of mass in the FLANGE frame (the last
//! link's frame, before any tool), where a real payload hangs whichever TCP
//! is declared. A description may state it in the flange frame or in the
//! tool's frame (`LoadFrame`); it is converted once, `c_flange = T·c_tool`
//! with `T` the tool's flange → TCP pose. The robot model keeps its payload's
//! centre of mass in the model tool's frame (gravity torques, thesis eqs.
//! 3.7–3.9, take it from the TCP pose); [`on_tool`] re-expresses a flange-frame
//! load for the tool a solve uses: `c_tool = T⁻¹·c_flange`.
//!
//! Units: SI inside (kg, m, kg·m²); descriptions in kg, mm, kg·m².

use crate::model::kinematics::chain::tool_pose;
use crate::model::{Pose, RobotModel};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Mass difference [kg] beyond which two loads differ.
pub const MASS_TOLERANCE_KG: f64 = 0.05;
/// Centre-of-mass distance [m] beyond which two loads differ.
pub const COM_TOLERANCE_M: f64 = 0.002;

/// A load on the flange (SI).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Load {
    /// Mass [kg].
    pub mass_kg: f64,
    /// Centre of mass in the flange frame [m].
    pub com: Vector3<f64>,
    /// Principal moments of inertia about the centre of mass [kg·m²], if
    /// known (carried to the controller's load data; the static deflection
    /// does not depend on them).
    #[serde(default)]
    pub inertia_kgm2: Option<[f64; 3]>,
}

impl Load {
    /// Whether `self` and `other` differ by more than the tolerances.
    pub fn differs(&self, other: &Load) -> bool {
        (self.mass_kg - other.mass_kg).abs() > MASS_TOLERANCE_KG
            || (self.com - other.com).norm() > COM_TOLERANCE_M
    }

    /// `12.5 kg at [x, y, z] mm (flange)`.
    pub fn describe(&self) -> String {
        format!(
            "{:.3} kg at [{:.1}, {:.1}, {:.1}] mm (flange)",
            self.mass_kg,
            self.com.x * 1e3,
            self.com.y * 1e3,
            self.com.z * 1e3
        )
    }

    /// The payload of `model` (mass and centre of mass, the latter stated in
    /// the model tool's frame) at its flange point.
    pub fn of_model(model: &RobotModel) -> Load {
        Load {
            mass_kg: model.payload.mass,
            com: tool_pose(model).transform_point(&model.payload.com),
            inertia_kgm2: None,
        }
    }
}

/// `model` with the tool `tcp` (flange → TCP) and the payload `load` kept
/// where it hangs on the flange (its centre of mass re-expressed in the new
/// tool's frame). The identified `mass_offset` is kept.
pub fn on_tool(model: &RobotModel, tcp: &Pose, load: &Load) -> RobotModel {
    let mut m = model.clone();
    m.tool = crate::model::Tool {
        p: tcp.p,
        rpy: crate::model::orientation::fixed_xyz_angles(&tcp.r),
    };
    m.payload.mass = load.mass_kg;
    m.payload.com = tcp.inverse().transform_point(&load.com);
    m
}

/// In which frame a described load's centre of mass is given.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LoadFrame {
    /// The flange frame (KUKA `LOAD_DATA`, ABB `tload`, Fanuc payload, UR `set_payload`).
    #[default]
    Flange,
    /// The tool's own frame (at its TCP).
    Tool,
}

/// A load in boundary units (cell file, HTTP).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadDescription {
    /// Mass [kg], 0 to 10000.
    pub mass_kg: f64,
    /// Centre of mass [mm] in `frame`.
    #[serde(default)]
    pub com_mm: [f64; 3],
    /// The frame of `com_mm` (default: the flange).
    #[serde(default)]
    pub frame: LoadFrame,
    /// Principal moments of inertia [kg·m²], optional.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inertia_kgm2: Option<[f64; 3]>,
}

/// Largest load mass accepted [kg].
pub const MAX_LOAD_KG: f64 = 10_000.0;
/// Largest principal moment of inertia accepted [kg·m²]: the largest mass
/// with a radius of gyration of 10 m.
pub const MAX_INERTIA_KGM2: f64 = 1e6;

impl LoadDescription {
    /// The load on the flange of a tool `tcp` (flange → TCP); an error names
    /// the value that is not one.
    pub fn to_load(&self, tcp: &Pose) -> Result<Load, String> {
        if !(self.mass_kg.is_finite() && (0.0..=MAX_LOAD_KG).contains(&self.mass_kg)) {
            return Err(format!(
                "load mass_kg must be a number from 0 to {MAX_LOAD_KG}, got {}",
                self.mass_kg
            ));
        }
        if !self.com_mm.iter().all(|v| v.is_finite() && v.abs() <= 1e5) {
            return Err(format!(
                "load com_mm must be finite and within ±100000 mm, got {:?}",
                self.com_mm
            ));
        }
        if let Some(j) = self.inertia_kgm2 {
            if !j
                .iter()
                .all(|v| v.is_finite() && (0.0..=MAX_INERTIA_KGM2).contains(v))
            {
                return Err(format!(
                    "load inertia_kgm2 must be numbers from 0 to {MAX_INERTIA_KGM2:e} kg·m², got {j:?}"
                ));
            }
        }
        let c = Vector3::from(self.com_mm) * 1e-3;
        let com = match self.frame {
            LoadFrame::Flange => c,
            LoadFrame::Tool => tcp.transform_point(&c),
        };
        Ok(Load {
            mass_kg: self.mass_kg,
            com,
            inertia_kgm2: self.inertia_kgm2,
        })
    }

    /// The flange-frame description of `load`.
    pub fn of(load: &Load) -> Self {
        LoadDescription {
            mass_kg: load.mass_kg,
            com_mm: (load.com * 1e3).into(),
            frame: LoadFrame::Flange,
            inertia_kgm2: load.inertia_kgm2,
        }
    }
}
