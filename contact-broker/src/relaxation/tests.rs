use super::*;

/// The shipped gate's repulsive force: D = 5 g H (H = 0.14 m), r0 = Δx/2 = 1 mm.
fn force() -> ParticleParticleParams {
    ParticleParticleParams {
        r0: 0.001,
        ..ParticleParticleParams::monaghan(0.002, 9.81, 0.14)
    }
}

/// Relaxation by at most `omega` a step and, with `lag` > 0, at most Δt/`lag`.
fn relaxation(omega: f64, lag: f64) -> Relaxation {
    Relaxation::new(RelaxationChoice {
        omega,
        lag,
        reason: String::new(),
    })
}

/// The shipped gate with `overrides`.
fn gate(overrides: &[&str]) -> Scene {
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/elastic_gate.toml");
    let text = std::fs::read_to_string(file).unwrap();
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    cosim_proto::scene::parse(file, &text, &overrides).unwrap()
}

#[test]
fn omega_is_one_unless_isph_with_particle_particle_or_asked() {
    let off = |s: &Scene| {
        let c = choose(s, &force());
        (c.omega, c.lag)
    };
    assert_eq!(off(&gate(&[])), (1.0, 0.0));
    assert_eq!(off(&gate(&["contact.algorithm=particle_particle"])), (1.0, 0.0));
    assert_eq!(off(&gate(&["fluid.solver=isph"])), (1.0, 0.0));
    let asked = gate(&[
        "contact.algorithm=particle_particle",
        "contact.reaction_relaxation=0.25",
    ]);
    assert_eq!(off(&asked), (0.25, 0.0));
    // The gate: water 0.14 m deep, rubber 1100 kg/m³ 5 mm thick: r = 1000 × 0.14 / (1100 × 0.005); the force's
    // frequency Ω_c = √(D (12 − 4)) / r0.
    let auto = choose(
        &gate(&["contact.algorithm=particle_particle", "fluid.solver=isph"]),
        &force(),
    );
    let r = 1000.0 * 0.14 / (1100.0 * 0.005);
    assert!((auto.omega - 1.0 / (1.0 + r)).abs() < 1e-12, "{auto:?}");
    let omega_c = (5.0 * 9.81 * 0.14 * 8.0f64).sqrt() / 0.001;
    assert!((auto.lag - LAG_PERIODS / omega_c).abs() < 1e-15, "{auto:?}");
    assert!(auto.reason.contains("`gate`"), "{auto:?}");
}

#[test]
fn omega_one_gives_every_impulse_at_once() {
    let mut relax = relaxation(1.0, 0.0);
    assert!(!relax.active());
    let mut j = vec![[1.0, -2.0], [3.0, 0.5]];
    let change = relax.give(&mut j, &[false, false], 1e-4);
    assert_eq!(j, vec![[1.0, -2.0], [3.0, 0.5]]);
    assert_eq!(change, vec![[0.0; 2]; 2]);
    assert!(relax.owed().is_empty());
}

/// What the structure receives plus what it is still owed is what the passes gave it, to round-off, over many
/// steps; a fixed node receives its reaction at once.
#[test]
fn impulse_given_plus_owed_is_the_impulse_of_the_passes() {
    let mut relax = relaxation(0.07, 0.0);
    let (mut passes, mut given) = ([[0.0f64; 2]; 3], [[0.0f64; 2]; 3]);
    let mut scale = 0.0f64;
    for n in 0..500 {
        let x = n as f64;
        let mut j = vec![
            [(0.37 * x).sin(), (1.3 * x).cos() - 0.2],
            [0.1 * (0.05 * x).sin(), -1.0],
            [2.0, 1.0],
        ];
        let before = j.clone();
        let change = relax.give(&mut j, &[false, false, true], 1e-4);
        for k in 0..3 {
            for d in 0..2 {
                passes[k][d] += before[k][d];
                given[k][d] += j[k][d];
                scale = scale.max(before[k][d].abs());
                assert_eq!(change[k][d], j[k][d] - before[k][d]);
            }
        }
        assert_eq!(j[2], before[2], "fixed node at step {n}");
    }
    for k in 0..3 {
        for d in 0..2 {
            let err = passes[k][d] - given[k][d] - relax.owed()[k][d];
            assert!(err.abs() <= 1e-12 * 500.0 * scale, "node {k}: {err:e}");
        }
    }
    assert_eq!(relax.owed()[2], [0.0; 2]);
    assert!(relax.owed()[1][1] < -1.0, "{:?}", relax.owed());
}

/// The added-mass model of the module's doc: the pass answers the structure's velocity change of the step before
/// with the added mass r times its own, J^n = −r m Δv^{n−1}. Given at once it grows by r a step; relaxed, it
/// decays for ω < 2/(1 + r), is gone after one step at ω = 1/(1 + r), and grows above the bound. The first Δv is
/// taken as one the relaxation gave, with the (1 − ω)/ω m Δv still owed that goes with it.
#[test]
fn relaxation_stabilises_the_added_mass_model_below_its_bound() {
    let (m, r) = (0.5, 14.0);
    let run = |omega: f64, steps: usize| {
        let mut relax = relaxation(omega, 0.0);
        let mut dv = 1.0f64;
        relax.restore(&[[(1.0 - omega) / omega * m * dv, 0.0]], 1).unwrap();
        for _ in 0..steps {
            let mut j = vec![[-r * m * dv, 0.0]];
            relax.give(&mut j, &[false], 1e-4);
            dv = j[0][0] / m;
        }
        dv.abs()
    };
    assert!(run(1.0, 10) > 1e11);
    assert!(run(1.0 / (1.0 + r), 1) < 1e-15);
    assert!(run(2.2 / (1.0 + r), 200) > 1e6);
    assert!(run(1.8 / (1.0 + r), 200) < 1e-6);
}

#[test]
fn restore_takes_nothing_or_one_impulse_per_node() {
    let mut relax = relaxation(0.5, 0.0);
    relax.restore(&[], 3).unwrap();
    relax.restore(&[[1.0, 2.0]; 3], 3).unwrap();
    assert_eq!(relax.owed(), &[[1.0, 2.0]; 3]);
    let err = relax.restore(&[[1.0, 2.0]; 2], 3).unwrap_err().to_string();
    assert!(err.contains("2 nodes") && err.contains("has 3"), "{err}");
}

/// With a lag τ, a step of length Δt gives at most Δt/τ of what is owed, and never more than the cap.
#[test]
fn a_lag_bounds_omega_by_the_step() {
    let relax = relaxation(0.1, 1e-3);
    assert!(relax.active());
    assert_eq!(relax.omega(2e-5), 2e-5 / 1e-3);
    assert_eq!(relax.omega(5e-4), 0.1);
    let mut relax = relaxation(1.0, 1e-3);
    let mut j = vec![[1.0, 0.0]];
    relax.give(&mut j, &[false], 1e-4);
    assert_eq!(j[0][0], 1e-4 / 1e-3);
}
