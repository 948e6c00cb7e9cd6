//! The scene's memory estimate (`cosim_proto::sizing`: what `cosim check` prints, and what `run` and each node
//! refuse a scene above the machine's memory by) covers what the WCSPH solver holds by its own count
//! (`WcsphSolver::heap_bytes`: particle arrays, sorted copies, neighbour and Verlet candidate lists, scratch). The
//! estimate's constants are calibrated on the measured peak RSS of a run (docs/PERFORMANCE.md, "Scene sizing"), which
//! holds more than the solver's arrays; a solver that grew past its estimate would let a run start that does not fit.
//! Both are compared as the growth from 5,000 to 20,000 fluid particles, so that the fixed part of a process
//! (program, libraries, thread pool) drops out.

mod common;

use cosim_proto::sizing::{Part, Sizing};
use sph_node::WcsphSolver;

/// The estimated sph-node bytes of the dam break at `dx` and what the solver holds after two steps.
fn estimate_and_held(dx: f64) -> (f64, f64, usize) {
    let scene = common::dam_break(0.1, 0.6, dx, "");
    let mut solver = WcsphSolver::new(&scene).expect("solver");
    for _ in 0..2 {
        let dt = solver.stable_dt();
        solver.step(dt).expect("step");
    }
    let estimate = Sizing::of(&scene).bytes(Part::Fluid);
    (estimate, solver.heap_bytes() as f64, solver.state().len())
}

#[test]
fn the_sizing_estimate_covers_what_the_wcsph_solver_holds() {
    let (e1, h1, n1) = estimate_and_held(0.002);
    let (e2, h2, n2) = estimate_and_held(0.001);
    assert_eq!((n1, n2), (5_000, 20_000));
    let per = |b: f64| b / (n2 - n1) as f64;
    let (estimate, held) = (per(e2 - e1), per(h2 - h1));
    println!("per added fluid particle: estimate {estimate:.0} B, solver's arrays {held:.0} B");
    // The estimate is of the peak RSS, which holds the solver's arrays and more (the state messages, the allocator's
    // free memory): never less than the arrays; and good to some tens of per cent, so not above twice them.
    assert!(
        estimate >= held,
        "estimate {estimate:.0} B < held {held:.0} B a fluid particle"
    );
    assert!(
        estimate <= 2.0 * held,
        "estimate {estimate:.0} B > 2 × held {held:.0} B a fluid particle"
    );
}
