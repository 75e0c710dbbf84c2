//! `positioner calibrate --touched-with MODEL --cell CELL --tool NAME`: the
//! files are touches with a calibrated tool instead of tracker readings —
//! joints files (`id`, `q1…qN` controller degrees) with the axes' columns,
//! one per feature on the face plate — placed by the calibrated robot
//! carrying the cell's tool (`cell_fit::positioner_touches`) and fitted as
//! a tracker's readings would be. Their σ is the robot's accuracy at the
//! tool's tip, which `--sigma-mm` must give.

use crate::calibrate::external::readings::PositionerColumns;
use crate::calibrate::external::PositionerReading;
use crate::cell_fit::positioner_touches::touch_readings;
use crate::service::positioners::ReadingsFrom;
use crate::solve::cell::{CellRef, Forward};

/// The calibrated robot with the touching tool.
pub(super) struct Touches {
    forward: Forward,
    /// Where the readings come from, as the `--json` answer states it.
    pub(super) from: ReadingsFrom,
}

impl Touches {
    /// The robot of the model file `model` carrying the tool `tool` of the
    /// cell file `cell`.
    pub(super) fn read(model: &str, cell: &str, tool: &str) -> anyhow::Result<Touches> {
        let m = super::model_files::load_with_payload(model, None)?;
        let cell_file = super::model_files::load_cell(Some(cell))?;
        let t = cell_file.tool(&tool.parse::<CellRef>()?)?;
        Ok(Touches {
            forward: Forward::new(&m, Some(&t.tcp), t.load.as_ref()),
            from: ReadingsFrom::Touches {
                model: Some(model.to_string()),
                version: None,
                tool: tool.to_string(),
            },
        })
    }

    /// A touches file's rows as readings of feature `k`.
    pub(super) fn readings(
        &self,
        text: &str,
        columns: PositionerColumns,
        k: usize,
    ) -> anyhow::Result<Vec<PositionerReading>> {
        Ok(touch_readings(&self.forward, text, columns, k)?)
    }
}
