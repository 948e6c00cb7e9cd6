//! A run that could never end is refused before it starts. Every step of a run costs at least microseconds, so a
//! scene whose numbers need more than [`MAX_STEPS`] steps — a `coupling.max_dt` of 1e-300, a viscosity of 1e300
//! m²/s that holds the fluid's step to 1e-307 s — would hold its processes busy for longer than any machine runs;
//! `cosim check`, `cosim run` and `contact-broker` say so with the key, as bad input (exit 2). Counted from what
//! bounds a step whatever the motion (`coupling.max_dt`; the fluid's acoustic and viscous conditions,
//! `sph_node::time_step::longest`), so a run refused here could not have been shorter. What the motion does later
//! (a fluid blowing up, its step collapsing) the nodes catch themselves: neither sub-cycles more than 2^32 steps
//! within one coupling step.

use cosim_proto::scene::Scene;
use cosim_proto::sizing::count;
use cosim_proto::Num;

/// The most steps of one kind a run may need: at 1 µs a step, 12 days.
pub const MAX_STEPS: f64 = 1e12;

/// `Err((key, what))` where `scene` needs more than [`MAX_STEPS`] coupling or fluid steps.
pub fn refuse_endless(scene: &Scene) -> Result<(), (String, String)> {
    let end = scene.run.end_time;
    let too_many = |n: f64| n.is_nan() || n > MAX_STEPS;
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
    let Some(fluid) = &scene.fluid else {
        return Ok(());
    };
    let Some((dt, key)) = sph_node::time_step::longest(fluid, scene.run.gravity) else {
        return Ok(());
    };
    let steps = end / dt;
    if too_many(steps) {
        let (value, condition) = match key {
            "fluid.kinematic_viscosity" => (format!("{} m²/s", Num(fluid.kinematic_viscosity)), "0.125 h²/ν"),
            _ => (
                fluid
                    .sound_speed
                    .map_or("its default".into(), |c| format!("{} m/s", Num(c))),
                "0.25 h/c0",
            ),
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
            key("dam_break.toml", &["fluid.kinematic_viscosity=1e300"]),
            "fluid.kinematic_viscosity"
        );
        assert_eq!(key("dam_break.toml", &["fluid.sound_speed=1e300"]), "fluid.sound_speed");
        let isph = ["fluid.solver=\"isph\"", "fluid.kinematic_viscosity=1e300"];
        assert_eq!(key("dam_break.toml", &isph), "fluid.kinematic_viscosity");
        // An inviscid ISPH fluid's step follows its speed: nothing bounds it from the scene.
        let inviscid = [
            "fluid.solver=\"isph\"",
            "fluid.kinematic_viscosity=0",
            "fluid.sound_speed=1e300",
        ];
        assert_eq!(refuse_endless(&scene("dam_break.toml", &inviscid)), Ok(()));
        let (_, what) = refuse_endless(&scene("dam_break.toml", &["fluid.kinematic_viscosity=1e300"])).unwrap_err();
        assert!(
            what.starts_with("1e300 m²/s holds the fluid's step to at most 8.450e-307 s"),
            "{what}"
        );
    }
}
