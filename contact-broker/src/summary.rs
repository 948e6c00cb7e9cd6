//! `DIR/summary.json` (`DESIGN.md` §5).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

/// Seconds spent per part of the run.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Timings {
    /// FEM computation (as reported by the node).
    pub fem: f64,
    /// SPH computation.
    pub sph: f64,
    /// Broker computation (contact, outputs).
    pub broker: f64,
    /// Round trips minus the nodes' computation.
    pub messaging: f64,
}

/// Contact statistics.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct ContactStats {
    /// Contacts resolved over the run.
    pub contacts: u64,
    /// Largest penetration seen [m].
    pub max_penetration: f64,
    /// Largest relative change of total linear momentum made by any step's corrections.
    pub linear_momentum_change: f64,
    /// Largest relative change of total angular momentum made by any step's corrections.
    pub angular_momentum_change: f64,
    /// Fluid particles sent to the broker per coupling step (the region of interest), on average.
    #[serde(default)]
    pub exchanged_per_step: f64,
    /// Most fluid particles sent in one coupling step.
    #[serde(default)]
    pub exchanged_max: u64,
}

/// The run's summary.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Summary {
    /// `ok` | `unstable` | `failed`.
    pub status: String,
    /// One line.
    pub message: String,
    /// Run id.
    pub run_id: String,
    /// Scene name.
    pub scene: String,
    /// Coupling steps taken.
    pub steps: u64,
    /// FEM sub-steps taken.
    pub fem_substeps: u64,
    /// SPH steps taken.
    #[serde(default)]
    pub sph_substeps: u64,
    /// Simulated time reached [s].
    pub sim_time: f64,
    /// Wall time of the run [s].
    pub wall_seconds: f64,
    /// Fluid particles.
    pub particles: u64,
    /// FE nodes.
    pub fem_nodes: u64,
    /// FE elements.
    pub fem_elements: u64,
    /// Fluid solver (`none` without fluid).
    pub solver: String,
    /// Contact algorithm in use (`none` without fluid or solid).
    pub contact: String,
    /// `processes` | `in-process`.
    pub mode: String,
    /// Frames written.
    pub frames: u64,
    /// Probe samples written.
    pub samples: u64,
    /// Seconds per part.
    pub timings: Timings,
    /// Contact statistics.
    pub contact_stats: ContactStats,
    /// What each node counted, by node (`fem-node`, `sph-node`), as it reported at the end of the run: its sizes,
    /// and for the WCSPH fluid `wall_pushes`, the particles its wall guard put back out of a wall over the run (a
    /// run that needed many of them is a run to look at). Empty for a node that could not say.
    #[serde(default)]
    pub counts: BTreeMap<String, BTreeMap<String, u64>>,
}
