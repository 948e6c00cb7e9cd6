//! The bytes a run writes into its output folder, estimated from the scene before it starts: the frames, the probe
//! table and the checkpoints. `cosim check` prints it; `cosim run` and `contact-broker` refuse a run whose outputs
//! cannot fit the free space of the folder's disk, naming the key that makes them large (a run that fills the disk
//! ends `failed` at the frame it could not write, maybe hours in).
//!
//! Frames are counted from what the frame writer puts in them (`contact-broker/src/output/vtu.rs`: every array in
//! base64, 4 characters for 3 bytes), so their estimate is good to the XML around the arrays (~1.5 KB a frame).
//! Checkpoints are counted from what each node saves, per particle and node, measured on the shipped scenes
//! (2026-12-06; docs/PERFORMANCE.md "Output size"); `cosim/tests/output_size.rs` holds both to what runs write.

use super::schema::{ContactAlgorithm, ElementKind, FluidSolver, Scene};
use super::sizing::{bytes_text, count, solid_counts, Sizing};
use crate::Num;

/// Per particle of a particle frame: position (3 × f64), velocity (3 × f64), pressure, density, wall flag
/// (f64 each), connectivity and offset (i64 each), cell type (u8).
const PARTICLE_POINT: f64 = 24.0 + 24.0 + 8.0 + 8.0 + 8.0 + 8.0 + 8.0 + 1.0;
/// Per FE node of a structure frame: position, displacement, velocity (3 × f64 each), mass.
const STRUCTURE_NODE: f64 = 3.0 * 24.0 + 8.0;
/// Per FE node of a structure frame beside a fluid: the interface load (3 × f64).
const STRUCTURE_LOAD: f64 = 24.0;
/// Per FE element of a structure frame besides its connectivity: von Mises stress, stress (3 × f64), solid
/// index (u32), offset (i64), cell type (u8).
const STRUCTURE_CELL: f64 = 8.0 + 24.0 + 4.0 + 8.0 + 1.0;
/// The XML around a frame's arrays (measured: 1.2–1.5 KB).
const FRAME_XML: f64 = 1536.0;
/// One line of a collection file (`frames/*.pvd`), which lists every frame written so far.
const COLLECTION_LINE: f64 = 80.0;
/// One value of `probes.csv` (time or probe value) and its comma, at most.
const CSV_VALUE: f64 = 24.0;
/// A fluid node's checkpoint per fluid particle: its state (x, v, ρ, p, m), acceleration and Verlet reference
/// position (measured, WCSPH and ISPH alike).
const CHECKPOINT_PARTICLE: f64 = 88.0;
/// A fluid node's checkpoint per wall particle.
const CHECKPOINT_WALL: f64 = 40.0;
/// An ISPH fluid node's checkpoint per fluid particle, beside a structure: its contact layer.
const CHECKPOINT_ISPH_CONTACT: f64 = 62.0;
/// The broker's checkpoint per fluid particle: the particles' first positions (for displacement probes) and the
/// pending corrections.
const CHECKPOINT_BROKER_PARTICLE: f64 = 17.0;
/// A structure node's checkpoint per FE node: position, velocity, acceleration (2 × f64 each).
const CHECKPOINT_NODE: f64 = 48.0;
/// The broker's checkpoint per FE node beside a fluid: the interface load and the impulse owed (2 × f64 each, for
/// the interface nodes; counted for all).
const CHECKPOINT_BROKER_NODE: f64 = 16.0;
/// A checkpoint's fixed part: the manifest, the scene, the broker's summary and the nodes' headers.
const CHECKPOINT_FIXED: f64 = 3072.0;

/// What a run writes into its output folder from simulated time `from` to its end.
#[derive(Clone, Debug, PartialEq)]
pub struct DiskEstimate {
    /// Frames (particle and structure frames counted together: one per frame time).
    pub frames: f64,
    /// Bytes of one frame time's files.
    pub frame_bytes: f64,
    /// Checkpoints (0 without `--checkpoint-interval`).
    pub checkpoints: f64,
    /// Bytes of one checkpoint folder (written or not).
    pub checkpoint_bytes: f64,
    /// Bytes of `probes.csv`.
    pub probe_bytes: f64,
    /// Bytes of the frames' collection files at the end.
    pub collection_bytes: f64,
}

impl DiskEstimate {
    /// The outputs of `scene` (sized by `sizing`) from simulated time `from` (0, or a restart's time) to its end,
    /// with a checkpoint every `checkpoint_interval` seconds of simulated time.
    pub fn of(scene: &Scene, sizing: &Sizing, checkpoint_interval: Option<f64>, from: f64) -> Self {
        let run = &scene.run;
        let remaining = (run.end_time - from).max(0.0);
        let left = remaining / run.end_time;
        let beside_fluid = scene.fluid.is_some();
        let (nf, nw) = (sizing.fluid_particles, sizing.wall_particles);
        let base64 = |raw: f64| 4.0 * (raw / 3.0).ceil();
        let particle_frame = match scene.fluid.is_some() {
            true => base64(PARTICLE_POINT * (nf + nw)) + FRAME_XML,
            false => 0.0,
        };
        let per_node = STRUCTURE_NODE + if beside_fluid { STRUCTURE_LOAD } else { 0.0 };
        let structure_raw: f64 = scene
            .solids
            .iter()
            .map(|solid| {
                let (nodes, elements) = solid_counts(solid);
                let corners = match solid.element {
                    ElementKind::Quad4 => 4.0,
                    ElementKind::Tri3 => 3.0,
                };
                nodes * per_node + elements * (STRUCTURE_CELL + 8.0 * corners)
            })
            .sum();
        let structure_frame = match scene.solids.is_empty() {
            true => 0.0,
            false => base64(structure_raw) + FRAME_XML,
        };
        let frames = (run.frame_count() as f64 * left).ceil();
        let collections = f64::from(u8::from(particle_frame > 0.0) + u8::from(structure_frame > 0.0));
        let samples = run.sample_count() as f64;
        // A row of the probe table: the time and every probe's value.
        let values = 1.0 + scene.probes.len() as f64;
        let isph_contact = scene.fluid.as_ref().is_some_and(|f| f.solver == FluidSolver::Isph)
            && !scene.solids.is_empty()
            && scene.contact.algorithm == ContactAlgorithm::ParticleElement;
        let per_particle = CHECKPOINT_PARTICLE + if isph_contact { CHECKPOINT_ISPH_CONTACT } else { 0.0 };
        let broker_node = if beside_fluid { CHECKPOINT_BROKER_NODE } else { 0.0 };
        // One at every whole multiple of the interval and one at the end, at most one a coupling step (a run
        // takes at least end_time / max_dt of them).
        let checkpoints = checkpoint_interval.map_or(0.0, |i| {
            (remaining / i).ceil().min((remaining / scene.coupling.max_dt).ceil())
        });
        // The broker's checkpoint also holds the probe table so far (8 B a value and 8 a row): at n checkpoints
        // evenly spread, (n + 1) / 2n of the whole table on average.
        let table_share = match checkpoints > 0.0 {
            true => (checkpoints + 1.0) / (2.0 * checkpoints),
            false => 0.5,
        };
        let checkpoint_bytes = nf * (per_particle + CHECKPOINT_BROKER_PARTICLE)
            + nw * CHECKPOINT_WALL
            + sizing.fem_nodes * (CHECKPOINT_NODE + broker_node)
            + table_share * samples * (values + 1.0) * 8.0
            + CHECKPOINT_FIXED;
        DiskEstimate {
            frames,
            frame_bytes: particle_frame + structure_frame,
            checkpoints,
            checkpoint_bytes,
            probe_bytes: samples * left * values * CSV_VALUE,
            collection_bytes: collections * (run.frame_count() as f64) * COLLECTION_LINE,
        }
    }

    /// Bytes in all.
    pub fn total(&self) -> f64 {
        self.frames * self.frame_bytes
            + self.checkpoints * self.checkpoint_bytes
            + self.probe_bytes
            + self.collection_bytes
    }

    /// One line: the total and its parts (`cosim check`).
    pub fn text(&self) -> String {
        let checkpoints = match self.checkpoints > 0.0 {
            true => format!(
                "{} checkpoints of {}",
                count(self.checkpoints),
                bytes_text(self.checkpoint_bytes)
            ),
            false => format!(
                "with --checkpoint-interval {} a checkpoint",
                bytes_text(self.checkpoint_bytes)
            ),
        };
        format!(
            "about {} written to the output folder ({} frames of {}, probes.csv {}; {checkpoints})",
            bytes_text(self.total()),
            count(self.frames),
            bytes_text(self.frame_bytes),
            bytes_text(self.probe_bytes + self.collection_bytes)
        )
    }

    /// Refuse outputs larger than `free` bytes: the key that makes them large (the frames' interval, or
    /// `--checkpoint-interval`) and one line with what they need and what `dir` has.
    pub fn refuse_above(&self, scene: &Scene, free: u64, dir: &str) -> Result<(), (String, String)> {
        let total = self.total();
        if total <= free as f64 {
            return Ok(());
        }
        let run = &scene.run;
        let (key, what) = if self.checkpoints * self.checkpoint_bytes > self.frames * self.frame_bytes {
            (
                "--checkpoint-interval".to_string(),
                format!(
                    "{} checkpoints of {}",
                    count(self.checkpoints),
                    bytes_text(self.checkpoint_bytes)
                ),
            )
        } else {
            let (key, interval) = match run.frame_interval {
                Some(f) => ("run.frame_interval", f),
                None => ("run.output_interval", run.output_interval),
            };
            let frames = format!("{} frames of {}", count(self.frames), bytes_text(self.frame_bytes));
            (key.to_string(), format!("{} s writes {frames}", Num(interval)))
        };
        Err((
            key,
            format!(
                "{what}: the outputs need about {}, {dir} has {} free (--ignore-disk-space starts it anyway)",
                bytes_text(total),
                bytes_text(free as f64)
            ),
        ))
    }
}
