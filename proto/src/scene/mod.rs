//! Scene files (TOML, SI units): the types of `DESIGN.md` §5.1, loading with `--set` overrides, and validation.
//!
//! Every user error is a [`SceneError`]: one line naming the file, the dotted key and the problem.
//!
//! - `schema/`: the types a scene file is read into, one file per section;
//! - `load.rs`: reading, `--set` overrides (`overrides.rs`) and serde errors with their full dotted key;
//! - `validate.rs`: the checks of every value a solver relies on;
//! - `grid.rs`: the FEM grid numbering of a solid;
//! - `sensors.rs`: the pressure sensors a fluid node samples every step (interval-mean pressure probes);
//! - `impact.rs`: the warning for WCSPH pressure probes on a side wall (what an impact reads there);
//! - `unheld.rs`: the warning for a solid with no `fixed` box (gravity and the water move it; only the walls stop it);
//! - `warnings.rs`: the warnings `cosim check` and `cosim run` both give;
//! - [`sizing`]: counts and bytes of a run, estimated from the scene alone.
//!
//! Everything is re-exported here, so users name `cosim_proto::scene::Scene`, `cosim_proto::scene::parse`, ….

pub mod disk;
mod grid;
mod impact;
mod load;
mod mass_ratio;
mod overrides;
mod schema;
mod sensors;
pub mod sizing;
mod unheld;
mod validate;
mod warnings;

pub use impact::IMPACT_DENSITY_DIFFUSION;
pub use load::{load, parse, LoadedScene, SceneError};
pub use schema::{
    shortest_step, whole_fluid_steps, Average, BoxSpec, Component, ContactAlgorithm, ContactSpec, CouplingSpec,
    DensityFilter, ElementKind, EnergyOf, EnergyPart, FluidSolver, FluidSpec, MaterialModel, MaterialSpec,
    PpeSourceKind, ProbeKind, ProbeSpec, ReferenceSpec, RunSpec, Scene, SolidSpec, FLUID_SUBSTEPS_MAX,
    FREE_MESH_DAMPING, ISPH_APD_DEFAULT, ISPH_PPE_TOLERANCE_DEFAULT, ISPH_PPE_TOLERANCE_RANGE, SCENE_VERSION,
    STRUCTURE_COURANT_DEFAULT, STRUCTURE_COURANT_MIN, SUBSTEP_SLACK, WCSPH_APD_DEFAULT, WCSPH_VERLET_SKIN_DEFAULT,
};
pub use sensors::{face_mean as sensors_face_mean, PressureSensor};

/// The shipped scene `scenes/NAME` with `--set` overrides `sets` (unit tests of what a scene warns of).
#[cfg(test)]
pub(crate) fn shipped(name: &str, sets: &[&str]) -> Scene {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../scenes")
        .join(name);
    let text = std::fs::read_to_string(&path).unwrap();
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    parse(name, &text, &sets).unwrap()
}
