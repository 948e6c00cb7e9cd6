//! A run that could never end is refused before it starts. Every step of a run costs at least microseconds, so a
//! scene whose numbers need more than [`MAX_STEPS`] steps — a `coupling.max_dt` of 1e-300, a viscosity of 1e40
//! m²/s that holds the fluid's step to 8e-47 s — would hold its processes busy for longer than any machine runs;
//! `cosim check`, `cosim run` and `contact-broker` say so with the key, as bad input (exit 2). Counted from what
//! bounds a step whatever the motion (`coupling.max_dt`; the fluid's acoustic and viscous conditions,
//! `sph_node::time_step::longest`; each structure's explicit step), so a run refused here could not have been shorter. What the motion does later
//! (a fluid blowing up, its step collapsing) the nodes catch themselves: neither sub-cycles more than 2^32 steps
//! within one coupling step.

use cosim_proto::scene::{Scene, SolidSpec};
use cosim_proto::sizing::count;
use cosim_proto::Num;

/// The most steps of one kind a run may need: at 1 µs a step, 12 days.
pub const MAX_STEPS: f64 = 1e12;

/// More steps than a run may take (or a count that is not a number).
fn too_many(steps: f64) -> bool {
    steps.is_nan() || steps > MAX_STEPS
}

/// `Err((key, what))` where `scene` needs more than [`MAX_STEPS`] coupling or fluid steps.
pub fn refuse_endless(scene: &Scene) -> Result<(), (String, String)> {
    let end = scene.run.end_time;
    let coupling = end / scene.coupling.max_dt;
    if too_many(coupling) {
        return Err((
            "coupling.max_dt".into(),
            format!(
                "{} s: the {} s of run.end_time take at least {} coupling steps, more than the {MAX_STEPS:e} a run \
                 may take",
                Num(scene.coupling.max_dt),
                Num(end),
                count(coupling)
            ),
        ));
    }
    for (s, solid) in scene.solids.iter().enumerate() {
        structure(s, solid, scene.coupling.fem_cfl, end)?;
    }
    let Some(fluid) = &scene.fluid else {
        return Ok(());
    };
    let Some((dt, key)) = sph_node::time_step::longest(fluid, scene.run.gravity) else {
        return Ok(());
    };
    let steps = end / dt;
    if too_many(steps) {
        let wcsph = fluid.solver == cosim_proto::scene::FluidSolver::Wcsph;
        // Both WCSPH conditions are `fluid.cfl` times the physics' bound: a run that would fit at cfl = 1 is held
        // back by the factor, not by the fluid.
        let (key, value, condition) = match key {
            _ if wcsph && !too_many(steps * fluid.cfl) => ("fluid.cfl", Num(fluid.cfl).to_string(), "a factor"),
            "fluid.kinematic_viscosity" => (key, format!("{} m²/s", Num(fluid.kinematic_viscosity)), "0.125 h²/ν"),
            // c0 defaults to 10 √(2 g H): then gravity sets it.
            _ => match fluid.sound_speed {
                Some(c) => (key, format!("{} m/s", Num(c)), "0.25 h/c0"),
                None => (
                    "run.gravity",
                    format!("{:?} m/s² (through c0's default, 10 √(2 g H))", scene.run.gravity),
                    "0.25 h/c0",
                ),
            },
        };
        return Err((
            key.into(),
            format!(
                "{value} holds the fluid's step to at most {dt:.3e} s ({condition}, h = {:.3e} m): the {} s of \
                 run.end_time take at least {} fluid steps, more than the {MAX_STEPS:e} a run may take",
                fluid.smoothing_ratio * fluid.spacing,
                Num(end),
                count(steps)
            ),
        ));
    }
    Ok(())
}

/// `Err` where solid `s` needs more than [`MAX_STEPS`] steps: its explicit step is at most `fem_cfl` L / c_d over
/// its undeformed cells (L: a cell's area over its diagonal, the length `fem_node::solver::stable_dt` takes for quads
/// and for the triangles that halve them; c_d = √((λ + 2μ)/ρ)) and `fem_cfl` / c with mass-proportional damping c.
/// The key named is the one the bound comes from: the damping, `coupling.fem_cfl` where the step at fem_cfl = 0.9
/// would fit, else the material.
fn structure(s: usize, solid: &SolidSpec, fem_cfl: f64, end: f64) -> Result<(), (String, String)> {
    let m = &solid.material;
    let (e, nu) = (m.youngs_modulus, m.poisson_ratio);
    let p_wave = e * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let c_d = (p_wave / m.density).sqrt();
    let [dx, dy] = [0, 1].map(|k| (solid.max[k] - solid.min[k]) / f64::from(solid.divisions[k]));
    let length = dx * dy / dx.hypot(dy);
    let elastic = length / c_d;
    let damped = match solid.damping > 0.0 {
        true => 1.0 / solid.damping,
        false => f64::INFINITY,
    };
    let steps = end / (fem_cfl * elastic.min(damped));
    if !too_many(steps) {
        return Ok(());
    }
    let why = |key: String, what: String, dt: f64| {
        let text = format!(
            "{what} holds the structure's step to at most {dt:.3e} s: the {} s of run.end_time take at least {} \
             structure steps, more than the {MAX_STEPS:e} a run may take",
            Num(end),
            count(steps)
        );
        Err((key, text))
    };
    let dt = fem_cfl * elastic.min(damped);
    if damped < elastic {
        let what = format!("{} 1/s (a step of at most coupling.fem_cfl / c)", Num(solid.damping));
        return why(format!("solid[{s}].damping"), what, dt);
    }
    if !too_many(end / (0.9 * elastic)) {
        return why("coupling.fem_cfl".into(), format!("{}", Num(fem_cfl)), dt);
    }
    let what = format!(
        "E = {} Pa, ρ = {} kg/m³ and ν = {} (a wave speed of {c_d:.3e} m/s across cells {length:.3e} m long)",
        Num(e),
        Num(m.density),
        Num(nu)
    );
    why(format!("solid[{s}].material"), what, dt)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(file: &str, set: &[&str]) -> Scene {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../scenes")
            .join(file);
        let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
        cosim_proto::scene::load(&path, &set).unwrap().scene
    }

    #[test]
    fn a_run_needing_more_than_the_most_steps_is_refused_with_its_key() {
        for file in [
            "csm3.toml",
            "dam_break.toml",
            "elastic_gate.toml",
            "lobovsky_dam_break.toml",
        ] {
            assert_eq!(refuse_endless(&scene(file, &[])), Ok(()), "{file} as shipped");
        }
        let key = |file: &str, set: &[&str]| refuse_endless(&scene(file, set)).unwrap_err().0;
        assert_eq!(key("csm3.toml", &["coupling.max_dt=1e-300"]), "coupling.max_dt");
        // 10 s of csm3: 0.91e12 coupling steps are allowed, 1.11e12 are not.
        assert_eq!(
            refuse_endless(&scene("csm3.toml", &["coupling.max_dt=1.1e-11"])),
            Ok(())
        );
        assert_eq!(key("csm3.toml", &["coupling.max_dt=0.9e-11"]), "coupling.max_dt");
        assert_eq!(
            key("dam_break.toml", &["fluid.kinematic_viscosity=1e40"]),
            "fluid.kinematic_viscosity"
        );
        assert_eq!(key("dam_break.toml", &["fluid.sound_speed=1e40"]), "fluid.sound_speed");
        // c0 defaulted from gravity: gravity is the key.
        assert_eq!(key("dam_break.toml", &["run.gravity=[0.0, -1e40]"]), "run.gravity");
        // A run that would fit at cfl = 1 is held back by the factor: 1000 s of the dam break take 3.1e7 steps at
        // fluid.cfl = 1, 3.1e13 at 1e-6.
        let long = ["run.end_time=1000", "fluid.cfl=1e-6"];
        assert_eq!(key("dam_break.toml", &long), "fluid.cfl");
        let isph = ["fluid.solver=\"isph\"", "fluid.kinematic_viscosity=1e40"];
        assert_eq!(key("dam_break.toml", &isph), "fluid.kinematic_viscosity");
        // An inviscid ISPH fluid's step follows its speed: nothing bounds it from the scene.
        let inviscid = [
            "fluid.solver=\"isph\"",
            "fluid.kinematic_viscosity=0",
            "fluid.sound_speed=1e40",
        ];
        assert_eq!(refuse_endless(&scene("dam_break.toml", &inviscid)), Ok(()));
        let (_, what) = refuse_endless(&scene("dam_break.toml", &["fluid.kinematic_viscosity=1e40"])).unwrap_err();
        assert!(
            what.starts_with("1e40 m²/s holds the fluid's step to at most 8.450e-47 s"),
            "{what}"
        );
    }

    /// The structure's explicit step, at most `fem_cfl` L / c_d and `fem_cfl` / c: csm3's bar (5 mm cells, c_d =
    /// 54.8 m/s: Δt ≈ 5.8e-5 s) over 100 s takes 1.7e6 steps; the key named is the one the bound comes from.
    #[test]
    fn a_structure_needing_more_than_the_most_steps_is_refused_with_its_key() {
        let key = |set: &[&str]| refuse_endless(&scene("csm3.toml", set)).unwrap_err().0;
        assert_eq!(refuse_endless(&scene("csm3.toml", &["run.end_time=100"])), Ok(()));
        assert_eq!(key(&["run.end_time=100", "coupling.fem_cfl=1e-6"]), "coupling.fem_cfl");
        assert_eq!(key(&["solid[0].damping=1e20"]), "solid[0].damping");
        assert_eq!(key(&["solid[0].material.youngs_modulus=1e40"]), "solid[0].material");
        assert_eq!(key(&["solid[0].material.density=1e-40"]), "solid[0].material");
        let (_, what) = refuse_endless(&scene("csm3.toml", &["solid[0].damping=1e20"])).unwrap_err();
        assert!(
            what.starts_with(
                "1e20 1/s (a step of at most coupling.fem_cfl / c) holds the structure's step to at most 9.000e-21 s"
            ),
            "{what}"
        );
    }
}
