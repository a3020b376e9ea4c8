//! CANDIDE-3 shape-unit problems (`.wfm` syntax errors are located
//! [`crate::error::ParseError`]s).

/// A CANDIDE-3 problem. Every variant is bad input (exit code 2).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CandideError {
    /// A shape-unit value is NaN or infinite.
    #[error("shape unit `{unit}`: value {value} is not finite")]
    NonFiniteShapeValue {
        /// The unit's name.
        unit: String,
        /// The value.
        value: f32,
    },
    /// No shape unit has this name.
    #[error("unknown shape unit `{name}`; valid names: {valid}")]
    UnknownShapeUnit {
        /// The name asked for.
        name: String,
        /// The model's unit names, comma-separated.
        valid: String,
    },
    /// A shape unit moves a vertex the model does not have.
    #[error("shape unit `{unit}` moves vertex {vertex}, which does not exist")]
    MissingVertex {
        /// The unit's name.
        unit: String,
        /// The 0-based vertex.
        vertex: u32,
    },
    /// A shape specification item is not `name=value`.
    #[error("shape spec item `{item}`: expected name=value")]
    ShapeSpecItem {
        /// The item.
        item: String,
    },
    /// A shape specification item's value is not a finite number.
    #[error("shape spec item `{item}`: expected a finite number after `=`")]
    ShapeSpecValue {
        /// The item.
        item: String,
    },
}

impl CandideError {
    /// Always true: every CANDIDE-3 problem is bad input.
    pub fn is_input_error(&self) -> bool {
        true
    }
}
