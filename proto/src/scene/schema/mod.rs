//! The scene file's types (`DESIGN.md` §5.1), one file per section: what serde reads a scene into. Defaults
//! sit next to the field they fill; nothing here checks a value (that is `validate.rs`).

mod contact;
mod coupling;
mod fluid;
mod probe;
mod solid;

use serde::{Deserialize, Serialize};

pub use contact::{ContactAlgorithm, ContactSpec};
pub use coupling::CouplingSpec;
pub use fluid::{DensityFilter, FluidSolver, FluidSpec, PpeSourceKind, ISPH_APD_DEFAULT, WCSPH_APD_DEFAULT};
pub use probe::{Average, Component, EnergyOf, EnergyPart, ProbeKind, ProbeSpec, ReferenceSpec};
pub use solid::{ElementKind, MaterialModel, MaterialSpec, SolidSpec};

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
    /// Interval between frames and probe samples \[s\].
    pub output_interval: f64,
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
    /// The scene as TOML text (used to hand the resolved scene to the nodes).
    pub fn to_toml(&self) -> String {
        toml::to_string(self).expect("a validated scene serialises")
    }
}
