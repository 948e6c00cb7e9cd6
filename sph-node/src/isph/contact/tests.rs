//! Unit tests of the contact layer: what it records from the corrections, what it gives back, and how it is checked
//! after a restart.

use super::*;

/// Two particles at rest, `dx` apart on the x axis, at t = 0.
fn row_of_two(dx: f64) -> FluidState {
    FluidState {
        x: vec![[0.0, 0.0], [dx, 0.0]],
        v: vec![[0.0; 2]; 2],
        rho: vec![1000.0; 2],
        p: vec![0.0; 2],
        m: vec![0.1; 2],
        ..FluidState::default()
    }
}

/// A layer read back from a checkpoint: its records are one per particle or none, its end the state's.
#[test]
fn a_restored_layer_is_checked_against_its_state() {
    let state = row_of_two(0.01);
    let mut layer = ContactLayer::default();
    layer.record_end(&state);
    assert_eq!(layer.check(&state), Ok(()));
    let mut moved = state.clone();
    moved.v[1] = [0.0, -0.1];
    layer.detect(&moved, 0.01);
    layer.record_end(&moved);
    assert_eq!(layer.check(&moved), Ok(()), "records made by a correction");
    let mut short = layer.clone();
    short.face.pop();
    assert_eq!(
        short.check(&moved),
        Err("contact.face holds 1 records (contact.age 2), there are 2 fluid particles".into())
    );
    let mut bad = layer.clone();
    bad.time[0] = f64::NAN;
    assert_eq!(
        bad.check(&moved),
        Err("contact.time[0] = NaN is not finite within ±1e50".into())
    );
    assert_eq!(
        layer.check(&state),
        Err("contact.v_end[1] = [0.0, -0.1] where state.v has [0.0, 0.0]".into())
    );
}

/// A face the broker sent with a `particle_particle` correction stands in for the one the correction would
/// reveal (the velocity change's direction), still (velocity 0), and only for the step that follows it.
#[test]
fn a_given_face_replaces_the_inferred_one_for_one_step() {
    let dx = 0.01;
    let mut state = row_of_two(dx);
    let mut layer = ContactLayer::default();
    layer.record_end(&state);
    // The force turned particle 1's velocity by (0.02, 0.1); the structure's face lies 0.3 Δx below it.
    state.v[1] = [0.02, 0.1];
    state.t = 1e-3;
    let given = ContactFace {
        point: [dx, -0.3 * dx],
        normal: [0.0, 1.0],
    };
    layer.give(&[(1, given)]);
    layer.detect(&state, dx);
    let face = layer.face(1).expect("particle 1 against the given face");
    assert_eq!((face.normal, face.velocity), ([0.0, 1.0], 0.0));
    assert!((face.distance(state.x[1]) - 0.3 * dx).abs() < 1e-15, "{face:?}");
    assert!(layer.face(0).is_none());
    // The next correction comes without a face: it is read from the correction again, along (1, 0).
    layer.record_end(&state);
    state.v[1][0] += 0.1;
    state.t = 2e-3;
    layer.detect(&state, dx);
    assert_eq!(layer.face(1).expect("inferred").normal, [1.0, 0.0]);
}

#[test]
fn half_space_of_the_default_kernel() {
    let dx = 0.01;
    let kernel = CubicSpline::new(1.3 * dx);
    let (div_r, w_sum) = half_space(&kernel, dx, 0.5 * dx);
    // Full lattice: ∇·r = 2.02, Shepard sum 1.0; first layer of a half lattice: 1.28 and 0.76.
    assert!((div_r - 0.743).abs() < 0.01, "{div_r}");
    assert!((w_sum - 0.237).abs() < 0.01, "{w_sum}");
    let (far, _) = half_space(&kernel, dx, 2.0 * dx);
    assert!(far < 0.01 && far < div_r, "{far}");
}

#[test]
fn a_layer_never_corrected_holds_no_records_and_the_first_correction_makes_them() {
    let dx = 0.01;
    let mut state = FluidState {
        t: 0.0,
        step: 0,
        x: vec![[0.0, 0.0], [dx, 0.0], [2.0 * dx, 0.0]],
        v: vec![[0.0; 2]; 3],
        rho: vec![1000.0; 3],
        p: vec![0.0; 3],
        m: vec![0.1; 3],
    };
    let mut layer = ContactLayer::default();
    for _ in 0..3 {
        layer.detect(&state, dx);
        layer.record_end(&state);
        state.t += 1e-3;
    }
    assert!(!layer.any() && layer.face(1).is_none() && layer.corrected() == 0);
    assert_eq!(
        layer.age.len() + layer.face.len() + layer.flags.len(),
        0,
        "records held before any correction"
    );
    // The contact puts particle 1 back along +y by 1e-4 m: it is against a face with normal +y, Δx/2 below it.
    state.x[1][1] += 1e-4;
    layer.detect(&state, dx);
    assert_eq!((layer.corrected(), layer.age.len()), (1, 3));
    let face = layer.face(1).expect("particle 1 against a face");
    assert_eq!(face.normal, [0.0, 1.0]);
    assert!(
        (face.distance(state.x[1]) - 0.5 * dx).abs() < 1e-15,
        "{}",
        face.distance(state.x[1])
    );
    assert!(layer.face(0).is_none() && layer.face(2).is_none());
}
