//! The one error of a model description or model file: the field it names
//! and why, an unknown preset, or JSON that does not parse.

/// An error in a model description, naming the field.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// A field of the description is out of range or inconsistent.
    #[error("model field `{field}`: {reason}")]
    InvalidField {
        /// The field's path (`joints[1].limits_deg`, `payload.com_mm`, …).
        field: String,
        /// What is wrong with it.
        reason: String,
    },
    /// No preset has this name; the name given.
    #[error("unknown robot preset `{0}` (known presets: ys100, hh800, ur5, ur10)")]
    UnknownPreset(String),
    /// The text is not valid model JSON; the parser's message.
    #[error("cannot read model JSON: {0}")]
    Parse(String),
}
