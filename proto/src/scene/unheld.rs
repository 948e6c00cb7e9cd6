//! A solid held nowhere: what a user should know before gravity moves it as a whole.
//!
//! The walls (`[[wall]]`) are the fluid's boundary particles; the structure node knows nothing of them. A solid with
//! no `fixed` box is moved by gravity and the water alone, and where it reaches a wall it passes through it, the
//! water caught between the two squeezed without bound. Measured (2026-12-07, a random sweep of coupled scenes): a
//! free aluminium-dense block 9 × 4 cm dropped beside the shipped gate's column fell 5 cm through the air onto the
//! surge along the floor and drove it into the floor's particles, the fluid gaining 1.8 times the energy the water
//! can release before the fluid node stopped the run (`unstable`) at t = 0.1 s. A floating body lighter than the
//! water is a legitimate scene, so this is a warning, not a refusal.

use super::schema::Scene;

impl Scene {
    /// One warning per solid with no `fixed` box under a non-zero gravity, in the scene's order, saying that the
    /// walls do not hold it and whether it is heavier or lighter than the scene's fluid.
    pub fn unheld_solid_warnings(&self) -> Vec<String> {
        if self.run.gravity == [0.0, 0.0] {
            return Vec::new();
        }
        self.solids
            .iter()
            .filter(|s| s.fixed.is_empty())
            .map(|s| {
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
                format!(
                    "solid `{}` is held nowhere (no `fixed` box): gravity and the water move it as a whole, and the \
                     walls act on the fluid only, so where it reaches a wall it passes through it, the water between \
                     them squeezed without bound; {fate}",
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
