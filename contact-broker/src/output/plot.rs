//! `DIR/plots/<probe>.svg`: one probe against time, with the scene's reference data where it names some.
//!
//! Plotters draws text in SVG as `<text>` elements left to the viewer's fonts, so no font is needed here.

use std::path::Path;

use cosim_proto::scene::ReferenceSpec;
use plotters::prelude::*;

use super::{OutputError, Result};

/// Most reference markers drawn; denser reference data is thinned evenly (every k-th row) so the markers
/// stay readable next to the line.
const MAX_MARKERS: usize = 200;

/// Plot the probe `name` against time into the SVG file `path` (its folder is created if needed): `series`
/// as a line, title `name`, axes `t [s]` and `name`.
///
/// With `reference` = (spec, resolved CSV path) the reference curve ([`read_reference`]) is drawn as markers
/// with `spec.label` (or the file name) in the legend. The time axis spans the probe's samples (the reference
/// is clipped to it; the reference's own span when there are no samples); the value axis spans both.
/// Non-finite samples are left out.
///
/// When the reference file is missing or malformed the plot is still written, without it, and the reference
/// error (naming the file) is returned for the caller to log.
pub fn plot_probe(
    path: &Path,
    name: &str,
    series: &[(f64, f64)],
    reference: Option<(&ReferenceSpec, &Path)>,
) -> Result<()> {
    let (reference, reference_error) = match reference {
        Some((spec, file)) => match read_reference(file, spec) {
            Ok(points) => {
                let label = spec.label.clone().unwrap_or_else(|| file_label(file));
                (Some((label, points)), None)
            }
            Err(e) => (None, Some(e)),
        },
        None => (None, None),
    };
    let series: Vec<(f64, f64)> = series
        .iter()
        .copied()
        .filter(|(t, v)| t.is_finite() && v.is_finite())
        .collect();

    let mut svg = String::new();
    draw(
        &mut svg,
        name,
        &series,
        reference.as_ref().map(|(l, p)| (l.as_str(), p.as_slice())),
    )
    .map_err(|message| OutputError::Plot {
        path: path.to_path_buf(),
        message,
    })?;
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| OutputError::io(dir, e))?;
    }
    super::write_whole(path, svg.as_bytes())?;
    reference_error.map_or(Ok(()), Err)
}

/// Read a reference curve from the CSV file `path`: the columns named `spec.t` and `spec.value` in its header
/// row, as `(t * spec.t_scale + spec.t_offset, value * spec.scale)`.
///
/// Fields are trimmed and may be quoted; empty lines and lines starting with `#` are skipped. A missing
/// column, a short row or a field that is not a number is an error naming the file (and the line).
pub fn read_reference(path: &Path, spec: &ReferenceSpec) -> Result<Vec<(f64, f64)>> {
    let text = std::fs::read_to_string(path).map_err(|e| OutputError::io(path, e))?;
    let error = |message: String| OutputError::Reference {
        path: path.to_path_buf(),
        message,
    };
    let mut lines = text
        .trim_start_matches('\u{feff}')
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let (_, header) = lines.next().ok_or_else(|| error("empty file, no header row".into()))?;
    let columns: Vec<&str> = header.split(',').map(field).collect();
    let column = |key: &str, name: &str| {
        columns.iter().position(|c| *c == name).ok_or_else(|| {
            error(format!(
                "no column `{name}` (reference.{key}) in the header; columns are: {}",
                columns.join(", ")
            ))
        })
    };
    let (kt, kv) = (column("t", &spec.t)?, column("value", &spec.value)?);
    let mut points = Vec::new();
    for (line, row) in lines {
        let fields: Vec<&str> = row.split(',').map(field).collect();
        let number = |k: usize, name: &str| -> Result<f64> {
            let f = fields
                .get(k)
                .ok_or_else(|| error(format!("line {line}: no field for column `{name}`")))?;
            f.parse()
                .map_err(|_| error(format!("line {line}: column `{name}`: `{f}` is not a number")))
        };
        points.push((
            number(kt, &spec.t)? * spec.t_scale + spec.t_offset,
            number(kv, &spec.value)? * spec.scale,
        ));
    }
    Ok(points)
}

fn field(s: &str) -> &str {
    let s = s.trim();
    s.strip_prefix('"').and_then(|s| s.strip_suffix('"')).unwrap_or(s)
}

fn file_label(file: &Path) -> String {
    file.file_name()
        .map_or_else(|| file.display().to_string(), |n| n.to_string_lossy().into_owned())
}

/// `[min, max]` of `values` with a 5 % margin; a unit (or ±10 %) interval around a single value; `[0, 1]` for none.
fn padded_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if lo > hi {
        return (0.0, 1.0);
    }
    let span = hi - lo;
    let pad = if span > 0.0 && span.is_finite() {
        0.05 * span
    } else if lo != 0.0 {
        0.1 * lo.abs()
    } else {
        1.0
    };
    (lo - pad, hi + pad)
}

fn draw(
    svg: &mut String,
    name: &str,
    series: &[(f64, f64)],
    reference: Option<(&str, &[(f64, f64)])>,
) -> Result<(), String> {
    let err = |e: &dyn std::fmt::Display| e.to_string();
    let reference = reference.map(|(label, points)| {
        let points: Vec<(f64, f64)> = points
            .iter()
            .copied()
            .filter(|(t, v)| t.is_finite() && v.is_finite())
            .collect();
        (label, points)
    });

    let (t0, t1) = if series.is_empty() {
        let all = reference.iter().flat_map(|(_, p)| p.iter().map(|&(t, _)| t));
        let (lo, hi) = all.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), t| (lo.min(t), hi.max(t)));
        if lo < hi {
            (lo, hi)
        } else {
            padded_range([lo, hi].into_iter().filter(|t| t.is_finite()))
        }
    } else {
        let (lo, hi) = series
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &(t, _)| {
                (lo.min(t), hi.max(t))
            });
        if lo < hi {
            (lo, hi)
        } else {
            padded_range([lo].into_iter())
        }
    };
    let markers: Option<(&str, Vec<(f64, f64)>)> = reference.as_ref().map(|(label, points)| {
        let visible: Vec<(f64, f64)> = points.iter().copied().filter(|&(t, _)| t >= t0 && t <= t1).collect();
        let stride = visible.len().div_ceil(MAX_MARKERS).max(1);
        (*label, visible.into_iter().step_by(stride).collect())
    });
    let (v0, v1) = padded_range(
        series
            .iter()
            .map(|p| p.1)
            .chain(markers.iter().flat_map(|(_, p)| p.iter().map(|q| q.1))),
    );

    let root = SVGBackend::with_string(svg, (900, 560)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(name, ("sans-serif", 24))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(90)
        .build_cartesian_2d(t0..t1, v0..v1)
        .map_err(|e| err(&e))?;
    chart
        .configure_mesh()
        .x_desc("t [s]")
        .y_desc(name)
        .draw()
        .map_err(|e| err(&e))?;

    chart
        .draw_series(LineSeries::new(series.iter().copied(), BLUE.stroke_width(2)))
        .map_err(|e| err(&e))?
        .label("simulation")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLUE.stroke_width(2)));
    if let Some((label, points)) = &markers {
        chart
            .draw_series(points.iter().map(|&p| Circle::new(p, 3, RED.filled())))
            .map_err(|e| err(&e))?
            .label(*label)
            .legend(|(x, y)| Circle::new((x + 10, y), 3, RED.filled()));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::test_dir;
    use super::*;

    fn spec(file: &str, t: &str, value: &str) -> ReferenceSpec {
        ReferenceSpec {
            file: file.into(),
            t: t.into(),
            value: value.into(),
            label: Some("FEAT level 4".into()),
            scale: 1.0,
            t_offset: 0.0,
            t_scale: 1.0,
        }
    }

    const TUREK: &str =
        "time,Ux,Uy\n0,0,0\n0.005,-1.28887291E-10,-0.0000250016078\n0.01,-5.21615594E-09,-0.000100029128\n";

    #[test]
    fn reference_columns_are_picked_by_header_name() {
        let dir = test_dir("ref");
        let file = dir.join("csm3.csv");
        std::fs::write(&file, TUREK).unwrap();
        let mut s = spec("csm3.csv", "time", "Uy");
        s.scale = 1000.0;
        s.t_offset = 1.0;
        let points = read_reference(&file, &s).unwrap();
        assert_eq!(points.len(), 3);
        assert_eq!(points[1], (1.005, -0.0000250016078 * 1000.0));
        assert_eq!(
            read_reference(&file, &spec("", "time", "Ux")).unwrap()[2].1,
            -5.21615594E-09
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn reference_errors_name_the_file() {
        let dir = test_dir("ref-bad");
        let file = dir.join("csm3.csv");
        std::fs::write(&file, TUREK).unwrap();
        let e = read_reference(&file, &spec("", "t", "Uy")).unwrap_err().to_string();
        assert!(
            e.contains("csm3.csv") && e.contains("`t`") && e.contains("time, Ux, Uy"),
            "{e}"
        );
        std::fs::write(&file, "time,Ux\n0,1\n0.1,x\n").unwrap();
        let e = read_reference(&file, &spec("", "time", "Ux")).unwrap_err().to_string();
        assert!(e.contains("csm3.csv") && e.contains("line 3"), "{e}");
        let e = read_reference(&dir.join("missing.csv"), &spec("", "time", "Ux"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing.csv"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn plot_is_written_with_the_reference_in_the_legend() {
        let dir = test_dir("plot");
        let file = dir.join("csm3.csv");
        std::fs::write(&file, TUREK).unwrap();
        let series: Vec<(f64, f64)> = (0..=20).map(|i| (i as f64 * 0.0005, -(i as f64) * 1e-6)).collect();
        let s = spec("csm3.csv", "time", "Uy");
        let out = dir.join("plots/tip_y.svg");
        plot_probe(&out, "tip_y", &series, Some((&s, &file))).unwrap();
        let svg = std::fs::read_to_string(&out).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("FEAT level 4") && svg.contains("t [s]"));
        assert!(svg.contains("tip_y") && svg.contains("<circle"));

        let plain = dir.join("plots/front.svg");
        plot_probe(&plain, "front", &series, None).unwrap();
        let svg = std::fs::read_to_string(&plain).unwrap();
        assert!(!svg.is_empty() && svg.contains("front") && !svg.contains("FEAT"));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn bad_reference_still_writes_the_plot_and_names_the_file() {
        let dir = test_dir("plot-bad");
        let out = dir.join("p.svg");
        let missing = dir.join("nowhere.csv");
        let s = spec("nowhere.csv", "time", "Uy");
        let e = plot_probe(
            &out,
            "p",
            &[(0.0, 1.0), (1.0, f64::NAN), (2.0, 3.0)],
            Some((&s, &missing)),
        )
        .unwrap_err();
        assert!(e.to_string().contains("nowhere.csv"), "{e}");
        assert!(std::fs::metadata(&out).unwrap().len() > 0);
        // Degenerate inputs (no samples, one sample) still give a plot.
        plot_probe(&dir.join("empty.svg"), "e", &[], None).unwrap();
        plot_probe(&dir.join("one.svg"), "o", &[(0.5, 0.0)], None).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
