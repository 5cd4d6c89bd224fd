//! Range and finiteness checks whose errors name the field.

use crate::error::{Error, Result};
use crate::model::TimeFunction;

/// `v` is positive and finite.
pub fn positive(field: &str, v: f64) -> Result<()> {
    if v > 0.0 && v.is_finite() {
        Ok(())
    } else {
        Err(Error::config(
            field,
            format!("must be positive and finite, got {v:?}"),
        ))
    }
}

/// Every entry of `v` is finite; the error names the first one that is not.
pub fn finite(field: &str, v: &[f64]) -> Result<()> {
    match v.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(i) if v.len() == 1 => Err(Error::config(
            field,
            format!("must be finite, got {:?}", v[i]),
        )),
        Some(i) => Err(Error::config(
            format!("{field}[{i}]"),
            format!("must be finite, got {:?}", v[i]),
        )),
    }
}

/// `v` is finite and not negative.
pub(crate) fn non_negative(field: &str, v: f64) -> Result<()> {
    if v >= 0.0 && v.is_finite() {
        Ok(())
    } else {
        Err(Error::config(
            field,
            format!("must be non-negative and finite, got {v:?}"),
        ))
    }
}

/// `v` lies in `lo..=hi`.
pub(crate) fn count_in(field: &str, v: usize, lo: usize, hi: usize, why: &str) -> Result<()> {
    if (lo..=hi).contains(&v) {
        Ok(())
    } else {
        Err(Error::config(
            field,
            format!("must lie in {lo}..={hi} ({why}), got {v}"),
        ))
    }
}

/// Young's modulus, Poisson's ratio and density of an isotropic material.
pub(crate) fn check_elastic(field: &str, e: f64, nu: f64, rho: f64) -> Result<()> {
    positive(&format!("{field}.E"), e)?;
    positive(&format!("{field}.rho"), rho)?;
    if !(nu > -1.0 && nu < 0.5) {
        return Err(Error::config(
            format!("{field}.nu"),
            format!("Poisson's ratio must lie in (-1, 0.5), got {nu:?}"),
        ));
    }
    Ok(())
}

/// Every number of a time function is finite and its shape is valid.
pub fn check_function(field: &str, f: &TimeFunction) -> Result<()> {
    match f {
        TimeFunction::Constant => Ok(()),
        TimeFunction::Step { at } => finite(&format!("{field}.at"), &[*at]),
        TimeFunction::Ramp { t0, t1 } => {
            finite(&format!("{field}.t0"), &[*t0])?;
            finite(&format!("{field}.t1"), &[*t1])?;
            if t1 > t0 {
                Ok(())
            } else {
                Err(Error::config(
                    field,
                    format!("ramp needs t1 > t0, got t0 = {t0}, t1 = {t1}"),
                ))
            }
        }
        TimeFunction::Table { points } => {
            if points.is_empty() {
                return Err(Error::config(
                    format!("{field}.points"),
                    "table needs at least one [t, value] point",
                ));
            }
            for (i, p) in points.iter().enumerate() {
                finite(&format!("{field}.points[{i}]"), p)?;
            }
            match points.windows(2).position(|w| w[1][0] <= w[0][0]) {
                Some(i) => Err(Error::config(
                    format!("{field}.points"),
                    format!(
                        "table times must increase strictly, but point {} (t = {}) does not follow point {i} (t = {})",
                        i + 1,
                        points[i + 1][0],
                        points[i][0]
                    ),
                )),
                None => Ok(()),
            }
        }
        TimeFunction::Harmonic { frequency, phase } => {
            positive(&format!("{field}.frequency"), *frequency)?;
            finite(&format!("{field}.phase"), &[*phase])
        }
    }
}

/// The largest step count a run takes: `t = k h` stays exact in double precision
/// up to `2^53` steps; far fewer are ever useful (`rothe check` warns from
/// [`HUGE_STEPS`] on).
pub(crate) const MAX_STEPS: f64 = 9_007_199_254_740_992.0;

/// Step counts from which `rothe check` warns.
pub const HUGE_STEPS: usize = 10_000_000;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_of_time_function_is_checked() {
        let bad = [
            TimeFunction::Step { at: f64::NAN },
            TimeFunction::Ramp {
                t0: 0.0,
                t1: f64::INFINITY,
            },
            TimeFunction::Ramp { t0: 1.0, t1: 1.0 },
            TimeFunction::Table { points: vec![] },
            TimeFunction::Table {
                points: vec![[0.0, 1.0], [f64::NAN, 2.0]],
            },
            TimeFunction::Table {
                points: vec![[0.0, 1.0], [0.0, 2.0]],
            },
            TimeFunction::Harmonic {
                frequency: 0.0,
                phase: 0.0,
            },
            TimeFunction::Harmonic {
                frequency: 1.0,
                phase: f64::NAN,
            },
        ];
        for f in &bad {
            let e = check_function("loads[0].function", f)
                .unwrap_err()
                .to_string();
            assert!(e.starts_with("loads[0].function"), "{e}");
        }
        assert!(check_function("f", &TimeFunction::Constant).is_ok());
        let msg = check_function(
            "f",
            &TimeFunction::Table {
                points: vec![[0.0, 1.0], [f64::NAN, 2.0]],
            },
        )
        .unwrap_err()
        .to_string();
        assert!(msg.contains("f.points[1][0]"), "{msg}");
    }
}
