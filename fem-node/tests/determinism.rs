//! Element forces are computed in parallel but assembled in element order: the state after N steps is
//! bit-identical for any thread count, and a solver resumed from a copy of the state continues bit-identically.

mod common;

use common::*;
use cosim_proto::scene::{ElementKind, MaterialModel};
use fem_node::{FemModel, FemSolver, FemState};

/// Two solids: a quad bar (neo-Hookean) and a triangle bar (St. Venant–Kirchhoff), swinging under gravity.
fn model() -> FemModel {
    let quads = cantilever(
        [0.0, 0.4],
        [0.0, 0.02],
        [80, 4],
        ElementKind::Quad4,
        material(MaterialModel::NeoHookean, 1000.0, 1.4e6, 0.4),
    );
    let mut tris = cantilever(
        [0.0, 0.3],
        [0.1, 0.12],
        [60, 4],
        ElementKind::Tri3,
        material(MaterialModel::StVenantKirchhoff, 1100.0, 2.0e6, 0.3),
    );
    tris.name = "tris".into();
    FemModel::from_solids(&[quads, tris], [0.0, -9.81]).unwrap()
}

fn run(threads: usize, parallel_min_elements: usize, steps: u32) -> FemState {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| {
        let mut s = FemSolver::new(model(), 0.9).unwrap();
        s.set_parallel_min_elements(parallel_min_elements);
        s.set_velocities(|_, p| [0.1 * p[1], 3.0 * p[0]]);
        let dt = s.stable_dt();
        for _ in 0..steps {
            s.substep(dt).unwrap();
        }
        s.state().clone()
    })
}

fn bits(s: &FemState) -> Vec<u64> {
    let mut out = vec![s.t.to_bits(), s.step];
    for field in [&s.x, &s.v, &s.a] {
        out.extend(field.iter().flatten().map(|v| v.to_bits()));
    }
    out
}

#[test]
fn one_and_two_threads_give_identical_bits() {
    let steps = 2000;
    let one = run(1, 0, steps);
    let two = run(2, 0, steps);
    let serial = run(2, usize::MAX, steps);
    assert!(
        one.x
            .iter()
            .zip(&FemModel::reference(&model()).to_vec())
            .any(|(a, b)| a != b),
        "nothing moved"
    );
    assert_eq!(bits(&one), bits(&two), "1 vs 2 threads");
    assert_eq!(bits(&one), bits(&serial), "parallel vs serial element loop");
}

#[test]
fn resumed_state_continues_bit_identically() {
    let mut a = FemSolver::new(model(), 0.9).unwrap();
    a.set_velocities(|_, p| [0.0, 2.0 * p[0]]);
    a.advance(0.01).unwrap();
    let copy = a.state().clone();
    let mut b = FemSolver::with_state(model(), copy, 0.9).unwrap();
    a.advance(0.02).unwrap();
    b.advance(0.02).unwrap();
    assert_eq!(bits(a.state()), bits(b.state()));
}
