//! A track value per row: the `e1` column of a joints file, beside the
//! joints, read in the same dialect as the joints (`solve::cell::joints_csv`
//! ignores columns it does not know, so the file reads there unchanged).
//!
//! Units: the track's value in mm as the controller shows it. Every row
//! gives a finite value; the values are matched to the joint readings by
//! their line in the text.

use crate::measure::csv_text::{self, short_text, Dialect, FieldCount, TextError};

/// The track value column a joints file may carry.
pub const TRACK_COLUMN: &str = "e1";

/// One row's track value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RowValue {
    /// 1-based line of the row in the text.
    pub line: usize,
    /// The track's value [mm].
    pub value_mm: f64,
}

/// Why a file's track values cannot be read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TrackColumnError {
    /// The text is not a table.
    #[error(transparent)]
    Text(#[from] TextError),
    /// A row whose field count is not the header's.
    #[error(transparent)]
    Shape(#[from] FieldCount),
    /// The header names the column twice.
    #[error("line {line}: the header names `{column}` twice")]
    Duplicate {
        /// 1-based line of the header.
        line: usize,
        /// The column.
        column: String,
    },
    /// A row's value is not a finite number.
    #[error("line {line}: `{TRACK_COLUMN}` is `{value}`, not a finite number of mm")]
    NotNumber {
        /// 1-based line of the row.
        line: usize,
        /// The field (shortened).
        value: String,
    },
}

/// The index of `column` (any ASCII case) in a header read at line
/// `header_line`, `None` when the header does not name it; a header naming it
/// twice is refused.
pub(super) fn column_index(
    header: &[String],
    header_line: usize,
    column: &str,
) -> Result<Option<usize>, TrackColumnError> {
    let mut at = header
        .iter()
        .enumerate()
        .filter(|(_, h)| h.eq_ignore_ascii_case(column))
        .map(|(i, _)| i);
    let first = at.next();
    if first.is_some() && at.next().is_some() {
        return Err(TrackColumnError::Duplicate {
            line: header_line,
            column: column.to_string(),
        });
    }
    Ok(first)
}

/// The `e1` values of every row of `text`, or `None` when its header has
/// no `e1` column (any ASCII case) or it has no header.
pub fn track_values(
    text: &str,
    dialect: Dialect,
) -> Result<Option<Vec<RowValue>>, TrackColumnError> {
    let Some(table) = csv_text::read(text, dialect)? else {
        return Ok(None);
    };
    let Some(col) = column_index(&table.header, table.header_line, TRACK_COLUMN)? else {
        return Ok(None);
    };
    table
        .records
        .iter()
        .map(|r| {
            table.check_shape(r)?;
            let field = &r.fields[col];
            let value_mm = table
                .number(field)
                .filter(|v| v.is_finite())
                .ok_or_else(|| TrackColumnError::NotNumber {
                    line: r.line,
                    value: short_text(field),
                })?;
            Ok(RowValue {
                line: r.line,
                value_mm,
            })
        })
        .collect::<Result<Vec<_>, _>>()
        .map(Some)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_are_read_per_row_in_the_files_dialect() {
        let text = "id;q1;E1;q2\na;1;1500,5;2\nb;3;-20;4\n";
        let d = Dialect::default();
        let v = track_values(text, d).unwrap().unwrap();
        assert_eq!(
            v,
            vec![
                RowValue {
                    line: 2,
                    value_mm: 1500.5
                },
                RowValue {
                    line: 3,
                    value_mm: -20.0
                }
            ]
        );
        assert_eq!(track_values("q1,q2\n1,2\n", d).unwrap(), None);
        assert_eq!(
            track_values("q1,e1\n1,x\n", d).unwrap_err(),
            TrackColumnError::NotNumber {
                line: 2,
                value: "x".into()
            }
        );
        assert_eq!(
            track_values("e1,q1,e1\n1,2,3\n", d).unwrap_err(),
            TrackColumnError::Duplicate {
                line: 1,
                column: "e1".into()
            }
        );
    }
}
