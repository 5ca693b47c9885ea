//! Errors of the core: small, `Copy`, naming the offending setting.

use core::fmt;

/// Why a setting or an argument was refused. Carries the name of the setting (as in
/// [`crate::Config`]) or of the argument.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Error {
    /// The setting is NaN or infinite.
    NonFinite(&'static str),
    /// The setting is finite but outside its valid range.
    OutOfRange(&'static str),
    /// The argument, a slice, is not as long as the block's times
    /// ([`crate::Pipeline::push_block`]).
    LengthMismatch(&'static str),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::NonFinite(name) => write!(f, "setting `{name}` is not a finite number"),
            Error::OutOfRange(name) => write!(f, "setting `{name}` is out of its valid range"),
            Error::LengthMismatch(name) => {
                write!(f, "`{name}` is not as long as the block's times")
            }
        }
    }
}

impl core::error::Error for Error {}

/// `Ok(value)` if `value` is finite and within `[min, max]`, else the matching error.
pub(crate) fn check_range(
    name: &'static str,
    value: f64,
    min: f64,
    max: f64,
) -> Result<f64, Error> {
    if !value.is_finite() {
        Err(Error::NonFinite(name))
    } else if value < min || value > max {
        Err(Error::OutOfRange(name))
    } else {
        Ok(value)
    }
}
