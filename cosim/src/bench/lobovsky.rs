//! The wall-impact case of the bench (`scenes/lobovsky_dam_break.toml`, Lobovsky et al. 2014, H = 0.3 m): the
//! pressure at sensors 1 (y = 3 mm) and 2 (y = 15 mm) against the recorded peak event, scored with the criteria of
//! issue 16 and `cosim/tests/lobovsky.rs` on the data's own time axis (t* = t √(g/H), p* = p/(ρgH)):
//!
//! * first impact: the first sample after t* = 1 with p* ≥ 0.1, against the recording's (bound ±0.1 t*);
//! * peak: the largest p* up to 0.5 t* after the first impact (bound 1.5–6, a factor 2 of the recorded event);
//! * RMS of p*_sim − p*_data (the data interpolated at the sample times) for t* in [3, 7] (bound 0.25);
//! * the lowest p* (bound −0.5) and the samples of exactly 0 from 0.1 t* after the first impact on (the sensors stay
//!   under water; ISPH's bound: none);
//! * the pressure impulse of the first impact, ∫ p* dt* from 0.05 t* before to 0.5 t* after it, each series from its
//!   own first impact (not bounded: it tells an impact that delivers the recorded momentum in a shorter, taller
//!   pulse — WCSPH's acoustic one, ρ c0 u — from one that delivers more).
//!
//! `bench/lobovsky_score.py` prints the same for any run folder.

use std::path::Path;

use anyhow::{bail, Context};
use serde::{Deserialize, Serialize};

use super::curve::{curve, interpolate};
use crate::compare::read_probe;

/// Water column height H [m], gravity [m/s²] and density [kg/m³] of the experiment.
const H: f64 = 0.3;
const G: f64 = 9.81;
const RHO: f64 = 1000.0;
/// The sensors' face, the downstream wall, at x [m]; their heights [m].
const WALL_X: f64 = 1.61;
const SENSOR_Y: [f64; 2] = [0.003, 0.015];
/// A sensor reads the impact once p* passes this.
const IMPACT: f64 = 0.1;
/// The post-impact window of the RMS [t*].
const AFTER: (f64, f64) = (3.0, 7.0);
/// The window of the first impact's pressure impulse, from its first impact [t*].
const IMPULSE: (f64, f64) = (-0.05, 0.5);

/// One sensor's scores (dimensionless, t* and p*).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SensorScore {
    /// The probe scored (`p_sensor1`, `p_sensor2`: the time mean over each sampling interval).
    pub probe: String,
    /// First impact [t*], and the recording's.
    pub first_impact: f64,
    /// The recording's first impact [t*].
    pub first_impact_data: f64,
    /// Largest p* within 0.5 t* of the first impact.
    pub peak: f64,
    /// The recording's largest p*.
    pub peak_data: f64,
    /// RMS of p*_sim − p*_data over t* in [3, 7].
    pub rms: f64,
    /// Lowest p* sampled.
    pub min: f64,
    /// Samples of exactly 0 from 0.1 t* after the first impact on.
    pub zeros: usize,
    /// Pressure impulse of the first impact, ∫ p* dt* over [`IMPULSE`] from the first impact (records written
    /// before it was scored read 0).
    #[serde(default)]
    pub impulse: f64,
    /// The recording's, over the same window from its own first impact.
    #[serde(default)]
    pub impulse_data: f64,
}

/// The `--set` overrides that put the sensor probes (the scene's probes 0–3: `p_sensor1`, `p_sensor2` and their
/// `_raw` twins) half a spacing in front of the wall at `spacing`, where the first column of fluid sits.
pub fn probe_sets(spacing: f64) -> Vec<String> {
    // rounded to a nanometre, so that the `--set` reads 1.6075, not 1.6074999999999999
    let x = ((WALL_X - 0.5 * spacing) * 1e9).round() / 1e9;
    (0..4)
        .map(|k| format!("probe[{k}].point=[{x},{}]", SENSOR_Y[k % 2]))
        .collect()
}

/// Score sensors 1 and 2 of the run in `out` against the recordings in `scenes/data`.
pub fn score(out: &Path, scenes: &Path) -> anyhow::Result<Vec<SensorScore>> {
    let (ts, ps) = ((H / G).sqrt(), RHO * G * H);
    (1..=2)
        .map(|k| {
            let probe = format!("p_sensor{k}");
            let sim: Vec<(f64, f64)> = read_probe(out, &probe)?
                .into_iter()
                .map(|(t, p)| (t / ts, p / ps))
                .collect();
            let file = scenes.join(format!("data/lobovsky2014_H300_sensor{k}_event.csv"));
            // (t*, p*): the recording's two columns, `t_star`, `p_star`
            let data = curve(&file)?;
            if data.len() < 2 {
                bail!("{}: fewer than two rows", file.display());
            }
            let t1 = first_impact(&sim).with_context(|| format!("{probe}: no impact (p* never reaches {IMPACT})"))?;
            let t1_data = first_impact(&data).with_context(|| format!("{}: no impact", file.display()))?;
            let peak = sim
                .iter()
                .filter(|p| p.0 <= t1 + 0.5)
                .map(|p| p.1)
                .fold(f64::NEG_INFINITY, f64::max);
            let diffs: Vec<f64> = sim
                .iter()
                .filter(|p| (AFTER.0..=AFTER.1).contains(&p.0))
                .map(|p| p.1 - interpolate(&data, p.0))
                .collect();
            if diffs.is_empty() {
                bail!("{probe}: no sample in t* {AFTER:?}");
            }
            Ok(SensorScore {
                probe,
                first_impact: t1,
                first_impact_data: t1_data,
                peak,
                peak_data: data.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max),
                rms: (diffs.iter().map(|d| d * d).sum::<f64>() / diffs.len() as f64).sqrt(),
                min: sim.iter().map(|p| p.1).fold(f64::INFINITY, f64::min),
                zeros: sim.iter().filter(|p| p.0 > t1 + 0.1 && p.1 == 0.0).count(),
                impulse: impulse(&sim, t1),
                impulse_data: impulse(&data, t1_data),
            })
        })
        .collect()
}

fn first_impact(s: &[(f64, f64)]) -> Option<f64> {
    s.iter().find(|p| p.0 > 1.0 && p.1 >= IMPACT).map(|p| p.0)
}

/// ∫ p* dt* over [`IMPULSE`] from `t1`, by the trapezoidal rule over the samples in the window (a 1 ms mean is the
/// interval's integral divided by its length, so on the probes' samples this is that integral to O(Δt²) of the
/// curve through them).
fn impulse(s: &[(f64, f64)], t1: f64) -> f64 {
    let (a, b) = (t1 + IMPULSE.0, t1 + IMPULSE.1);
    s.windows(2)
        .filter(|w| w[0].0 >= a && w[1].0 <= b)
        .map(|w| 0.5 * (w[0].1 + w[1].1) * (w[1].0 - w[0].0))
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_probes_sit_half_a_spacing_in_front_of_the_wall() {
        assert_eq!(
            probe_sets(0.005),
            [
                "probe[0].point=[1.6075,0.003]",
                "probe[1].point=[1.6075,0.015]",
                "probe[2].point=[1.6075,0.003]",
                "probe[3].point=[1.6075,0.015]"
            ]
        );
    }

    /// A run that reads the recording itself, sampled every 1 ms: first impact and peak are the recording's (to
    /// the sampling), the RMS 0 to interpolation error, no zero.
    #[test]
    fn the_recording_scores_against_itself() {
        let dir = std::env::temp_dir().join(format!("cosim-lobovsky-score-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("data")).unwrap();
        let data: Vec<(f64, f64)> = (0..=2000)
            .map(|k| {
                let t = 1.0 + 0.004 * k as f64;
                (t, if t < 2.44 { 0.0 } else { 1.5 + (t - 2.44).cos() })
            })
            .collect();
        let csv: String = data.iter().map(|(t, p)| format!("{t},{p}\n")).collect();
        for k in 1..=2 {
            std::fs::write(
                dir.join(format!("data/lobovsky2014_H300_sensor{k}_event.csv")),
                format!("t_star,p_star\n{csv}"),
            )
            .unwrap();
        }
        let (ts, ps) = ((H / G).sqrt(), RHO * G * H);
        let rows: String = (0..=1250)
            .map(|k| {
                let t = 0.001 * k as f64;
                let p = interpolate(&data, t / ts) * ps;
                format!("{t},{p},{p}\n")
            })
            .collect();
        std::fs::write(dir.join("probes.csv"), format!("t,p_sensor1,p_sensor2\n{rows}")).unwrap();
        let s = score(&dir, &dir).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        assert_eq!(s.len(), 2);
        for s in s {
            assert!((s.first_impact - 2.44).abs() <= 0.006, "{s:?}");
            assert!((s.first_impact_data - 2.44).abs() <= 0.004, "{s:?}");
            assert!(
                (s.peak - 2.5).abs() <= 1e-4 && (s.peak_data - 2.5).abs() <= 1e-4,
                "{s:?}"
            );
            assert!(s.rms <= 1e-5, "{s:?}");
            assert_eq!((s.min, s.zeros), (0.0, 0), "{s:?}");
            // ∫ (1.5 + cos(t* − 2.44)) dt* from the impact to 0.5 t* after it: 0.75 + sin 0.5 = 1.2294 (the 0.05
            // before it are zero), to the sampling of the window's ends (5.7e-3 t* at 1 ms, 4e-3 in the data)
            let exact = 0.75 + 0.5f64.sin();
            assert!((s.impulse - exact).abs() <= 0.02, "{s:?}");
            assert!((s.impulse_data - exact).abs() <= 0.01, "{s:?}");
        }
    }
}
