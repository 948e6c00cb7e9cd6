//! A blow-up is a typed `SphError::Unstable` naming the step and particle, never a panic.

mod common;

use sph_node::{SphError, WcsphSolver};

#[test]
fn oversized_step_reports_unstable() {
    let scene = common::still_water(0.2, 0.2, 0.02, "");
    let mut solver = WcsphSolver::new(&scene).expect("solver");
    let dt = 200.0 * solver.stable_dt();
    let err = (0..100)
        .find_map(|_| solver.step(dt).err())
        .expect("a 200× step must blow up");
    match err {
        SphError::Unstable { step, particle, .. } => {
            assert!(step >= 1 && particle < solver.state().len());
        }
        other => panic!("expected Unstable, got {other}"),
    }
    assert!(matches!(solver.step(-1.0), Err(SphError::InvalidParameter { .. })));
}
