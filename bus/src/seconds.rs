//! Seconds to wait, given on a command line or in a scene: read as a positive number, and turned into a
//! `Duration` that neither panics (`Duration::from_secs_f64` does above 1.8e19 s) nor overflows an `Instant` it is
//! added to. Past [`LONGEST_WAIT`] every wait is the same "as long as it takes".

use std::time::Duration;

/// The longest wait, in seconds (about 31.7 years); a longer one is taken as this.
pub const LONGEST_WAIT: f64 = 1e9;

/// A clap value parser for a number of seconds to wait: finite and positive, said with the value given.
pub fn positive(text: &str) -> Result<f64, String> {
    let value: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("`{text}` is not a number of seconds"))?;
    match value.is_finite() && value > 0.0 {
        true => Ok(value),
        false => Err(format!("must be a positive number of seconds, got {text}")),
    }
}

/// `seconds` (positive; see [`positive`]) as a wait, at most [`LONGEST_WAIT`]; zero for anything not positive.
pub fn wait(seconds: f64) -> Duration {
    match seconds > 0.0 {
        true => Duration::from_secs_f64(seconds.min(LONGEST_WAIT)),
        false => Duration::ZERO,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What `Duration::from_secs_f64` panics on is a wait here: 1e300 s is the longest, and it can be added to now.
    #[test]
    fn any_number_is_a_wait_that_can_be_added_to_now() {
        for s in [1e300, f64::MAX, f64::INFINITY, 2e19] {
            let w = wait(s);
            assert_eq!(w, Duration::from_secs(1_000_000_000), "{s}");
            assert!(std::time::Instant::now().checked_add(w).is_some());
        }
        for s in [0.0, -1.0, f64::NAN, -f64::INFINITY] {
            assert_eq!(wait(s), Duration::ZERO, "{s}");
        }
        assert_eq!(wait(0.25), Duration::from_millis(250));
    }

    #[test]
    fn the_parser_takes_positive_finite_seconds_only() {
        assert_eq!(positive("2.5"), Ok(2.5));
        assert_eq!(positive("1e300"), Ok(1e300));
        for bad in ["0", "-1", "nan", "inf", "-inf"] {
            let e = positive(bad).unwrap_err();
            assert!(e.contains("positive number of seconds") && e.contains(bad), "{e}");
        }
        assert!(positive("ten").unwrap_err().contains("`ten` is not a number"));
    }
}
