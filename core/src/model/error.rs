//! The one error of a model description or model file: the field it names
//! and why, an unknown preset, or JSON that does not parse.

/// An error in a model description, naming the field.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModelError {
    #[error("model field `{field}`: {reason}")]
    InvalidField { field: String, reason: String },
    #[error("unknown robot preset `{0}` (known presets: ys100, hh800, ur5, ur10)")]
    UnknownPreset(String),
    #[error("cannot read model JSON: {0}")]
    Parse(String),
}
