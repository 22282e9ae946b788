//! The one error type of the core. Messages name the argument or file element, what was expected
//! and what was received.

use crate::dispatch::multiversion;
use thiserror::Error;

/// Everything that can go wrong when building a model or calling an algorithm.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum Error {
    /// A model file does not exist.
    #[error("model file not found: '{path}'")]
    FileNotFound {
        /// The path that was looked up.
        path: String,
    },

    /// A model description is malformed or inconsistent. `location` names the file, element and
    /// line where known.
    #[error("{location}: {message}")]
    InvalidModel {
        /// Where the problem is: file, element and line where known.
        location: String,
        /// What is wrong there.
        message: String,
    },

    /// An input array has the wrong length.
    #[error("argument '{argument}': expected {expected}, got {received}")]
    Shape {
        /// Name of the offending argument.
        argument: String,
        /// The length or shape that was expected.
        expected: String,
        /// The length or shape that was received.
        received: String,
    },

    /// An input holds NaN or an infinite value.
    #[error("argument '{argument}': expected finite values, got {value} at index {index}")]
    NotFinite {
        /// Name of the offending argument.
        argument: String,
        /// Index of the first non-finite entry.
        index: usize,
        /// The non-finite value found there.
        value: f64,
    },

    /// An input value is finite but outside what the argument accepts (e.g. a non-unit quaternion).
    #[error("argument '{argument}': {message}")]
    InvalidValue {
        /// Name of the offending argument.
        argument: String,
        /// What was expected and what was received.
        message: String,
    },

    /// Finite inputs so large that a result overflowed.
    #[error("the result is not finite (entry {index} is {value}): the inputs are too large for float64 arithmetic")]
    Overflow {
        /// Index of the first non-finite entry of the result.
        index: usize,
        /// The non-finite value found there.
        value: f64,
    },

    /// A simulation could not go on at time `time` (s): the state diverged, the controller or
    /// the wrenches gave something unusable, or the equations became too stiff.
    #[error("simulation stopped at t = {time} s: {message}")]
    Simulation {
        /// Simulation time (s) at which it stopped.
        time: f64,
        /// Why it stopped.
        message: String,
    },

    /// A simulation left the bounds of a sensible motion at time `time` (s): a non-finite state,
    /// a speed or an energy beyond its bound, or a fixed step far too large for the dynamics.
    #[error("simulation diverged at t = {time:.6} s: {message}")]
    Diverged {
        /// Simulation time (s) at which the divergence was detected.
        time: f64,
        /// Which bound was left.
        message: String,
    },

    /// A frame name that the model does not have.
    #[error("unknown frame '{name}': the model's frames are {available}")]
    UnknownFrame {
        /// The frame name that was asked for.
        name: String,
        /// The model's frame names, listed for the message.
        available: String,
    },
}

/// Result with the core's [`enum@Error`].
pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    /// Shorthand for [`Error::InvalidModel`].
    pub fn model(location: impl Into<String>, message: impl Into<String>) -> Self {
        Error::InvalidModel {
            location: location.into(),
            message: message.into(),
        }
    }
}

impl Error {
    /// The same error about argument `argument`, for a value checked under another name (a
    /// configuration checked as `q` that the caller knows as `q0`).
    pub fn for_argument(self, argument: &str) -> Self {
        let argument = argument.to_string();
        match self {
            Error::Shape {
                expected, received, ..
            } => Error::Shape {
                argument,
                expected,
                received,
            },
            Error::NotFinite { index, value, .. } => Error::NotFinite {
                argument,
                index,
                value,
            },
            Error::InvalidValue { message, .. } => Error::InvalidValue { argument, message },
            other => other,
        }
    }
}

/// Checks that an argument has `expected` entries. The checks are inlined into every call that
/// makes them (a few instructions each), their errors built out of line.
#[inline]
pub fn check_length(argument: &str, length: usize, expected: usize) -> Result<()> {
    if length == expected {
        return Ok(());
    }
    Err(length_error(argument, length, expected))
}

/// The error of [`check_length`].
#[cold]
#[inline(never)]
fn length_error(argument: &str, length: usize, expected: usize) -> Error {
    Error::Shape {
        argument: argument.to_string(),
        expected: format!("length {expected}"),
        received: format!("length {length}"),
    }
}

/// Checks that `values` has `expected` entries, all finite.
#[inline]
pub fn check_vector(argument: &str, values: &[f64], expected: usize) -> Result<()> {
    check_length(argument, values.len(), expected)?;
    check_finite(argument, values)
}

/// Whether every entry of `values` is finite, in one pass without an early exit: a value is not
/// finite exactly when its exponent bits are all set, tested on every value and or-ed (vectorised,
/// with AVX-512 or AVX2 where the processor has it: results are checked this way after every call,
/// a batch's megabytes at a time). A few values (a state of a small robot, its result) take the
/// plain loop inlined where it is called: the choice of instruction set costs more than they do.
#[inline]
pub fn all_finite(values: &[f64]) -> bool {
    const FEW: usize = 16;
    if values.len() <= FEW {
        return all_finite_generic(values);
    }
    all_finite_wide(values)
}

multiversion! {
    /// [`all_finite`] of many values, in the widest vectors the processor has.
    fn all_finite_wide(values: &[f64]) -> bool {
        all_finite_avx512 for ["avx512f"] => { all_finite_generic(values) }
        all_finite_avx2 for ["avx2"] => { all_finite_generic(values) }
        baseline => { all_finite_generic(values) }
    }
}

#[inline(always)]
fn all_finite_generic(values: &[f64]) -> bool {
    const EXPONENT: u64 = 0x7ff0_0000_0000_0000;
    let not_finite = values
        .iter()
        .fold(false, |any, x| any | (x.to_bits() & EXPONENT == EXPONENT));
    !not_finite
}

/// Checks that every entry of `values` is finite.
#[inline]
pub fn check_finite(argument: &str, values: &[f64]) -> Result<()> {
    if all_finite(values) {
        return Ok(());
    }
    first_not_finite(argument, values)
}

/// The error of [`check_finite`] for values that are not all finite.
#[cold]
#[inline(never)]
fn first_not_finite(argument: &str, values: &[f64]) -> Result<()> {
    match values.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(index) => Err(Error::NotFinite {
            argument: argument.to_string(),
            index,
            value: values[index],
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn all_finite_finds_every_non_finite_entry_wherever_it_is() {
        let finite = [0.0, -0.0, 1e308, -1e308, f64::MIN_POSITIVE / 4.0, 3.5];
        // lengths below, at and past whole vectors and unrolled loops
        for length in 0..150 {
            let values: Vec<f64> = (0..length).map(|k| finite[k % finite.len()]).collect();
            assert!(all_finite(&values), "length {length}");
            assert!(all_finite_generic(&values), "length {length}");
            for index in 0..length {
                for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                    let mut with_bad = values.clone();
                    with_bad[index] = bad;
                    assert!(!all_finite(&with_bad), "{bad} at {index} of {length}");
                    assert!(
                        !all_finite_generic(&with_bad),
                        "{bad} at {index} of {length}"
                    );
                    let error = check_finite("x", &with_bad).unwrap_err();
                    assert!(
                        matches!(error, Error::NotFinite { index: i, .. } if i == index),
                        "{error}"
                    );
                }
            }
        }
    }
}
