//! ISPH: the state (and the wall pressures) after N steps are bit-identical with 1 and 2 rayon threads (every
//! loop is a fixed-order gather; BiCGSTAB sums its dot products in fixed chunks).

mod common;

use sph_node::{FluidState, IsphSolver};

fn run(threads: usize) -> (FluidState, Vec<f64>) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("pool");
    pool.install(|| {
        let scene = common::dam_break(0.05, 0.2, 0.005, "solver = \"isph\"\nkinematic_viscosity = 1.0e-6");
        let mut solver = IsphSolver::new(&scene).expect("solver");
        for _ in 0..60 {
            let dt = solver.stable_dt();
            solver.step(dt).expect("stable");
        }
        (solver.state().clone(), solver.walls().p.clone())
    })
}

fn bits(s: &FluidState, wall_p: &[f64]) -> Vec<u64> {
    let mut out = vec![s.t.to_bits(), s.step];
    for i in 0..s.len() {
        out.extend([s.x[i][0], s.x[i][1], s.v[i][0], s.v[i][1], s.rho[i], s.p[i], s.m[i]].map(f64::to_bits));
    }
    out.extend(wall_p.iter().map(|p| p.to_bits()));
    out
}

#[test]
fn isph_one_and_two_threads_agree_bitwise() {
    let (a, wa) = run(1);
    let (b, wb) = run(2);
    assert!(
        a.v.iter().any(|v| v[0].abs() > 1e-3),
        "the column must have started to move"
    );
    assert_eq!(bits(&a, &wa), bits(&b, &wb));
}
