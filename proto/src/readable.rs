//! Numbers as a message should show them: a value a user typed may be 1e-300 or 1e300, and Rust's `{}` writes
//! every one of its digits (300 zeros), where a person reads `1e-300`; and a node's own text as one printable line.

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

/// `x` rounded to `digits` significant digits, for a message whose value is a sum or a norm (2000000.0999999999 m
/// reads 2000000.1 m at 8 digits); as it is for 0, ±∞ and NaN.
pub fn significant(x: f64, digits: usize) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    // Rust's own decimal rounding, which cannot overflow or leave a last-bit error as a scaling would.
    format!("{x:.*e}", digits.saturating_sub(1)).parse().unwrap_or(x)
}

/// A node's message as one printable line of at most 2,000 characters: control characters (a carriage return, a
/// terminal's escape sequences) became spaces, so that what a node says cannot hide which node said it or rewrite
/// the terminal (found 2026-12-06).
pub fn one_line(message: &str) -> String {
    const MOST: usize = 2000;
    let mut line: String = message
        .chars()
        .take(MOST)
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect();
    if message.chars().nth(MOST).is_some() {
        line.push('…');
    }
    line
}

#[cfg(test)]
mod tests {
    use super::{one_line, significant, Num};

    #[test]
    fn a_sum_reads_with_its_significant_digits() {
        assert_eq!(Num(significant(2000000.0999999999, 6)).to_string(), "2000000");
        assert_eq!(Num(significant(100.00080000179999, 6)).to_string(), "100.001");
        assert_eq!(Num(significant(-2.2222222223803344e8, 6)).to_string(), "-2.22222e8");
        assert_eq!(significant(1.7e308, 6), 1.7e308);
        assert!(significant(f64::NAN, 6).is_nan());
        assert_eq!(significant(0.0, 6), 0.0);
    }

    #[test]
    fn a_nodes_message_is_one_printable_line() {
        assert_eq!(one_line("diverged\r\x1b[2Kfem-node: ok"), "diverged  [2Kfem-node: ok");
        assert_eq!(one_line("a\nb"), "a b");
        let long = "x".repeat(2500);
        let line = one_line(&long);
        assert_eq!(line.chars().count(), 2001);
        assert!(line.ends_with('…'));
        assert_eq!(one_line("ünïcode ok"), "ünïcode ok");
    }

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
