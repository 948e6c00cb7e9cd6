//! `DIR/pareto.svg`: error against wall time on log–log axes, one curve per case, solver and contact algorithm
//! (points joined in order of spacing, so each curve runs from coarse to fine).

use std::path::Path;

use anyhow::Context;
use plotters::prelude::*;

use super::record::Record;

/// Draw the records that have a positive, finite error into the SVG file `path`.
pub fn plot(path: &Path, records: &[Record]) -> anyhow::Result<()> {
    let mut curves: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for r in records.iter().filter(|r| r.ok() && r.wall_seconds > 0.0) {
        let error = r.error.unwrap_or(0.0).max(1e-6);
        let label = match r.contact.as_str() {
            "none" => format!("{} {}", r.case, r.solver),
            c => format!("{} {} {c}", r.case, r.solver),
        };
        let point = (r.wall_seconds, error, r.spacing);
        match curves.iter_mut().find(|c| c.0 == label) {
            Some(c) => c.1.push((point.0, point.1)),
            None => curves.push((label, vec![(point.0, point.1)])),
        }
    }
    let span = |f: fn(&(f64, f64)) -> f64, fallback: (f64, f64)| {
        let (lo, hi) = curves
            .iter()
            .flat_map(|c| c.1.iter().map(f))
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
        if lo.is_finite() && hi > 0.0 {
            (lo / 1.5, hi * 1.5)
        } else {
            fallback
        }
    };
    let (x0, x1) = span(|p| p.0, (0.1, 100.0));
    // Room below the points for the legend (lower left: fast and accurate, where few points fall).
    let (y0, y1) = span(|p| p.1, (1e-3, 1.0));
    let y0 = y0 / 4.0;
    let mut svg = String::new();
    let drawn = (|| -> Result<(), String> {
        let err = |e: &dyn std::fmt::Display| e.to_string();
        let root = SVGBackend::with_string(&mut svg, (960, 600)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let mut chart = ChartBuilder::on(&root)
            .caption("error against wall time (cosim bench)", ("sans-serif", 24))
            .margin(16)
            .x_label_area_size(48)
            .y_label_area_size(80)
            .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
            .map_err(|e| err(&e))?;
        chart
            .configure_mesh()
            .x_desc("wall time [s]")
            .y_desc("relative error")
            .light_line_style(WHITE)
            .x_label_formatter(&|v| short(*v))
            .y_label_formatter(&|v| short(*v))
            .draw()
            .map_err(|e| err(&e))?;
        for (k, (label, points)) in curves.iter().enumerate() {
            let colour = Palette99::pick(k).to_rgba();
            chart
                .draw_series(LineSeries::new(points.iter().copied(), colour.stroke_width(2)))
                .map_err(|e| err(&e))?
                .label(label.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2)));
            chart
                .draw_series(PointSeries::of_element(
                    points.iter().copied(),
                    4,
                    colour.filled(),
                    &|c, s, st| Circle::new(c, s, st),
                ))
                .map_err(|e| err(&e))?;
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerLeft)
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(|e| err(&e))?;
        root.present().map_err(|e| err(&e))
    })();
    drawn.map_err(|m| anyhow::anyhow!("{}: cannot draw: {m}", path.display()))?;
    std::fs::write(path, svg).with_context(|| format!("cannot write {}", path.display()))
}

/// A tick label without the binary round-off of the log axis' tick values (0.30000000000000004 → 0.3).
fn short(v: f64) -> String {
    let text = format!("{:.3e}", v);
    text.parse::<f64>().map_or(text, |r| r.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_drop_round_off() {
        assert_eq!(short(0.30000000000000004), "0.3");
        assert_eq!(short(20.0), "20");
        assert_eq!(short(0.0123456), "0.01235");
    }
}
