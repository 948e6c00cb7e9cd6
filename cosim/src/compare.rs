//! `cosim compare RUN... --probe NAME --out FILE.svg`: one probe of several finished runs in one plot, and a line
//! per run with its peak (largest |value|) and when it happened.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{bail, Context};
use contact_broker::output::plot_compare;

use crate::cli::CompareArgs;

/// Read column `probe` of `DIR/probes.csv` as (t, value).
pub fn read_probe(dir: &Path, probe: &str) -> anyhow::Result<Vec<(f64, f64)>> {
    let path = dir.join("probes.csv");
    let text = std::fs::read_to_string(&path).with_context(|| format!("{}: cannot read", path.display()))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let Some(k) = header.iter().position(|h| *h == probe) else {
        bail!(
            "{}: no probe `{probe}` (columns: {})",
            path.display(),
            header[1..].join(", ")
        );
    };
    lines
        .enumerate()
        .map(|(i, l)| {
            let f: Vec<&str> = l.split(',').collect();
            let num = |s: Option<&&str>| -> anyhow::Result<f64> {
                s.and_then(|s| s.parse().ok())
                    .with_context(|| format!("{}: line {}: not a number", path.display(), i + 2))
            };
            Ok((num(f.first())?, num(f.get(k))?))
        })
        .collect()
}

/// Run `cosim compare`.
pub fn compare(args: &CompareArgs) -> anyhow::Result<ExitCode> {
    let mut curves = Vec::new();
    for run in &args.runs {
        let (label, dir) = match run.split_once('=') {
            Some((l, d)) => (l.to_string(), PathBuf::from(d)),
            None => (run.clone(), PathBuf::from(run)),
        };
        let series = read_probe(&dir, &args.probe)?;
        let peak = series
            .iter()
            .copied()
            .fold((0.0, 0.0), |a: (f64, f64), p| if p.1.abs() > a.1.abs() { p } else { a });
        println!("{label}: peak {} = {:.6e} at t = {} s", args.probe, peak.1, peak.0);
        curves.push((label, series));
    }
    plot_compare(&args.out, &args.probe, &args.probe, &curves)?;
    println!("wrote {}", args.out.display());
    Ok(ExitCode::SUCCESS)
}
