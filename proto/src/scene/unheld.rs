//! A solid held nowhere: what a user should know before gravity moves it as a whole.
//!
//! A solid with no `fixed` box is moved by gravity and the water alone, and only the walls (`[[wall]]`) stop it:
//! a node that a step takes into a wall is put back on the wall's surface without friction, its velocity into the
//! wall taken off (`crate::walls`; fem-node within every sub-step, the broker after each contact pass; before
//! 2026-12-07 a solid passed through the walls, and until 2026-12-08 the broker's once-a-step stop made energy as an
//! elastic solid landed). The body itself is elastic: dropped on the floor it bounces, as an undamped elastic body
//! does. Such a body sinks or floats, and the water caught under one that falls is squeezed hard: measured
//! (2026-12-07, a random sweep of coupled scenes), an aluminium-dense block 9 × 4 cm dropped 5 cm beside the shipped
//! gate's column onto the surge along the floor made 15 times the energy the water can release with WCSPH (thrown
//! back up; 9.0 times since 2026-12-08), most of it in the ringing of the mesh's highest modes. Since 2026-12-08
//! (thirty-sixth session) a solid held nowhere is damped at its mesh's scale unless the scene says otherwise
//! (`mesh_damping` [`super::schema::FREE_MESH_DAMPING`] = 0.02): the same block made 0.93 times. What is left is the
//! slam itself: the block reaches the floor with particles under it, which the contact and the walls squeeze between
//! them (not fixed); a shorter `coupling.max_dt` is the lever then. A floating body lighter than the water is a
//! legitimate scene, so this is a warning, not a refusal.

use super::schema::Scene;

impl Scene {
    /// One warning per solid with no `fixed` box under a non-zero gravity, in the scene's order, saying what moves
    /// and stops it and whether it is heavier or lighter than the scene's fluid.
    pub fn unheld_solid_warnings(&self) -> Vec<String> {
        if self.run.gravity == [0.0, 0.0] {
            return Vec::new();
        }
        self.solids
            .iter()
            .enumerate()
            .filter(|(_, s)| s.held_nowhere())
            .map(|(i, s)| {
                let rho_s = s.material.density;
                let fate = match &self.fluid {
                    Some(f) if rho_s > f.density => {
                        format!("heavier than the water ({rho_s} > {} kg/m³), it sinks", f.density)
                    }
                    Some(f) => format!(
                        "lighter than the water ({rho_s} <= {} kg/m³), it floats while the water holds it",
                        f.density
                    ),
                    None => "with no fluid, it falls freely".to_string(),
                };
                let damping = match s.mesh_damping {
                    None => format!(
                        "its mesh is damped at its own scale by default (solid[{i}].mesh_damping = {})",
                        crate::Num(s.mesh_damping())
                    ),
                    Some(z) => format!("solid[{i}].mesh_damping = {}", crate::Num(z)),
                };
                format!(
                    "solid `{}` is held nowhere (no `fixed` box): gravity and the water move it as a whole and only \
                     the walls stop it, without friction (an elastic body, it bounces; {damping}); water caught \
                     under a falling solid is squeezed hard: a shorter coupling.max_dt is the first thing to try if \
                     the run warns of energy made; {fate}",
                    s.name
                )
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    fn gate(sets: &[&str]) -> crate::scene::Scene {
        crate::scene::shipped("elastic_gate.toml", sets)
    }

    #[test]
    fn a_solid_without_a_fixed_box_is_named_with_its_fate() {
        assert!(
            gate(&[]).unheld_solid_warnings().is_empty(),
            "the shipped gate hangs from its wall"
        );
        let heavy = gate(&["solid[0].fixed=[]", "solid[0].material.density=2700.0"]).unheld_solid_warnings();
        assert_eq!(heavy.len(), 1);
        assert!(
            heavy[0].starts_with("solid `gate` is held nowhere (no `fixed` box)"),
            "{}",
            heavy[0]
        );
        assert!(
            heavy[0].contains("(an elastic body, it bounces; its mesh is damped at its own scale by default (solid[0].mesh_damping = 0.02))"),
            "{}",
            heavy[0]
        );
        let undamped = gate(&[
            "solid[0].fixed=[]",
            "solid[0].mesh_damping=0",
            "solid[0].material.density=2700.0",
        ]);
        let undamped = undamped.unheld_solid_warnings();
        assert!(
            undamped[0].contains("(an elastic body, it bounces; solid[0].mesh_damping = 0)"),
            "{}",
            undamped[0]
        );
        assert!(
            heavy[0].ends_with("heavier than the water (2700 > 1000 kg/m³), it sinks"),
            "{}",
            heavy[0]
        );
        let light = gate(&["solid[0].fixed=[]", "solid[0].material.density=500.0"]).unheld_solid_warnings();
        assert!(light[0].ends_with("lighter than the water (500 <= 1000 kg/m³), it floats while the water holds it"));
        // Without gravity nothing moves it as a whole.
        assert!(gate(&["solid[0].fixed=[]", "run.gravity=[0.0,0.0]"])
            .unheld_solid_warnings()
            .is_empty());
    }
}
