//! CSV text as robocal reads it: the one reader behind the measurement files
//! (`measure::csv`) and the target files (`ik::targets_csv`), on the `csv`
//! crate (quoted fields, record positions) with robocal's own rules on top:
//!
//! - a UTF-8 byte-order mark is ignored; lines whose first non-blank character
//!   is `#` are comments; blank lines are ignored; fields are trimmed;
//! - the first remaining line is the header;
//! - the field delimiter is `,`, `;` or a tab: declared, or detected as the
//!   one of the three that occurs most often in the header (ties go to `,`);
//! - the decimal separator is `.`, or `,` when the delimiter is not `,`
//!   (tracker software in many locales writes `1523,2;12,5;980,1`): declared,
//!   or accepted in either form when the delimiter allows it; a declared
//!   decimal comma in a `,`-separated text is read in quoted fields (`"1523,2"`);
//! - every record keeps its 1-based line number for messages.
//!
//! Whether a record has as many fields as the header is checked by
//! [`Table::check_shape`], the one row-shape check of every reader (it names
//! the line and the first column or field that does not fit).

use std::borrow::Cow;

/// The decimal separator of numeric fields.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Decimal {
    /// `1523.2`.
    Point,
    /// `1523,2` (needs `;` or a tab as the delimiter).
    Comma,
}

impl Decimal {
    /// `point` / `.` or `comma` / `,`.
    pub fn parse(text: &str) -> Option<Decimal> {
        match text.trim().to_ascii_lowercase().as_str() {
            "point" | "." | "dot" => Some(Decimal::Point),
            "comma" | "," => Some(Decimal::Comma),
            _ => None,
        }
    }
}

/// How to read a text: each `None` is detected.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Dialect {
    /// `b','`, `b';'` or `b'\t'`.
    pub delimiter: Option<u8>,
    /// `.` or `,` as the decimal separator of numeric fields.
    pub decimal: Option<Decimal>,
}

/// The delimiters robocal reads.
pub const DELIMITERS: [u8; 3] = [b',', b';', b'\t'];

/// A delimiter by name: `,` / `comma`, `;` / `semicolon`, `tab` / `\t`.
pub fn parse_delimiter(text: &str) -> Option<u8> {
    match text {
        "," | "comma" => Some(b','),
        ";" | "semicolon" => Some(b';'),
        "\t" | "tab" | "\\t" => Some(b'\t'),
        _ => None,
    }
}

/// Why a text cannot be read as a table.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum TextError {
    /// The delimiter given is not `,`, `;` or a tab.
    #[error("the delimiter must be `,`, `;` or a tab")]
    BadDelimiter,
    /// The CSV reader failed (an unclosed quote, a bad encoding).
    #[error("line {line}: {message}")]
    Malformed {
        /// 1-based line where the reader failed (0 when it does not say).
        line: usize,
        /// The reader's message.
        message: String,
    },
}

/// Where a record's fields and its header's columns part (see [`FieldCount`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Misfit {
    /// The record ends before column `column` (1-based `index`).
    Missing {
        /// 1-based index of the column.
        index: usize,
        /// The column's name.
        column: String,
    },
    /// Field `index` (1-based) holds `value` beyond the last column `last`.
    Extra {
        /// 1-based index of the field.
        index: usize,
        /// The field as written.
        value: String,
        /// The header's last column.
        last: String,
        /// The text is `,`-separated (where a decimal comma splits a number).
        comma_delimited: bool,
    },
}

impl std::fmt::Display for Misfit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Misfit::Missing { index, column } => {
                write!(f, "column {index} `{column}` has no field")
            }
            Misfit::Extra {
                index,
                value,
                last,
                comma_delimited,
            } => {
                write!(
                    f,
                    "field {index} `{}` is beyond the last column `{last}`",
                    short_text(value)
                )?;
                if *comma_delimited {
                    write!(
                        f,
                        "; a decimal comma splits a number in two in a comma-separated file \
                         (write `8.85`, quote `\"8,85\"`, or separate the fields with `;`)"
                    )?;
                }
                Ok(())
            }
        }
    }
}

/// A record whose field count is not its header's: every column after the
/// place where they part would be read shifted, so the record is refused,
/// naming its line and the first column (or field) that does not fit.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("line {line}: {got} fields, the header has {expected}: {misfit}")]
pub struct FieldCount {
    /// 1-based line of the record in the text.
    pub line: usize,
    /// Fields in the record.
    pub got: usize,
    /// Columns in the header.
    pub expected: usize,
    /// Where the record and the header part.
    pub misfit: Misfit,
}

/// One record after the header.
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    /// 1-based line of the record in the text.
    pub line: usize,
    /// The record's fields, in header order, trimmed.
    pub fields: Vec<String>,
}

/// A text read as a header and records.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// The delimiter, given or detected: `b','`, `b';'` or `b'\t'`.
    pub delimiter: u8,
    /// Whether numeric fields may use a decimal comma.
    pub decimal_comma: bool,
    /// 1-based line of the header in the text.
    pub header_line: usize,
    /// Header names as written (trimmed).
    pub header: Vec<String>,
    /// The records after the header, comments and blank lines left out.
    pub records: Vec<Record>,
}

impl Table {
    /// The record's field count against the header's (the one row-shape
    /// check of every reader).
    pub fn check_shape(&self, r: &Record) -> Result<(), FieldCount> {
        let (got, expected) = (r.fields.len(), self.header.len());
        if got == expected {
            return Ok(());
        }
        let misfit = if got < expected {
            Misfit::Missing {
                index: got + 1,
                column: self.header[got].clone(),
            }
        } else {
            Misfit::Extra {
                index: expected + 1,
                value: r.fields[expected].clone(),
                last: self.header.last().cloned().unwrap_or_default(),
                comma_delimited: self.delimiter == b',',
            }
        };
        Err(FieldCount {
            line: r.line,
            got,
            expected,
            misfit,
        })
    }

    /// [`Table::check_shape`] of every record, the first misfit.
    pub fn check_shapes(&self) -> Result<(), FieldCount> {
        self.records.iter().try_for_each(|r| self.check_shape(r))
    }

    /// Parses a numeric field: `None` when it is not a number in the table's
    /// decimal convention. Empty fields are the caller's business.
    pub fn number(&self, field: &str) -> Option<f64> {
        parse_number(field, self.decimal_comma)
    }
}

/// A number with `.` or, when `decimal_comma`, `,` as the decimal separator
/// (never both, and no digit grouping).
pub fn parse_number(field: &str, decimal_comma: bool) -> Option<f64> {
    let field = field.trim();
    if decimal_comma && field.contains(',') {
        if field.contains('.') || field.matches(',').count() > 1 {
            return None;
        }
        return field.replace(',', ".").parse().ok();
    }
    field.parse().ok()
}

/// A field for a message: cut to 40 characters (never a whole long line).
pub fn short_text(s: &str) -> String {
    if s.chars().count() > 40 {
        format!("{}…", s.chars().take(40).collect::<String>())
    } else {
        s.to_string()
    }
}

/// A delimiter or decimal separator name that is not one.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DialectError {
    /// The delimiter's name is not `,`, `;` or `tab`.
    #[error("the delimiter must be `,`, `;` or `tab`, got `{value}`")]
    Delimiter {
        /// The name given.
        value: String,
    },
    /// The decimal separator's name is not `point` or `comma`.
    #[error("the decimal separator must be point or comma, got `{value}`")]
    Decimal {
        /// The name given.
        value: String,
    },
}

/// Delimiter and decimal separator by name (`,` / `;` / `tab`, `point` /
/// `comma`), each `None` to detect; the error names the bad value.
pub fn dialect_from_names(
    delimiter: Option<&str>,
    decimal: Option<&str>,
) -> Result<Dialect, DialectError> {
    Ok(Dialect {
        delimiter: delimiter
            .map(|d| {
                parse_delimiter(d).ok_or_else(|| DialectError::Delimiter {
                    value: d.to_string(),
                })
            })
            .transpose()?,
        decimal: decimal
            .map(|d| {
                Decimal::parse(d).ok_or_else(|| DialectError::Decimal {
                    value: d.to_string(),
                })
            })
            .transpose()?,
    })
}

fn is_comment(line: &str) -> bool {
    line.trim_start().starts_with('#')
}

/// The delimiter that occurs most often in the header line (outside quotes).
fn detect_delimiter(header: &str) -> u8 {
    let mut counts = [0usize; 3];
    let mut quoted = false;
    for b in header.bytes() {
        if b == b'"' {
            quoted = !quoted;
        } else if !quoted {
            if let Some(i) = DELIMITERS.iter().position(|&d| d == b) {
                counts[i] += 1;
            }
        }
    }
    let best = (0..3).max_by_key(|&i| (counts[i], 3 - i)).unwrap_or(0);
    if counts[best] == 0 {
        b','
    } else {
        DELIMITERS[best]
    }
}

/// Reads a text as a header and records; `Ok(None)` when it has no header
/// line (empty, or only comments and blank lines).
pub fn read(text: &str, dialect: Dialect) -> Result<Option<Table>, TextError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    // Comment lines become blank lines, which the reader skips, so line
    // numbers stay those of the text and a quote in a comment is harmless.
    let text: Cow<str> = if text.lines().any(is_comment) {
        let mut s = String::with_capacity(text.len());
        for l in text.split_inclusive('\n') {
            if is_comment(l) {
                s.push_str(if l.ends_with("\r\n") {
                    "\r\n"
                } else if l.ends_with('\n') {
                    "\n"
                } else {
                    ""
                });
            } else {
                s.push_str(l);
            }
        }
        Cow::Owned(s)
    } else {
        Cow::Borrowed(text)
    };
    let Some(header_text) = text.lines().find(|l| !l.trim().is_empty()) else {
        return Ok(None);
    };
    let delimiter = match dialect.delimiter {
        Some(d) if DELIMITERS.contains(&d) => d,
        Some(_) => return Err(TextError::BadDelimiter),
        None => detect_delimiter(header_text),
    };
    let decimal_comma = match dialect.decimal {
        Some(Decimal::Comma) => true,
        Some(Decimal::Point) => false,
        None => delimiter != b',',
    };
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .delimiter(delimiter)
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    // Line numbers from byte offsets: a record's position is where the reader
    // started looking for it, before the blank lines it skipped.
    let line_starts: Vec<usize> = std::iter::once(0)
        .chain(text.match_indices('\n').map(|(i, _)| i + 1))
        .collect();
    let lines: Vec<&str> = text.split('\n').collect();
    let line_of = |byte: u64| {
        let mut l = line_starts.partition_point(|&s| s as u64 <= byte);
        while l < lines.len() && lines[l - 1].trim().is_empty() {
            l += 1;
        }
        l
    };
    let mut header: Option<(usize, Vec<String>)> = None;
    let mut records = Vec::new();
    let mut record = csv::StringRecord::new();
    loop {
        let more = reader.read_record(&mut record).map_err(|e| {
            let line = e.position().map_or(0, |p| line_of(p.byte()));
            TextError::Malformed {
                line,
                message: e.to_string(),
            }
        })?;
        if !more {
            break;
        }
        if record.iter().all(str::is_empty) {
            continue;
        }
        let line = record.position().map_or(0, |p| line_of(p.byte()));
        let fields: Vec<String> = record.iter().map(str::to_string).collect();
        if header.is_none() {
            header = Some((line, fields));
        } else {
            records.push(Record { line, fields });
        }
    }
    Ok(header.map(|(header_line, header)| Table {
        delimiter,
        decimal_comma,
        header_line,
        header,
        records,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(text: &str) -> Table {
        read(text, Dialect::default()).unwrap().unwrap()
    }

    #[test]
    fn comments_blank_lines_and_line_numbers() {
        let t = table("\u{feff}# a \"quoted comment\n\n  # indented\nx,y\n\n1,2\n   \n# c\n3, 4\n");
        assert_eq!(t.header_line, 4);
        assert_eq!(t.header, ["x", "y"]);
        assert_eq!(t.records.len(), 2);
        assert_eq!(t.records[0].line, 6);
        assert_eq!(t.records[1].line, 9);
        assert_eq!(t.records[1].fields, ["3", "4"]);
        assert!(read("# only\n\n", Dialect::default()).unwrap().is_none());
    }

    #[test]
    fn quoted_fields_keep_their_delimiters() {
        let t = table("id,x\n\"a,b\",1\n");
        assert_eq!(t.records[0].fields, ["a,b", "1"]);
    }

    #[test]
    fn semicolons_and_decimal_commas_are_detected() {
        let t = table("x;y;z\n1523,25;-12,5;980\n");
        assert_eq!(t.delimiter, b';');
        assert!(t.decimal_comma);
        let v: Vec<f64> = t.records[0]
            .fields
            .iter()
            .map(|f| t.number(f).unwrap())
            .collect();
        assert_eq!(v, [1523.25, -12.5, 980.0]);
        let t = table("x\ty\n1,5\t2.5\n");
        assert_eq!(t.delimiter, b'\t');
        assert_eq!(t.number("1,5"), Some(1.5));
        // A comma-separated file never reads a decimal comma.
        let t = table("x,y\n1.5,2\n");
        assert!(!t.decimal_comma);
        assert_eq!(t.number("1,5"), None);
    }

    #[test]
    fn declared_dialects_win() {
        let d = Dialect {
            delimiter: Some(b';'),
            decimal: Some(Decimal::Point),
        };
        let t = read("x,y;z\n1,5;2\n", d).unwrap().unwrap();
        assert_eq!(t.header, ["x,y", "z"]);
        assert_eq!(t.number("1,5"), None);
        // A decimal comma in a comma-separated text: quoted fields.
        let d = Dialect {
            delimiter: Some(b','),
            decimal: Some(Decimal::Comma),
        };
        let t = read("x,y\n\"1,5\",2.25\n", d).unwrap().unwrap();
        assert_eq!(t.delimiter, b',');
        let v: Vec<Option<f64>> = t.records[0].fields.iter().map(|f| t.number(f)).collect();
        assert_eq!(v, [Some(1.5), Some(2.25)]);
    }

    #[test]
    fn dialect_names() {
        let d = dialect_from_names(Some("tab"), Some("comma")).unwrap();
        assert_eq!(
            (d.delimiter, d.decimal),
            (Some(b'\t'), Some(Decimal::Comma))
        );
        let e = dialect_from_names(Some("|"), None).unwrap_err();
        assert_eq!(e, DialectError::Delimiter { value: "|".into() });
        assert_eq!(
            e.to_string(),
            "the delimiter must be `,`, `;` or `tab`, got `|`"
        );
        let e = dialect_from_names(None, Some("dot,")).unwrap_err();
        assert_eq!(
            e.to_string(),
            "the decimal separator must be point or comma, got `dot,`"
        );
    }

    #[test]
    fn a_record_of_another_width_names_the_column_where_it_parts() {
        let t = table("pose,cycle,x_mm,y_mm,z_mm\nP1,1,600,0,400\nP1,2,600,0,8,85\nP1,3,600\n");
        assert_eq!(t.check_shape(&t.records[0]), Ok(()));
        let e = t.check_shape(&t.records[1]).unwrap_err();
        assert_eq!((e.line, e.got, e.expected), (3, 6, 5));
        assert!(
            e.to_string().starts_with(
                "line 3: 6 fields, the header has 5: field 6 `85` is beyond the last column `z_mm`; a decimal comma"
            ),
            "{e}"
        );
        let e = t.check_shape(&t.records[2]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "line 4: 3 fields, the header has 5: column 4 `y_mm` has no field"
        );
        assert_eq!(
            t.check_shapes(),
            Err(t.check_shape(&t.records[1]).unwrap_err())
        );
        // No decimal-comma hint where the delimiter is not a comma.
        let t = table("a;b\n1;2;3\n");
        let e = t.check_shapes().unwrap_err().to_string();
        assert_eq!(
            e,
            "line 2: 3 fields, the header has 2: field 3 `3` is beyond the last column `b`"
        );
    }

    #[test]
    fn grouped_or_mixed_separators_are_not_numbers() {
        assert_eq!(parse_number("1.234,5", true), None);
        assert_eq!(parse_number("1,234,5", true), None);
        assert_eq!(parse_number("-0,25", true), Some(-0.25));
        assert_eq!(parse_number("2e3", true), Some(2000.0));
    }
}
