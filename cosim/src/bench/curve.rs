//! Reference curves: (x, y) rows of a two-column CSV, and linear interpolation on them (the dam break's and the
//! wall impact's scoring, [`super::metrics`] and [`super::lobovsky`]).

use std::path::Path;

use anyhow::Context;

/// (x, y) rows of a two-column CSV with a header.
pub fn curve(path: &Path) -> anyhow::Result<Vec<(f64, f64)>> {
    let text = std::fs::read_to_string(path).with_context(|| format!("{}: cannot read", path.display()))?;
    Ok(text
        .lines()
        .skip(1)
        .filter_map(|l| {
            let mut it = l.split(',').map(|v| v.trim().parse::<f64>());
            Some((it.next()?.ok()?, it.next()?.ok()?))
        })
        .collect())
}

/// Linear interpolation of y(x) on a curve sorted by x (extrapolated from the end segments).
pub fn interpolate(curve: &[(f64, f64)], x: f64) -> f64 {
    let k = curve.partition_point(|p| p.0 < x).clamp(1, curve.len() - 1);
    let (a, b) = (curve[k - 1], curve[k]);
    a.1 + (b.1 - a.1) * (x - a.0) / (b.0 - a.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_between_and_beyond_the_points() {
        let c = [(0.0, 0.0), (1.0, 2.0), (2.0, 2.0)];
        assert_eq!(interpolate(&c, 0.5), 1.0);
        assert_eq!(interpolate(&c, 1.5), 2.0);
        assert_eq!(interpolate(&c, -1.0), -2.0);
    }
}
