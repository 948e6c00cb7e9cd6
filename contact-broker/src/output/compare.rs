//! One probe from several runs in one SVG: `cosim compare` (e.g. the gate's tip displacement for each solver and
//! contact algorithm, `docs/VALIDATION.md`).

use std::path::Path;

use plotters::prelude::*;

use super::{OutputError, Result};

/// Draw each `(label, series)` as a line of its own colour into the SVG file `path`, titled `title`, with the
/// value axis named `value`. Non-finite samples are left out.
pub fn plot_compare(path: &Path, title: &str, value: &str, curves: &[(String, Vec<(f64, f64)>)]) -> Result<()> {
    let curves: Vec<(&str, Vec<(f64, f64)>)> = curves
        .iter()
        .map(|(l, s)| {
            let s = s
                .iter()
                .copied()
                .filter(|(t, v)| t.is_finite() && v.is_finite())
                .collect();
            (l.as_str(), s)
        })
        .collect();
    let bounds = |f: fn(&(f64, f64)) -> f64| {
        let (lo, hi) = curves
            .iter()
            .flat_map(|(_, s)| s.iter().map(f))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
        if lo < hi {
            let pad = 0.05 * (hi - lo);
            (lo - pad, hi + pad)
        } else if lo.is_finite() {
            (lo - 1.0, lo + 1.0)
        } else {
            (0.0, 1.0)
        }
    };
    let ((t0, t1), (v0, v1)) = (bounds(|p| p.0), bounds(|p| p.1));
    let mut svg = String::new();
    let drawn = (|| -> std::result::Result<(), String> {
        let err = |e: &dyn std::fmt::Display| e.to_string();
        let root = SVGBackend::with_string(&mut svg, (900, 560)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 24))
            .margin(16)
            .x_label_area_size(48)
            .y_label_area_size(90)
            .build_cartesian_2d(t0..t1, v0..v1)
            .map_err(|e| err(&e))?;
        chart
            .configure_mesh()
            .x_desc("t [s]")
            .y_desc(value)
            .draw()
            .map_err(|e| err(&e))?;
        for (k, (label, series)) in curves.iter().enumerate() {
            let colour = Palette99::pick(k).to_rgba();
            chart
                .draw_series(LineSeries::new(series.iter().copied(), colour.stroke_width(2)))
                .map_err(|e| err(&e))?
                .label(*label)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2)));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(|e| err(&e))?;
        root.present().map_err(|e| err(&e))
    })();
    drawn.map_err(|message| OutputError::Plot {
        path: path.to_path_buf(),
        message,
    })?;
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| OutputError::io(dir, e))?;
    }
    super::write_whole(path, svg.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_one_line_and_legend_entry_per_curve() {
        let dir = std::env::temp_dir().join(format!("cosim-compare-{}", std::process::id()));
        let path = dir.join("cmp.svg");
        let curves = vec![
            ("a".to_string(), vec![(0.0, 0.0), (1.0, 1.0)]),
            ("b".to_string(), vec![(0.0, 1.0), (1.0, f64::NAN), (2.0, 0.5)]),
        ];
        plot_compare(&path, "tip_x", "tip_x [m]", &curves).unwrap();
        let svg = std::fs::read_to_string(&path).unwrap();
        // Each curve and its legend mark are drawn in the curve's own colour; the legend names it.
        for (k, label) in ["a", "b"].iter().enumerate() {
            let c = Palette99::pick(k).to_rgba();
            let colour = format!("stroke=\"#{:02X}{:02X}{:02X}\"", c.0, c.1, c.2);
            assert_eq!(svg.matches(&colour).count(), 2, "curve {k} ({colour})");
            assert!(svg.contains(&format!(">\n{label}\n</text>")), "legend {label}");
        }
        std::fs::remove_dir_all(dir).unwrap();
    }
}
