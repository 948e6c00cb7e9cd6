//! `DIR/summary.json` (`DESIGN.md` §5): what a run did and how it ended, built by [`SummaryBuilder`] and written
//! by [`write`] over the room [`reserve`] kept for it (`file.rs`).

use std::collections::BTreeMap;

use cosim_proto::run_status::RunStatus;
use cosim_proto::scene::Scene;
use serde::{Deserialize, Serialize};

mod file;

pub use file::{reserve, write, FILE, PLACEHOLDER, RESERVED_BYTES};

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
    pub status: RunStatus,
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
    /// How the structure's contact impulse was relaxed (`contact.reaction_relaxation`; ISPH with
    /// `particle_particle` by default): the largest ω of a step, the lag τ [s] that bounds it (0: none) and why;
    /// `null` where every impulse was given at once.
    #[serde(default)]
    pub reaction_relaxation: Option<crate::relaxation::RelaxationChoice>,
    /// The longest coupling step the contact force's stiffness allowed [s] (WCSPH with `particle_particle`:
    /// `contact_step.rs`), `null` where it set no bound.
    #[serde(default)]
    pub contact_step_bound: Option<f64>,
    /// The largest mechanical energy the fluid and the structure together gained over t = 0, at the output times,
    /// against the energy the water can release (`energy_balance.rs`); `null` without a fluid under gravity.
    #[serde(default)]
    pub energy_growth: Option<crate::energy_balance::EnergyGrowth>,
    /// `--record`: what the trace holds, and why it stopped before the run's end if it did; `null` without it.
    #[serde(default)]
    pub trace: Option<TraceNote>,
    /// The first structure node found inside a wall at an output time, deeper than the walls' contact leaves one
    /// (`wall_entry.rs`); `null` where none was.
    #[serde(default)]
    pub solid_in_wall: Option<crate::wall_entry::WallEntry>,
}

/// What `--record` wrote (`crate::recorder`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TraceNote {
    /// Records in `trace/trace.bin`.
    pub records: u64,
    /// Its bytes.
    pub bytes: u64,
    /// Why the recording stopped before the run's end (a full disk, or the room the outputs needed), `null` where
    /// it holds the whole run.
    pub stopped: Option<String>,
}

impl Summary {
    /// A run that failed before it computed anything: `message` says why.
    pub fn failed(run_id: &str, mode: &str, message: String) -> Self {
        SummaryBuilder::new(run_id, mode).failed(message)
    }

    /// Whether this is the placeholder [`reserve`] wrote: the run's own summary was never written.
    pub fn is_placeholder(&self) -> bool {
        self.status == RunStatus::Failed && self.message == PLACEHOLDER
    }

    /// Carry on the counts of `saved`, the summary of the run a checkpoint was taken in: its steps, simulated time,
    /// frames, samples, timings, contact statistics and energy balance.
    pub fn continue_from(&mut self, saved: &Summary) {
        self.steps = saved.steps;
        self.fem_substeps = saved.fem_substeps;
        self.sph_substeps = saved.sph_substeps;
        self.sim_time = saved.sim_time;
        self.frames = saved.frames;
        self.samples = saved.samples;
        self.timings = saved.timings.clone();
        self.contact_stats = saved.contact_stats.clone();
        self.energy_growth = saved.energy_growth.clone();
        self.solid_in_wall = saved.solid_in_wall.clone();
    }

    /// End the run after `wall_seconds`: `ok`, saying how far it got, or `failure`'s status and message.
    pub fn end(&mut self, failure: Option<(RunStatus, String)>, wall_seconds: f64) {
        match failure {
            Some((status, message)) => {
                self.status = status;
                self.message = message;
            }
            None => {
                self.status = RunStatus::Ok;
                self.message = format!(
                    "reached t = {} s in {} steps",
                    cosim_proto::Num(self.sim_time),
                    self.steps
                );
            }
        }
        self.wall_seconds = wall_seconds;
    }
}

/// How every summary of a run begins: the coordinator's, the placeholder [`reserve`] writes, and the one the
/// launcher writes for a run that ended without its own. Counters not set here start at zero.
#[derive(Clone, Debug)]
pub struct SummaryBuilder(Summary);

impl SummaryBuilder {
    /// Run `run_id`, launched in `mode` (`processes` | `in-process`), nothing computed yet.
    pub fn new(run_id: &str, mode: &str) -> Self {
        Self(Summary {
            status: RunStatus::Failed,
            message: String::new(),
            run_id: run_id.into(),
            scene: String::new(),
            steps: 0,
            fem_substeps: 0,
            sph_substeps: 0,
            sim_time: 0.0,
            wall_seconds: 0.0,
            particles: 0,
            fem_nodes: 0,
            fem_elements: 0,
            solver: "none".into(),
            contact: "none".into(),
            mode: mode.into(),
            frames: 0,
            samples: 0,
            timings: Timings::default(),
            contact_stats: ContactStats::default(),
            counts: BTreeMap::new(),
            reaction_relaxation: None,
            contact_step_bound: None,
            energy_growth: None,
            trace: None,
            solid_in_wall: None,
        })
    }

    /// The scene's name, its fluid solver (`none` without a fluid) and its contact algorithm (`none` unless a fluid
    /// meets a solid).
    pub fn scene(mut self, scene: &Scene) -> Self {
        let s = &mut self.0;
        s.scene = scene.run.name.clone();
        s.solver = scene
            .fluid
            .as_ref()
            .map_or("none".into(), |f| format!("{:?}", f.solver).to_lowercase());
        s.contact = if scene.fluid.is_some() && !scene.solids.is_empty() {
            scene.contact.algorithm.name().into()
        } else {
            "none".into()
        };
        self
    }

    /// The sizes the nodes registered: fluid particles, FE nodes and FE elements.
    pub fn sizes(mut self, particles: u64, fem_nodes: u64, fem_elements: u64) -> Self {
        (self.0.particles, self.0.fem_nodes, self.0.fem_elements) = (particles, fem_nodes, fem_elements);
        self
    }

    /// What a run that ended without its own summary left on disk: probe samples up to `sim_time`, and frames.
    pub fn kept(mut self, samples: u64, sim_time: f64, frames: u64) -> Self {
        (self.0.samples, self.0.sim_time, self.0.frames) = (samples, sim_time, frames);
        self
    }

    /// The wall time of the run [s].
    pub fn wall_seconds(mut self, seconds: f64) -> Self {
        self.0.wall_seconds = seconds;
        self
    }

    /// A run under way: `ok` until [`Summary::end`] says otherwise.
    pub fn running(mut self) -> Summary {
        self.0.status = RunStatus::Ok;
        self.0
    }

    /// A run that failed: `message` says why.
    pub fn failed(mut self, message: String) -> Summary {
        self.0.status = RunStatus::Failed;
        self.0.message = message;
        self.0
    }
}
