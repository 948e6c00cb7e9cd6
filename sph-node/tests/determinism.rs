//! The state after N steps is bit-identical with 1 and 2 rayon threads (every loop is a fixed-order gather).

mod common;

use sph_node::{FluidState, WcsphSolver};

fn run(threads: usize) -> FluidState {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("pool");
    pool.install(|| {
        let scene = common::dam_break(0.05, 0.2, 0.005, "kinematic_viscosity = 1.0e-6");
        let mut solver = WcsphSolver::new(&scene).expect("solver");
        for _ in 0..300 {
            let dt = solver.stable_dt();
            solver.step(dt).expect("stable");
        }
        solver.state().clone()
    })
}

fn bits(s: &FluidState) -> Vec<u64> {
    let mut out = vec![s.t.to_bits(), s.step];
    for i in 0..s.len() {
        out.extend([s.x[i][0], s.x[i][1], s.v[i][0], s.v[i][1], s.rho[i], s.p[i], s.m[i]].map(f64::to_bits));
    }
    out
}

#[test]
fn one_and_two_threads_agree_bitwise() {
    let a = run(1);
    let b = run(2);
    assert!(
        a.v.iter().any(|v| v[0].abs() > 1e-3),
        "the column must have started to move"
    );
    assert_eq!(bits(&a), bits(&b));
}
