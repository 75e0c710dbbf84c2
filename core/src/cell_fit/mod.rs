//! Fitting the cell's items from readings on the calibrated model: a
//! production tool's TCP (`tcp`: a fixed point, a tracker reflector or 6-D
//! probe, the tool's axis; each fit judged against the readings' noise and
//! stored as a cell file entry), a work object from touched points
//! (`work_object`) and a positioner's readings from touches with a
//! calibrated tool (`positioner_touches`, which the positioner's fit in
//! `calibrate::external` then reads as a tracker's).
//!
//! A floor of its own above `solve`: the fits stand the cell's items on the
//! calibrated flange (`solve::cell::with_tool`) and write them as the cell
//! file describes them (`solve::cell::file`), so they cannot sit in
//! `calibrate`, below `solve`, without an import upwards.
//!
//! Units: SI (m, rad) in poses and points; the reported residuals and σ are in
//! mm and degrees (fields named so).

pub mod positioner_touches;
pub mod tcp;
pub mod work_object;
