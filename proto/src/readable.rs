//! Numbers as a message should show them: a value a user typed may be 1e-300 or 1e300, and Rust's `{}` writes
//! every one of its digits (300 zeros), where a person reads `1e-300`.

use std::fmt;

/// `x` as it reads best in a message: as Rust writes it for 0, ±∞, NaN and magnitudes in [1e-4, 1e7) (so the usual
/// values read as typed), in scientific notation beyond. A precision (`{:.3}`) applies in either notation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Num(pub f64);

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        let a = x.abs();
        let plain = a == 0.0 || !a.is_finite() || (1e-4..1e7).contains(&a);
        match (plain, f.precision()) {
            (true, Some(p)) => write!(f, "{x:.p$}"),
            (true, None) => write!(f, "{x}"),
            (false, Some(p)) => write!(f, "{x:.p$e}"),
            (false, None) => write!(f, "{x:e}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Num;

    #[test]
    fn usual_values_read_as_typed_and_extreme_ones_in_scientific_notation() {
        assert_eq!(Num(0.005).to_string(), "0.005");
        assert_eq!(Num(12_000_000.0).to_string(), "1.2e7");
        assert_eq!(Num(9_999_999.0).to_string(), "9999999");
        assert_eq!(Num(1e-4).to_string(), "0.0001");
        assert_eq!(Num(-1e300).to_string(), "-1e300");
        assert_eq!(Num(1e-300).to_string(), "1e-300");
        assert_eq!(Num(0.0).to_string(), "0");
        assert_eq!(Num(f64::INFINITY).to_string(), "inf");
        assert_eq!(Num(f64::NAN).to_string(), "NaN");
        assert_eq!(format!("{:.1}", Num(3.64)), "3.6");
        assert_eq!(format!("{:.1}", Num(3.6e299)), "3.6e299");
        assert_eq!(format!("{:.3}", Num(9.587500000000001e-5)), "9.588e-5");
    }
}
