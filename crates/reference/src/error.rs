//! The crate's error type and the parameter checks shared by all modules.

use thiserror::Error;

/// Why a reference solution could not be evaluated.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ReferenceError {
    /// A real-valued parameter broke its rule (for example "must be positive and finite").
    #[error("invalid {name} = {value}: {rule}")]
    InvalidParameter {
        /// Name of the parameter, as in the function signature.
        name: &'static str,
        /// The value that was passed.
        value: f64,
        /// The rule it broke.
        rule: &'static str,
    },
    /// An integer parameter (a mode number, a sample count) broke its rule.
    #[error("invalid {name} = {value}: {rule}")]
    InvalidCount {
        /// Name of the parameter.
        name: &'static str,
        /// The value that was passed.
        value: usize,
        /// The rule it broke.
        rule: &'static str,
    },
    /// A list parameter was empty.
    #[error("{name} must not be empty")]
    Empty {
        /// Name of the list parameter.
        name: &'static str,
    },
    /// The ODE integrator failed (it should not for valid parameters).
    #[error("ODE integration failed at t = {t} s: {message}")]
    Integration {
        /// Time (s) at which the integrator stopped.
        t: f64,
        /// The integrator's message.
        message: String,
    },
}

/// `value` must be finite and > 0.
pub(crate) fn positive(name: &'static str, value: f64) -> Result<f64, ReferenceError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(ReferenceError::InvalidParameter { name, value, rule: "must be positive and finite" })
    }
}

/// `value` must be finite and >= 0.
pub(crate) fn non_negative(name: &'static str, value: f64) -> Result<f64, ReferenceError> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(ReferenceError::InvalidParameter { name, value, rule: "must be non-negative and finite" })
    }
}

/// `value` must be finite (any sign).
pub(crate) fn finite(name: &'static str, value: f64) -> Result<f64, ReferenceError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(ReferenceError::InvalidParameter { name, value, rule: "must be finite" })
    }
}

/// `value` must lie in `[lo, hi]` (and be finite); `rule` describes the interval.
pub(crate) fn within(
    name: &'static str,
    value: f64,
    lo: f64,
    hi: f64,
    rule: &'static str,
) -> Result<f64, ReferenceError> {
    if value.is_finite() && (lo..=hi).contains(&value) {
        Ok(value)
    } else {
        Err(ReferenceError::InvalidParameter { name, value, rule })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checks_reject_bad_values_and_name_them() {
        assert!(positive("radius", 1.0).is_ok());
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let e = positive("radius", bad).unwrap_err();
            assert!(e.to_string().contains("radius"), "{e}");
        }
        assert!(non_negative("t", 0.0).is_ok());
        assert!(non_negative("t", -1e-300).is_err());
        assert!(finite("force", -3.0).is_ok());
        assert!(finite("force", f64::NEG_INFINITY).is_err());
        assert!(within("y", 0.5, 0.0, 1.0, "must lie in [0, width]").is_ok());
        let e = within("y", 1.5, 0.0, 1.0, "must lie in [0, width]").unwrap_err();
        assert_eq!(e.to_string(), "invalid y = 1.5: must lie in [0, width]");
    }
}
