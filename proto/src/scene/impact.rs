//! A WCSPH pressure probe on a side wall: where a user reads wall-impact pressures, say what weakly compressible SPH
//! gives there (issue 16; docs/CORRECTIONS.md "WCSPH at the wall impact").
//!
//! Measured on the Lobovsky et al. 2014 impact (H = 0.3 m): at Δx = H/30 and H/60 the WCSPH sensors read the first
//! impact as an acoustic pulse of 12–15 ρgH against the recorded 3.0 (the water hammer ρ c0 u of the artificial sound
//! speed, over a millisecond), then its rebound to −2 … −9 ρgH and a ringing of the pool (RMS after the impact 0.34
//! ρgH at H/30). δ-SPH at 0.5 takes the ringing within 0.2 ρgH; ISPH reads the incompressible peak (2.8–3.0 ρgH).
//! Neither the floor's probes (the still or slowly varying column over them) nor a probe away from a wall take an
//! impact of that kind, so only a probe in front of a wall's vertical face is named.

use super::schema::{FluidSolver, ProbeKind, Scene};

/// The δ-SPH coefficient the warning recommends: what docs/CORRECTIONS.md measured for wall-impact pressures.
pub const IMPACT_DENSITY_DIFFUSION: f64 = 0.5;

/// How far in front of a wall's vertical face a pressure probe counts as on it, in fluid spacings.
const ON_THE_WALL: f64 = 2.0;

impl Scene {
    /// The names of the pressure probes within [`ON_THE_WALL`] spacings in front of a wall's vertical face (its
    /// height range included), in the scene's order; empty without a fluid.
    pub fn side_wall_pressure_probes(&self) -> Vec<&str> {
        let Some(fluid) = self.fluid.as_ref() else {
            return Vec::new();
        };
        let reach = ON_THE_WALL * fluid.spacing;
        let on_a_side = |p: [f64; 2]| {
            self.walls.iter().any(|w| {
                let beside = (w.min[1]..=w.max[1]).contains(&p[1]);
                let left = p[0] < w.min[0] && w.min[0] - p[0] <= reach;
                let right = p[0] > w.max[0] && p[0] - w.max[0] <= reach;
                beside && (left || right)
            })
        };
        self.probes
            .iter()
            .filter(|p| p.kind == ProbeKind::Pressure)
            .filter(|p| p.point.is_some_and(on_a_side))
            .map(|p| p.name.as_str())
            .collect()
    }

    /// With WCSPH below the recommended δ-SPH, the warning that pressure probes on a side wall will read an impact as
    /// an acoustic pulse; `None` otherwise.
    pub fn wall_impact_pressure_warning(&self) -> Option<String> {
        let fluid = self.fluid.as_ref()?;
        if fluid.solver != FluidSolver::Wcsph || fluid.density_diffusion >= IMPACT_DENSITY_DIFFUSION {
            return None;
        }
        let probes = self.side_wall_pressure_probes();
        if probes.is_empty() {
            return None;
        }
        Some(format!(
            "pressure probe{} {} on a wall: WCSPH reads a wall impact as an acoustic pulse (4 times the recorded \
             peak at 30 and 60 particles over the column's height on the Lobovsky impact), then its rebound below 0 \
             and a ringing (docs/CORRECTIONS.md \"WCSPH at the wall impact\"); fluid.density_diffusion = \
             {IMPACT_DENSITY_DIFFUSION} damps the ringing, fluid.solver = \"isph\" reads the incompressible peak",
            if probes.len() > 1 { "s" } else { "" },
            probes.join(", ")
        ))
    }
}

#[cfg(test)]
mod tests {
    fn scene(sets: &[&str]) -> crate::scene::Scene {
        crate::scene::shipped("lobovsky_dam_break.toml", sets)
    }

    #[test]
    fn the_sensors_on_the_downstream_wall_are_named_with_wcsph_alone() {
        let s = scene(&[]);
        assert_eq!(
            s.side_wall_pressure_probes(),
            ["p_sensor1", "p_sensor2", "p_sensor1_raw", "p_sensor2_raw"]
        );
        let w = s.wall_impact_pressure_warning().expect("WCSPH without δ-SPH");
        assert!(
            w.starts_with("pressure probes p_sensor1, p_sensor2, p_sensor1_raw, p_sensor2_raw on a wall"),
            "{w}"
        );
        assert!(scene(&["fluid.density_diffusion=0.5"])
            .wall_impact_pressure_warning()
            .is_none());
        assert!(scene(&["fluid.solver=isph"]).wall_impact_pressure_warning().is_none());
        // Two spacings from the face is still on it; a probe further out, or on the floor, is not.
        assert_eq!(
            scene(&["probe[0].point=[1.591,0.003]"])
                .side_wall_pressure_probes()
                .len(),
            4
        );
        assert_eq!(
            scene(&["probe[0].point=[1.589,0.003]"])
                .side_wall_pressure_probes()
                .len(),
            3
        );
        assert_eq!(
            scene(&["probe[0].point=[0.8,0.003]"]).side_wall_pressure_probes().len(),
            3
        );
    }
}
