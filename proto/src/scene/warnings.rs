//! What `cosim check` and `cosim run` warn of before a run, from the scene alone: one list, so that a warning added
//! here is given by both.

use super::schema::Scene;

impl Scene {
    /// The warnings of the scene whose fluid takes `dt_fluid` as its first stable step (infinite without a fluid):
    /// a mesh much finer than the fluid ([`Scene::heavy_particle_warnings`]), the fluid sub-cycled against a fine
    /// mesh ([`Scene::fluid_substeps_warning`]), WCSPH pressure probes on a wall
    /// ([`Scene::wall_impact_pressure_warning`]) and solids held nowhere ([`Scene::unheld_solid_warnings`]), in that
    /// order.
    pub fn warnings(&self, dt_fluid: f64) -> Vec<String> {
        let mut warnings = self.heavy_particle_warnings();
        warnings.extend(self.fluid_substeps_warning(dt_fluid));
        warnings.extend(self.wall_impact_pressure_warning());
        warnings.extend(self.unheld_solid_warnings());
        warnings
    }
}
