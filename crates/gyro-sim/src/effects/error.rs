//! Why an effect specification or parameter set is rejected.

use super::spec::ParamRange;

/// An invalid effect: unknown id or parameter, a value that is not a number, or one out
/// of its parameter's range.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum EffectError {
    /// No effect has this id.
    #[error("unknown effect `{id}` (known: {})", known.join(", "))]
    UnknownEffect {
        /// The id given.
        id: String,
        /// Every known id.
        known: Vec<&'static str>,
    },
    /// A parameter assignment without `=`.
    #[error("effect `{id}`: expected name=value, found `{pair}`")]
    ExpectedNameValue {
        /// Effect id.
        id: String,
        /// What was found.
        pair: String,
    },
    /// The effect has no parameter of this name.
    #[error("effect `{id}` has no parameter `{name}` (it has: {})", names.join(", "))]
    UnknownParam {
        /// Effect id.
        id: String,
        /// The name given.
        name: String,
        /// The effect's parameter names.
        names: Vec<&'static str>,
    },
    /// A value that is not a finite number.
    #[error("effect `{id}`: `{value}` is not a finite number")]
    NotANumber {
        /// Effect id.
        id: String,
        /// The text given.
        value: String,
    },
    /// A parameter value that is not finite.
    #[error("effect `{id}`: parameters must be finite")]
    NotFinite {
        /// Effect id.
        id: &'static str,
    },
    /// The wrong number of parameter values for the effect.
    #[error("effect `{id}`: wrong number of parameters")]
    ParamCount {
        /// Effect id.
        id: &'static str,
    },
    /// A parameter out of its range.
    #[error("effect `{id}`: {param} must be {range}")]
    OutOfRange {
        /// Effect id.
        id: &'static str,
        /// Parameter name.
        param: &'static str,
        /// Its valid range.
        range: ParamRange,
    },
}
