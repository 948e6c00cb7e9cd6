//! ISPH under the `particle_particle` contact: the broker applies that contact's repulsive force once per coupling
//! step, explicitly, and the coupling step is the fluid's stable step; the ISPH step is bounded by the WCSPH
//! acoustic step 0.25 h/(c0 + v_max) there (`docs/CORRECTIONS.md`, "ISPH + particle_particle"), and only there.

use cosim_proto::scene::parse;
use sph_node::IsphSolver;

fn gate_solver(contact: &str) -> IsphSolver {
    let text = include_str!("../../scenes/elastic_gate.toml");
    let overrides = ["fluid.solver=isph".to_string(), format!("contact.algorithm={contact}")];
    let scene = parse("elastic_gate.toml", text, &overrides).expect("valid scene");
    IsphSolver::new(&scene).expect("solver")
}

#[test]
fn the_isph_step_resolves_the_particle_particle_force() {
    let pp = gate_solver("particle_particle");
    let pe = gate_solver("particle_element");
    let h = pp.params().h;
    // The gate scene's fluid.sound_speed = 20 m/s; the fluid is at rest: 0.25 h / c0.
    let acoustic = 0.25 * h / 20.0;
    assert!(
        (pp.stable_dt() - acoustic).abs() <= 1e-12 * acoustic,
        "particle_particle: ISPH step {} against the acoustic step {acoustic}",
        pp.stable_dt()
    );
    // particle_element is a projection, not a force: the ISPH step of §4.3 stays, here 3 × longer.
    assert!(
        pe.stable_dt() > 3.0 * acoustic,
        "particle_element: ISPH step {} against the acoustic step {acoustic}",
        pe.stable_dt()
    );
}
