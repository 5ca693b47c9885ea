//! Numeric option values checked as they are parsed: one home for "finite", "positive"
//! and "≥ 0", shared by every command's options (`GridOptions` here, the rest in
//! `gyro-cli`). Each function fits clap's `value_parser` (`fn(&str) -> Result<T, String>`)
//! and says what was expected. A value that overflows its type (`1e40` as `f32`) is not
//! finite.

use std::str::FromStr;

fn checked<T>(text: &str, ok: impl Fn(f64) -> bool, expected: &str) -> Result<T, String>
where
    T: FromStr + Copy + Into<f64>,
{
    let shown: String = text.chars().take(40).collect();
    match text.trim().parse::<T>() {
        Ok(value) if ok(value.into()) => Ok(value),
        _ => Err(format!("expected {expected}, got `{shown}`")),
    }
}

/// A finite number (not NaN, not infinite).
pub fn finite<T: FromStr + Copy + Into<f64>>(text: &str) -> Result<T, String> {
    checked(text, f64::is_finite, "a finite number")
}

/// A finite number > 0.
pub fn positive<T: FromStr + Copy + Into<f64>>(text: &str) -> Result<T, String> {
    checked(
        text,
        |v| v.is_finite() && v > 0.0,
        "a positive finite number",
    )
}

/// A finite number ≥ 0.
pub fn non_negative<T: FromStr + Copy + Into<f64>>(text: &str) -> Result<T, String> {
    checked(text, |v| v.is_finite() && v >= 0.0, "a finite number >= 0")
}

/// A parser of a finite number from `lo` to `hi` (`what` says what the bounds are, e.g.
/// "°C; ...").
pub fn within(
    lo: f64,
    hi: f64,
    what: &'static str,
) -> impl Fn(&str) -> Result<f64, String> + Clone + Send + Sync + 'static {
    move |text| {
        checked(
            text,
            |v| v.is_finite() && (lo..=hi).contains(&v),
            &format!("a number from {lo} to {hi} ({what})"),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_are_checked_as_parsed() {
        assert_eq!(positive::<f64>("1e3"), Ok(1000.0));
        assert_eq!(non_negative::<f64>("0"), Ok(0.0));
        assert_eq!(finite::<f32>("-2.5"), Ok(-2.5));
        for bad in ["nan", "inf", "-inf", "0", "-1", "fast", ""] {
            assert!(positive::<f64>(bad).is_err(), "{bad}");
        }
        for bad in ["nan", "inf", "-1e-9", "x"] {
            assert!(non_negative::<f64>(bad).is_err(), "{bad}");
        }
        // Overflows f32: infinite.
        assert!(finite::<f32>("1e40").is_err());
        let rise = within(-125.0, 125.0, "°C");
        assert_eq!(rise("-5"), Ok(-5.0));
        for bad in ["-1e308", "126", "nan", "inf", "x"] {
            assert!(rise(bad).is_err(), "{bad}");
        }
        assert_eq!(
            rise("-1e308").unwrap_err(),
            "expected a number from -125 to 125 (°C), got `-1e308`"
        );
        assert_eq!(
            positive::<f64>("-1").unwrap_err(),
            "expected a positive finite number, got `-1`"
        );
    }
}
