//! One data row of a measurement CSV, read through its header (`super`
//! module docs for the units and bounds).

use super::format::{short_number, CsvError, DifSign, MAX_JOINT_DEG};
use super::header::{Header, PositionCols};
use crate::csv_write::read_text;
use crate::measure::bounds::{self, within};
use crate::measure::convention::OrientationValueError;
use crate::measure::csv_text::{self, short_text};
use crate::measure::external::ExternalValues;
use crate::measure::{MeasuredPose, SetRole};
use crate::model::bounds::Bound;

/// Parses one numeric field; `None` for an empty field.
fn number(
    line: usize,
    column: &str,
    s: &str,
    decimal_comma: bool,
) -> Result<Option<f64>, CsvError> {
    if s.is_empty() {
        return Ok(None);
    }
    let v: f64 = csv_text::parse_number(s, decimal_comma).ok_or_else(|| CsvError::NotNumeric {
        line,
        column: column.to_string(),
        value: s.to_string(),
    })?;
    if !v.is_finite() {
        return Err(CsvError::NotFinite {
            line,
            column: column.to_string(),
            value: s.to_string(),
        });
    }
    Ok(Some(v))
}

fn required(line: usize, column: &str, s: &str, decimal_comma: bool) -> Result<f64, CsvError> {
    number(line, column, s, decimal_comma)?.ok_or_else(|| CsvError::NotNumeric {
        line,
        column: column.to_string(),
        value: String::new(),
    })
}

impl Header {
    /// One data row (at `line`) as a measured pose, every value checked.
    pub(super) fn row(
        &self,
        line: usize,
        fields: &[&str],
        sign: DifSign,
    ) -> Result<MeasuredPose, CsvError> {
        // The caller checked the row's shape (`Table::check_shape`).
        debug_assert_eq!(fields.len(), self.names.len());
        let length = if self.metres { 1e3 } else { 1.0 };
        let q_deg = self.joints(line, fields)?;
        let xyz_mm = self.position(line, fields, sign)?;
        let rpy_deg = self.orientation(line, fields)?;
        let std_mm = self.std(line, fields, self.std_pos, length, &bounds::STD_MM)?;
        let std_deg = self.std_deg(line, fields, rpy_deg.is_some())?;
        let payload_kg = self.bounded(line, fields, self.payload, &bounds::PAYLOAD_KG)?;
        let temperature_c = self.bounded(line, fields, self.temperature, &bounds::TEMPERATURE_C)?;
        Ok(MeasuredPose {
            q_deg,
            xyz_mm,
            rpy_deg,
            std_mm,
            std_deg,
            payload_kg,
            temperature_c,
            set: self.set(line, fields)?,
            session: self.session(line, fields)?,
        })
    }

    /// The row's external-axis values: every column the header has, given,
    /// finite and within `bounds::EXTERNAL_VALUE`.
    pub(super) fn external_values(
        &self,
        line: usize,
        fields: &[&str],
    ) -> Result<ExternalValues, CsvError> {
        let mut out = ExternalValues::default();
        for &(axis, c) in &self.external {
            let v =
                number(line, &self.names[c], fields[c], self.decimal_comma)?.ok_or_else(|| {
                    CsvError::MissingExternal {
                        line,
                        column: self.names[c].clone(),
                    }
                })?;
            self.within(line, c, v, &bounds::EXTERNAL_VALUE, "")?;
            out.0[axis.index()] = Some(v);
        }
        Ok(out)
    }

    /// An optional number of column `c` (if the header has it), within `b`.
    fn bounded(
        &self,
        line: usize,
        fields: &[&str],
        c: Option<usize>,
        b: &Bound,
    ) -> Result<Option<f64>, CsvError> {
        let Some(c) = c else { return Ok(None) };
        let v = number(line, &self.names[c], fields[c], self.decimal_comma)?;
        if let Some(v) = v {
            self.within(line, c, v, b, "")?;
        }
        Ok(v)
    }

    /// `v` (as stored) of column `c` within `b`, else an error naming line,
    /// column, value and bound (`hint` after it).
    fn within(
        &self,
        line: usize,
        c: usize,
        v: f64,
        b: &Bound,
        hint: &'static str,
    ) -> Result<(), CsvError> {
        if within(v, b) {
            return Ok(());
        }
        Err(CsvError::OutOfRange {
            line,
            column: self.names[c].clone(),
            value: v,
            bound: *b,
            hint,
        })
    }

    /// A required number of column `c`.
    fn required(&self, line: usize, fields: &[&str], c: usize) -> Result<f64, CsvError> {
        required(line, &self.names[c], fields[c], self.decimal_comma)
    }

    /// An angle read in the file's unit, in degrees.
    fn degrees(&self, v: f64) -> f64 {
        if self.radians {
            v.to_degrees()
        } else {
            v
        }
    }

    /// The joint readings [deg], each within `MAX_JOINT_DEG`.
    fn joints(&self, line: usize, fields: &[&str]) -> Result<Vec<f64>, CsvError> {
        let mut q_deg = Vec::with_capacity(self.joints.len());
        for &c in &self.joints {
            let v = self.degrees(self.required(line, fields, c)?);
            if v.abs() > MAX_JOINT_DEG {
                return Err(CsvError::JointUnits {
                    line,
                    column: self.names[c].clone(),
                    value: v,
                });
            }
            q_deg.push(v);
        }
        Ok(q_deg)
    }

    /// The measured position [mm] (`target + sign·dif` in the real-data
    /// layout), each coordinate within `MAX_POSITION_MM`.
    fn position(&self, line: usize, fields: &[&str], sign: DifSign) -> Result<[f64; 3], CsvError> {
        let length = if self.metres { 1e3 } else { 1.0 };
        let mut xyz_mm = [0.0; 3];
        let cols = match &self.position {
            PositionCols::Measured(p) => {
                for (x, &c) in xyz_mm.iter_mut().zip(p) {
                    *x = length * self.required(line, fields, c)?;
                }
                *p
            }
            PositionCols::TargetPlusDif(t, d) => {
                for i in 0..3 {
                    xyz_mm[i] = length
                        * (self.required(line, fields, t[i])?
                            + sign.factor() * self.required(line, fields, d[i])?);
                }
                *t
            }
        };
        for (x, &c) in xyz_mm.iter().zip(&cols) {
            self.within(
                line,
                c,
                *x,
                &bounds::POSITION_MM,
                " (positions are in millimetres)",
            )?;
        }
        Ok(xyz_mm)
    }

    /// The orientation as fixed-axis XYZ angles [deg]: none when the row
    /// leaves every orientation field empty, an error when it leaves some.
    fn orientation(&self, line: usize, fields: &[&str]) -> Result<Option<[f64; 3]>, CsvError> {
        let Some((conv, cols)) = &self.rot else {
            return Ok(None);
        };
        let v = cols
            .iter()
            .map(|&c| number(line, &self.names[c], fields[c], self.decimal_comma))
            .collect::<Result<Vec<_>, _>>()?;
        if v.iter().all(Option::is_none) {
            return Ok(None);
        }
        if v.iter().any(Option::is_none) {
            return Err(if conv.is_angles() {
                CsvError::PartialOrientation { line }
            } else {
                self.partial(line, cols)
            });
        }
        let v: Vec<f64> = v.into_iter().flatten().collect();
        let v: Vec<f64> = if conv.is_angles() {
            v.into_iter().map(|a| self.degrees(a)).collect()
        } else {
            v
        };
        let rpy = conv.to_fixed_xyz_deg(&v).map_err(|e| match e {
            OrientationValueError::NonUnitQuaternion { norm } => {
                CsvError::NonUnitQuaternion { line, norm }
            }
        })?;
        for (a, &c) in rpy.iter().zip(cols) {
            self.within(line, c, *a, &bounds::ANGLE_DEG, "")?;
        }
        Ok(Some(rpy))
    }

    /// The orientation's standard deviations [deg]; a row without an
    /// orientation must leave them empty.
    fn std_deg(
        &self,
        line: usize,
        fields: &[&str],
        oriented: bool,
    ) -> Result<Option<[f64; 3]>, CsvError> {
        match self.std_rot {
            Some(cols) if !oriented => {
                if let Some(&c) = cols.iter().find(|&&c| !fields[c].is_empty()) {
                    return Err(CsvError::BadStd {
                        line,
                        column: self.names[c].clone(),
                        what: "an orientation standard deviation on a row without an orientation"
                            .into(),
                    });
                }
                Ok(None)
            }
            cols => self.std(line, fields, cols, self.degrees(1.0), &bounds::STD_DEG),
        }
    }

    /// The row's data role, if its `set` field names one.
    fn set(&self, line: usize, fields: &[&str]) -> Result<Option<SetRole>, CsvError> {
        match self.set {
            Some(c) if !fields[c].is_empty() => {
                SetRole::parse(fields[c])
                    .map(Some)
                    .ok_or_else(|| CsvError::UnknownSet {
                        line,
                        value: fields[c].to_string(),
                    })
            }
            _ => Ok(None),
        }
    }

    /// The row's tracker session, if named (as written: `read_text`): at
    /// most 64 characters, none a control character.
    fn session(&self, line: usize, fields: &[&str]) -> Result<Option<String>, CsvError> {
        match self.session {
            Some(c) if !fields[c].is_empty() => {
                let v = read_text(fields[c]);
                if v.chars().count() > 64 || v.chars().any(|ch| ch.is_control()) {
                    return Err(CsvError::BadSession {
                        line,
                        value: short_text(&v),
                    });
                }
                Ok(Some(v.into_owned()))
            }
            _ => Ok(None),
        }
    }

    fn partial(&self, line: usize, cols: &[usize]) -> CsvError {
        CsvError::PartialColumns {
            line,
            columns: cols
                .iter()
                .map(|&c| self.names[c].as_str())
                .collect::<Vec<_>>()
                .join(", "),
        }
    }

    /// Three standard deviations (scaled by `unit` into mm or degrees); when
    /// the columns exist every row gives all three, each > 0 and, as stored,
    /// within `b`.
    fn std(
        &self,
        line: usize,
        fields: &[&str],
        cols: Option<[usize; 3]>,
        unit: f64,
        b: &Bound,
    ) -> Result<Option<[f64; 3]>, CsvError> {
        let Some(cols) = cols else { return Ok(None) };
        let mut out = [0.0; 3];
        for (o, &c) in out.iter_mut().zip(&cols) {
            let bad = |what: String| CsvError::BadStd {
                line,
                column: self.names[c].clone(),
                what,
            };
            let v = number(line, &self.names[c], fields[c], self.decimal_comma)?;
            *o = match v {
                None => {
                    return Err(bad(
                        "empty: the file has standard-deviation columns, so every row gives them (or leave the columns out)"
                            .into(),
                    ))
                }
                Some(v) if v <= 0.0 => {
                    return Err(bad(format!(
                        "{} is not a standard deviation (must be > 0)",
                        short_number(v)
                    )))
                }
                Some(v) => v * unit,
            };
            self.within(line, c, *o, b, "")?;
        }
        Ok(Some(out))
    }
}
