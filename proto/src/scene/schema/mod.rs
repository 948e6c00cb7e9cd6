//! The scene file's types (`DESIGN.md` §5.1), one file per section: what serde reads a scene into. Defaults
//! sit next to the field they fill; nothing here checks a value (that is `validate.rs`).

mod contact;
mod coupling;
mod fluid;
mod probe;
mod solid;

use serde::{Deserialize, Serialize};

pub use contact::{ContactAlgorithm, ContactSpec};
pub use coupling::{
    shortest_step, whole_fluid_steps, CouplingSpec, FLUID_SUBSTEPS_MAX, STRUCTURE_COURANT_DEFAULT,
    STRUCTURE_COURANT_MIN, SUBSTEP_SLACK,
};
pub use fluid::{
    DensityFilter, FluidSolver, FluidSpec, PpeSourceKind, ISPH_APD_DEFAULT, ISPH_PPE_TOLERANCE_DEFAULT,
    ISPH_PPE_TOLERANCE_RANGE, WCSPH_APD_DEFAULT, WCSPH_VERLET_SKIN_DEFAULT,
};
pub use probe::{Average, Component, EnergyOf, EnergyPart, ProbeKind, ProbeSpec, ReferenceSpec};
pub use solid::{ElementKind, MaterialModel, MaterialSpec, SolidSpec, FREE_MESH_DAMPING};

/// The scene format version this build reads.
pub const SCENE_VERSION: u32 = 1;

/// A whole scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Format version; must be [`SCENE_VERSION`].
    pub version: u32,
    /// Run-wide settings.
    pub run: RunSpec,
    /// Water (`[fluid]`); absent for a structure-only run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fluid: Option<FluidSpec>,
    /// Rigid walls (`[[wall]]`), filled with fixed boundary particles.
    #[serde(default, rename = "wall", skip_serializing_if = "Vec::is_empty")]
    pub walls: Vec<BoxSpec>,
    /// Elastic structures (`[[solid]]`).
    #[serde(default, rename = "solid", skip_serializing_if = "Vec::is_empty")]
    pub solids: Vec<SolidSpec>,
    /// Contact algorithm settings.
    #[serde(default)]
    pub contact: ContactSpec,
    /// Coupling (step) settings.
    #[serde(default)]
    pub coupling: CouplingSpec,
    /// Probes sampled every `run.output_interval` (`[[probe]]`).
    #[serde(default, rename = "probe", skip_serializing_if = "Vec::is_empty")]
    pub probes: Vec<ProbeSpec>,
}

/// `[run]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunSpec {
    /// Name used in outputs.
    pub name: String,
    /// Simulated end time \[s\].
    pub end_time: f64,
    /// Gravity [m/s²].
    #[serde(default = "default_gravity")]
    pub gravity: [f64; 2],
    /// Interval between probe samples (and frames, unless `frame_interval` says otherwise) \[s\].
    pub output_interval: f64,
    /// Interval between frames \[s\]: a whole multiple of `output_interval` (default: every output time). The first
    /// and the last output times always get a frame.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frame_interval: Option<f64>,
}

impl RunSpec {
    /// Frames are written at every `frame_every`-th output time (the first and the last always): the
    /// `frame_interval` in output intervals, 1 without one. Validation has made it a whole positive multiple.
    pub fn frame_every(&self) -> u64 {
        self.frame_interval
            .map_or(1, |f| (f / self.output_interval).round().max(1.0) as u64)
    }

    /// Whether output time number `k` (0 at t = 0) gets a frame; `last`: it is the run's last output time.
    pub fn is_frame(&self, k: u64, last: bool) -> bool {
        last || k % self.frame_every() == 0
    }

    /// Output times (probe samples) of a run to `end_time`, t = 0 and the end included.
    pub fn sample_count(&self) -> u64 {
        ((self.end_time / self.output_interval).ceil() as u64).saturating_add(1)
    }

    /// Frames a run to `end_time` writes: output times 0, `frame_every`, 2 `frame_every`, … and the last one.
    pub fn frame_count(&self) -> u64 {
        let last = self.sample_count() - 1;
        let every = self.frame_every();
        last / every + 1 + u64::from(last % every != 0)
    }
}

fn default_gravity() -> [f64; 2] {
    [0.0, -9.81]
}

/// An axis-aligned box.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxSpec {
    /// Lower corner.
    pub min: [f64; 2],
    /// Upper corner.
    pub max: [f64; 2],
}

impl BoxSpec {
    /// True if `p` lies inside the box (bounds included).
    pub fn contains(&self, p: [f64; 2]) -> bool {
        (0..2).all(|k| p[k] >= self.min[k] && p[k] <= self.max[k])
    }
}

impl Scene {
    /// The box round the fluid's blocks, the walls and the solids (lower, upper corner); inverted (lower +∞, upper
    /// −∞) where the scene has none of them.
    pub fn bounds(&self) -> ([f64; 2], [f64; 2]) {
        let boxes = (self.fluid.iter().flat_map(|f| &f.blocks).chain(&self.walls))
            .map(|b| (b.min, b.max))
            .chain(self.solids.iter().map(|s| (s.min, s.max)));
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for (min, max) in boxes {
            for k in 0..2 {
                lo[k] = lo[k].min(min[k]);
                hi[k] = hi[k].max(max[k]);
            }
        }
        (lo, hi)
    }

    /// The scene as TOML text (used to hand the resolved scene to the nodes).
    pub fn to_toml(&self) -> String {
        toml::to_string(self).expect("a validated scene serialises")
    }
}

/// A number key left at 0 is not written to the resolved scene (`skip_serializing_if`).
fn is_zero(x: &f64) -> bool {
    *x == 0.0
}
