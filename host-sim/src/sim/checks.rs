//! Range checks shared by the simulator's parameter structs (`params`, `terms`, `spec`,
//! `base`, `turntable`): each refuses a value with the parameter's name, the value and
//! the rule it broke. A module of its own so that `params` (which holds the extra drift
//! terms) and `terms` (whose terms validate themselves) do not import each other.

use super::error::SimError;

/// `Ok` when `ok`, else a `BadParameter` error naming `name`, `v` and `why`.
fn require(name: &'static str, v: f64, ok: bool, why: &'static str) -> Result<(), SimError> {
    if ok {
        Ok(())
    } else {
        Err(SimError::BadParameter {
            name,
            value: v,
            why,
        })
    }
}

/// `v` is a finite number.
pub(crate) fn finite(name: &'static str, v: f64) -> Result<(), SimError> {
    require(name, v, v.is_finite(), "must be finite")
}

/// `v` is finite and > 0.
pub(crate) fn positive(name: &'static str, v: f64) -> Result<(), SimError> {
    require(name, v, v.is_finite() && v > 0.0, "must be > 0")
}

/// `v` is finite and >= 0.
pub(crate) fn non_negative(name: &'static str, v: f64) -> Result<(), SimError> {
    require(name, v, v.is_finite() && v >= 0.0, "must be >= 0")
}

/// `v` is within 0..=1.
pub(crate) fn fraction(name: &'static str, v: f64) -> Result<(), SimError> {
    require(name, v, (0.0..=1.0).contains(&v), "must be within 0..=1")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checks_name_the_parameter_and_the_rule() {
        assert!(finite("a", 1.0).is_ok());
        assert!(positive("a", 1e-300).is_ok());
        assert!(non_negative("a", 0.0).is_ok());
        assert!(fraction("a", 1.0).is_ok());
        for (r, why) in [
            (finite("a", f64::NAN), "must be finite"),
            (positive("a", 0.0), "must be > 0"),
            (positive("a", f64::INFINITY), "must be > 0"),
            (non_negative("a", -1e-300), "must be >= 0"),
            (fraction("a", 1.5), "must be within 0..=1"),
            (fraction("a", f64::NAN), "must be within 0..=1"),
        ] {
            match r {
                Err(SimError::BadParameter { name, why: w, .. }) => {
                    assert_eq!((name, w), ("a", why));
                }
                other => panic!("{other:?}"),
            }
        }
    }
}
