//! One line of `DIR/bench.json`: what ran, how long it took, how much memory, how far from its reference.

use std::path::Path;

use anyhow::Context;
use serde::{Deserialize, Serialize};

use contact_broker::energy_balance::made_energy;

use super::lobovsky::SensorScore;

/// One bench case's result. A case that failed or blew up is a record too, with `status` and `message`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Record {
    /// `dam_break` | `hydrostatic_plate` | `elastic_gate` | `scaling` | `stress`.
    pub case: String,
    /// Which stress test; empty for the other cases.
    #[serde(default)]
    pub variant: String,
    /// `wcsph` | `isph`.
    pub solver: String,
    /// `particle_element` | `particle_particle` | `none` (no structure).
    pub contact: String,
    /// Fluid particle spacing [m].
    pub spacing: f64,
    /// Worker threads of the run.
    pub threads: usize,
    /// Runs of this case; the record is the one with the median `sph_ns_per_particle_step`.
    pub repeats: usize,
    /// Fluid particles.
    pub particles: u64,
    /// Fluid (SPH) steps taken.
    pub steps: u64,
    /// Coupling steps taken (the broker's steps).
    pub coupling_steps: u64,
    /// Simulated time reached [s].
    pub sim_time: f64,
    /// Simulated end time asked for [s].
    pub end_time: f64,
    /// Wall time of the run as `summary.json` reports it (set-up to last output) [s].
    pub wall_seconds: f64,
    /// Wall time of the whole child process, start to exit [s].
    pub process_seconds: f64,
    /// particles × steps / wall_seconds.
    pub particle_steps_per_second: f64,
    /// Seconds the fluid node spent computing (`summary.json` timings.sph).
    pub sph_seconds: f64,
    /// sph_seconds / (particles × steps) [ns]: the fluid's cost per particle-step, outputs and set-up left out.
    pub sph_ns_per_particle_step: f64,
    /// Relative error against the case's reference (see `metric`); `null` when not measured.
    pub error: Option<f64>,
    /// The worst pointwise relative error, where the metric has points (the dam break); else `null`.
    pub error_max: Option<f64>,
    /// The measured quantity the error is computed from (front error has none: `null`).
    pub value: Option<f64>,
    /// The reference value (`null` for a curve).
    pub reference: Option<f64>,
    /// Stress cases: the fluid's largest total energy over its budget ρ0 g Σ W H²/2 (energy the scheme created;
    /// 0 at t = 0); `null` for the other cases.
    #[serde(default)]
    pub energy_growth: Option<f64>,
    /// Stress cases: the fluid's total energy at the end over its budget (negative: dissipated).
    #[serde(default)]
    pub energy_drift: Option<f64>,
    /// Every case: the most mechanical energy the fluid and the structure together gained over t = 0, as a fraction
    /// of the energy the water can release (`summary.json` `energy_growth.largest`); `null` without a fluid under
    /// gravity. Past `energy_balance::WARN_GROWTH` the case made energy and its result is not physical, whatever its error.
    #[serde(default)]
    pub energy_made: Option<f64>,
    /// The wall-impact case: each sensor's first impact, peak, RMS after the impact, lowest sample and exact
    /// zeros (`bench/lobovsky.rs`); empty for the other cases.
    #[serde(default)]
    pub sensors: Vec<SensorScore>,
    /// How `error` is computed.
    pub metric: String,
    /// Peak resident memory of the run's process (VmHWM) [bytes].
    pub peak_rss_bytes: Option<u64>,
    /// CPU time of the run's process, all threads [s].
    pub cpu_seconds: Option<f64>,
    /// The machine's 1-minute load average when the case started (the bench itself adds about 1).
    pub load_average: Option<f64>,
    /// `ok` | `unstable` | `failed` | `timeout`.
    pub status: String,
    /// One line: the run's message, or why the case has no result.
    pub message: String,
    /// The `--set` overrides the case ran with.
    pub sets: Vec<String>,
    /// The run's output folder.
    pub out: String,
}

impl Record {
    /// Whether the case ran to its end time with a finite error.
    pub fn ok(&self) -> bool {
        self.status == "ok" && self.error.is_some_and(f64::is_finite)
    }

    /// "made N % of its energy budget" where the case made energy (`energy_made`); `None` otherwise.
    pub fn energy_note(&self) -> Option<String> {
        let made = self.energy_made.filter(|g| made_energy(*g))?;
        Some(format!("made {:.0} % of its energy budget", 100.0 * made))
    }

    /// The status as the report shows it: an `ok` run that made energy says how much ([`Record::energy_note`]).
    pub fn status_shown(&self) -> String {
        match self.energy_note() {
            Some(note) if self.status == "ok" => format!("ok, {note}"),
            _ => self.status.clone(),
        }
    }
}

/// Write `records` as a pretty JSON list.
pub fn write(path: &Path, records: &[Record]) -> anyhow::Result<()> {
    let text = serde_json::to_string_pretty(records)?;
    std::fs::write(path, text + "\n").with_context(|| format!("cannot write {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(status: &str, energy_made: Option<f64>) -> Record {
        let mut r: Record = serde_json::from_str(r#"{"case": "gate", "variant": "", "solver": "isph", "contact": "pp",
            "spacing": 0.004, "threads": 1, "repeats": 1, "particles": 1, "steps": 1, "coupling_steps": 1,
            "sim_time": 0.4, "end_time": 0.4, "wall_seconds": 1.0, "process_seconds": 1.0, "particle_steps_per_second": 1.0,
            "sph_seconds": 1.0, "sph_ns_per_particle_step": 1.0, "metric": "peak", "status": "ok", "message": "",
            "sets": [], "out": ""}"#)
        .unwrap();
        r.status = status.into();
        r.energy_made = energy_made;
        r
    }

    #[test]
    fn an_ok_case_that_made_energy_says_how_much() {
        assert_eq!(
            record("ok", Some(2.655)).status_shown(),
            "ok, made 266 % of its energy budget"
        );
        assert_eq!(
            record("ok", Some(contact_broker::energy_balance::WARN_GROWTH)).status_shown(),
            "ok"
        );
        assert_eq!(record("ok", Some(0.03)).status_shown(), "ok");
        assert_eq!(record("ok", None).status_shown(), "ok");
        assert_eq!(record("unstable", Some(3.0)).status_shown(), "unstable");
        // Older bench.json files have no energy_made.
        assert_eq!(record("ok", None).energy_made, None);
    }
}
