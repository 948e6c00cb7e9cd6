//! How heavy a fluid particle is against the structure's mesh cells: the number that decides whether the
//! particle–element contact, which exchanges momentum between one particle and a segment's two nodes, rings a
//! structure mesh much finer than the fluid's spacing (issue 16; docs/CORRECTIONS.md "The structure's mesh against the
//! fluid's particles").
//!
//! Measured on the elastic gate (E = 12 MPa, 0.2 s; `energy_growth`, fluid and structure together, as a fraction of
//! the energy the water can release, 0.1 being where a run warns): with WCSPH at its own step the gain follows this
//! ratio alone, 0.0015 at 14.5 (Δx = 2 or 4 mm), 0.019 at 28 and 0.106 at 58; with ISPH it also grows with the
//! coupling step (at `coupling.max_dt` 1e-4: 0.009 at 4.4, 0.053 at 14.5, 0.44 at 58).

use super::schema::{ContactAlgorithm, FluidSolver, Scene, SolidSpec};
use crate::Num;

/// The ratio above which `cosim check` and `cosim run` warn: between the gate's 28 (a gain of 0.019 with WCSPH) and
/// 58 (0.106).
pub const HEAVY_PARTICLE: f64 = 30.0;

/// ISPH coupled to a structure: `cosim check` warns where a coupling step spans at least this many of the structure's
/// FE steps and a fluid particle weighs at least [`LONG_STEP_RATIO`] cells. On the gate 24 FE steps kept every such
/// case under the run's energy warning (0.018–0.093 of the budget) and 48 none (0.099–0.44); the hydrostatic plate
/// spans 78 with a particle of 1.5 cells and keeps its energy.
pub const LONG_COUPLING_STEP: u64 = 32;

/// See [`LONG_COUPLING_STEP`]: the shipped gate's 3.6 is above it, the plate's 1.5 below.
pub const LONG_STEP_RATIO: f64 = 3.0;

/// With the fluid sub-cycled between contact passes (`coupling.fluid_substeps` > 1 in force): `cosim check` and `cosim
/// run` warn where a fluid particle weighs more than this many cells of a solid. A pass every k fluid steps gives the
/// mesh k-fold impulses k times less often. On the gate (0.2 s, WCSPH; `energy_growth` as a fraction of the budget)
/// the 2 mm gate, 3.6 cells, kept its energy at 3 fluid steps a pass (0.0006, lockstep 0) and rang at 2 (0.035); the
/// 4 mm gate, 14.5 cells, gained 0.050 / 0.059 / 0.083 at 2 / 3 / 4 against 0.0014 in lockstep
/// (docs/CORRECTIONS.md "The fluid sub-cycled between contact passes").
pub const SUBSTEP_RATIO: f64 = 4.0;

impl SolidSpec {
    /// The mass of one cell of the mesh grid per unit depth [kg/m]: ρ_s times the cell's area (one quad4 element, two
    /// tri3 elements).
    pub fn cell_mass(&self) -> f64 {
        let w = (self.max[0] - self.min[0]) / f64::from(self.divisions[0]);
        let h = (self.max[1] - self.min[1]) / f64::from(self.divisions[1]);
        self.material.density * w * h
    }
}

impl Scene {
    /// For each solid a fluid touches through a contact algorithm, its name and a fluid particle's mass ρ Δx² over
    /// one of its cells' ([`SolidSpec::cell_mass`]), in the scene's order; empty without a fluid or with
    /// `contact.algorithm = "none"`.
    pub fn particle_to_cell_mass(&self) -> Vec<(&str, f64)> {
        let Some(fluid) = self.fluid.as_ref() else {
            return Vec::new();
        };
        if self.contact.algorithm == ContactAlgorithm::None {
            return Vec::new();
        }
        let particle = fluid.density * fluid.spacing * fluid.spacing;
        self.solids
            .iter()
            .map(|s| (s.name.as_str(), particle / s.cell_mass()))
            .collect()
    }

    /// One line per solid whose cells are more than [`HEAVY_PARTICLE`] times lighter than a fluid particle: what it
    /// does to a coupled run and what to change.
    pub fn heavy_particle_warnings(&self) -> Vec<String> {
        self.particle_to_cell_mass()
            .into_iter()
            .filter(|&(_, ratio)| ratio > HEAVY_PARTICLE)
            .map(|(name, ratio)| {
                format!(
                    "a fluid particle weighs {:.0} cells of solid `{name}` (above {HEAVY_PARTICLE:.0}): the contact's \
                     impulses ring a mesh that fine and the coupled run gains energy (measured on the gate: 0.11 of \
                     the water's releasable energy at 58 with WCSPH, 0.44 with ISPH at coupling.max_dt 1e-4); coarsen \
                     the solid's divisions, refine fluid.spacing, {}or spread the load (contact.load_spread = 2; \
                     docs/CORRECTIONS.md)",
                    Num(ratio),
                    self.damping_hint(name, "damp the ringing ({}.mesh_damping = 0.02), ")
                )
            })
            .collect()
    }

    /// A warning where the fluid, its stable step `dt_fluid`, is sub-cycled between contact passes
    /// ([`Scene::fluid_steps_per_pass`] > 1) against a solid whose cells a particle outweighs more than
    /// [`SUBSTEP_RATIO`] times.
    pub fn fluid_substeps_warning(&self, dt_fluid: f64) -> Option<String> {
        let k = self.fluid_steps_per_pass(dt_fluid);
        let (name, ratio) = self.heaviest_particle()?;
        (k > 1 && ratio > SUBSTEP_RATIO).then(|| {
            format!(
                "coupling.fluid_substeps = {} against solid `{name}`, whose cells a fluid particle outweighs {:.1} \
                 times (above {SUBSTEP_RATIO:.0}): a contact pass every {k} fluid steps rings a mesh that fine (the 4 mm \
                 gate, 14.5 cells, gained 0.05-0.08 of the water's releasable energy at 2-4 against 0.0014 in lockstep); \
                 set coupling.fluid_substeps = 1 (docs/CORRECTIONS.md)",
                self.coupling.fluid_substeps,
                Num(ratio)
            )
        })
    }

    /// With ISPH, a coupling step of `coupling_dt` spanning `fem_steps` FE steps of `fem_dt` each: a warning where it
    /// spans at least [`LONG_COUPLING_STEP`] of them against a solid whose cells a particle outweighs
    /// [`LONG_STEP_RATIO`] times, naming a `coupling.max_dt` of 24 FE steps. None where the structure's speed bounds
    /// the step (`coupling.structure_courant` > 0 with `particle_element`: the 4 mm gate at ISPH's own step then
    /// keeps within the run's energy warning, docs/CORRECTIONS.md "The coupling step bounded by the structure's
    /// speed").
    pub fn long_coupling_step_warning(&self, coupling_dt: f64, fem_dt: f64, fem_steps: u64) -> Option<String> {
        let bounded =
            self.coupling.structure_courant > 0.0 && self.contact.algorithm == ContactAlgorithm::ParticleElement;
        let isph = self.fluid.as_ref()?.solver == FluidSolver::Isph && !bounded;
        let (name, ratio) = self.heaviest_particle()?;
        (isph && ratio >= LONG_STEP_RATIO && fem_steps >= LONG_COUPLING_STEP).then(|| {
            format!(
                "with ISPH the coupling step ({coupling_dt:.2e} s) spans {fem_steps} FE steps of the structure, and a \
                 fluid particle weighs {:.1} cells of solid `{name}`: measured on the gate, 24 FE steps a coupling \
                 step kept the energy and 48 did not (ISPH's own step, which the default coupling.max_dt = 1e-3 leaves \
                 free, made the 4 mm gate unstable without a bound from the structure's speed); try coupling.max_dt = \
                 {:.0e}{}{}",
                Num(ratio),
                24.0 * fem_dt,
                self.damping_hint(
                    name,
                    ", or damp the structure's ringing ({}.mesh_damping = 0.02: the 4 mm gate then ends at ISPH's own \
                     step; docs/CORRECTIONS.md)"
                ),
                match self.contact.algorithm {
                    ContactAlgorithm::ParticleElement =>
                        ", or bound the step by the structure's speed again \
                                                          (coupling.structure_courant = 0.05)",
                    _ => "",
                }
            )
        })
    }

    /// The solid whose cells a fluid particle outweighs most, and by how much ([`Scene::particle_to_cell_mass`]).
    fn heaviest_particle(&self) -> Option<(&str, f64)> {
        self.particle_to_cell_mass()
            .into_iter()
            .max_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// `solid[i]`, the key of the solid named `name`.
    fn solid_key(&self, name: &str) -> String {
        let i = self.solids.iter().position(|s| s.name == name).unwrap_or(0);
        format!("solid[{i}]")
    }

    /// `hint` with its `{}` replaced by the solid's key where solid `name` is undamped at its mesh's scale; empty
    /// where it already is (a solid held nowhere by default, `FREE_MESH_DAMPING`).
    fn damping_hint(&self, name: &str, hint: &str) -> String {
        let undamped = self
            .solids
            .iter()
            .find(|s| s.name == name)
            .is_none_or(|s| s.mesh_damping() == 0.0);
        if undamped {
            hint.replace("{}", &self.solid_key(name))
        } else {
            String::new()
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::scene::parse;

    /// The shipped gate at Δx = 4 mm: ρ Δx² / (ρ_s w h / (nx ny)) = 16 / 1.1 = 14.55 against its 1 mm cells; halving
    /// the cells quadruples it (58.2, over the bound: one warning naming the solid); no contact, no ratio.
    #[test]
    fn the_ratio_is_the_particle_over_a_cell_and_warns_above_the_bound() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/elastic_gate.toml");
        let text = std::fs::read_to_string(path).unwrap();
        let gate = |more: &[&str]| {
            let mut sets = vec!["fluid.spacing=0.004".to_string()];
            sets.extend(more.iter().map(|s| s.to_string()));
            parse("g.toml", &text, &sets).unwrap()
        };
        let scene = gate(&[]);
        let r = scene.particle_to_cell_mass();
        assert_eq!(r.len(), 1);
        assert_eq!(r[0].0, "gate");
        assert!((r[0].1 - 16.0 / 1.1).abs() < 1e-9, "{r:?}");
        assert!(scene.heavy_particle_warnings().is_empty());
        let fine = gate(&["solid[0].divisions=[10,158]"]);
        let r = fine.particle_to_cell_mass();
        assert!((r[0].1 - 64.0 / 1.1).abs() < 1e-9, "{r:?}");
        let w = fine.heavy_particle_warnings();
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(w[0].contains("weighs 58 cells of solid `gate`"), "{}", w[0]);
        assert!(
            w[0].contains("damp the ringing (solid[0].mesh_damping = 0.02), or spread"),
            "{}",
            w[0]
        );
        // A solid held nowhere is damped already (FREE_MESH_DAMPING): no advice to damp it.
        let free = gate(&["solid[0].divisions=[10,158]", "solid[0].fixed=[]"]).heavy_particle_warnings();
        assert!(
            free[0].contains("refine fluid.spacing, or spread the load"),
            "{}",
            free[0]
        );
        assert!(gate(&["contact.algorithm=\"none\""]).particle_to_cell_mass().is_empty());
        // The fluid sub-cycled between passes: the 4 mm gate's 14.5 cells warn where 2 or more of its fluid steps
        // (6.5e-5 s) fit under max_dt, not under the shipped 1e-4 (1.5 steps), not in lockstep, not with ISPH (which
        // keeps the lockstep); the shipped 2 mm gate's 3.6 cells do not.
        let dt = 6.5e-5;
        let long = |k: &str| gate(&[k, "coupling.max_dt=2.5e-4"]);
        let w = long("coupling.fluid_substeps=4").fluid_substeps_warning(dt).unwrap();
        assert!(
            w.starts_with(
                "coupling.fluid_substeps = 4 against solid `gate`, whose cells a fluid particle outweighs 14.5 times \
                 (above 4): a contact pass every 3 fluid steps"
            ),
            "{w}"
        );
        assert_eq!(long("coupling.fluid_substeps=4").fluid_steps_per_pass(dt), 3);
        assert!(gate(&[]).fluid_substeps_warning(dt).is_none());
        assert!(long("coupling.fluid_substeps=1").fluid_substeps_warning(dt).is_none());
        assert!(gate(&["fluid.solver=\"isph\"", "coupling.max_dt=2.5e-4"])
            .fluid_substeps_warning(dt)
            .is_none());
        assert!(gate(&["fluid.spacing=0.002"])
            .fluid_substeps_warning(dt / 2.0)
            .is_none());
        // The coupling step's length in FE steps: with ISPH only, from 32 FE steps, and naming 24 of them.
        // Without the bound from the structure's speed, which the default sets (`coupling.structure_courant`).
        let isph = gate(&["fluid.solver=\"isph\"", "coupling.structure_courant=0"]);
        let w = isph.long_coupling_step_warning(6.3e-4, 4.16e-6, 151).unwrap();
        assert!(
            w.contains("spans 151 FE steps")
                && w.contains("coupling.max_dt = 1e-4")
                && w.contains("coupling.structure_courant = 0.05"),
            "{w}"
        );
        assert!(
            w.contains("or damp the structure's ringing (solid[0].mesh_damping = 0.02"),
            "{w}"
        );
        let free = gate(&[
            "fluid.solver=\"isph\"",
            "coupling.structure_courant=0",
            "solid[0].fixed=[]",
        ]);
        let w = free.long_coupling_step_warning(6.3e-4, 4.16e-6, 151).unwrap();
        assert!(
            !w.contains("mesh_damping") && w.contains("coupling.max_dt = 1e-4, or bound"),
            "{w}"
        );
        assert!(gate(&["fluid.solver=\"isph\""])
            .long_coupling_step_warning(6.3e-4, 4.16e-6, 151)
            .is_none());
        let pp = gate(&["fluid.solver=\"isph\"", "contact.algorithm=\"particle_particle\""]);
        let w = pp.long_coupling_step_warning(6.3e-4, 4.16e-6, 151).unwrap();
        assert!(!w.contains("structure_courant"), "{w}");
        assert!(isph.long_coupling_step_warning(1e-4, 4.16e-6, 25).is_none());
        assert!(scene.long_coupling_step_warning(6.3e-4, 4.16e-6, 151).is_none());
    }
}
