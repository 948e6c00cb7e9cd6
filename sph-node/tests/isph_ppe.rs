//! The ISPH pressure Poisson equation converges below its tolerance, and a forced non-convergence (one BiCGSTAB
//! iteration allowed) is a typed `SphError::PpeNotConverged` naming the step and the residual.

mod common;

use sph_node::isph::IsphOptions;
use sph_node::{IsphSolver, PpeSource, SphError};

#[test]
fn ppe_converges_for_both_sources() {
    for source in [PpeSource::DivergenceFree, PpeSource::DensityInvariant] {
        let scene = common::still_water(0.2, 0.2, 0.02, "solver = \"isph\"");
        let mut solver = IsphSolver::with_source(&scene, source).expect("solver");
        let tol = solver.options().tolerance;
        for _ in 0..20 {
            let dt = solver.stable_dt();
            solver.step(dt).expect("converged");
            let ppe = solver.last_ppe();
            assert!(ppe.residual <= tol, "{source:?}: residual {} > {tol}", ppe.residual);
            assert!(ppe.free_surface > 0, "the top row is a free surface");
        }
        eprintln!("{source:?}: last PPE {:?}", solver.last_ppe());
    }
}

#[test]
fn forced_non_convergence_is_a_typed_error() {
    let scene = common::still_water(0.2, 0.2, 0.02, "solver = \"isph\"");
    let options = IsphOptions {
        max_iterations: 1,
        tolerance: 1e-14,
        ..IsphOptions::default()
    };
    let mut solver = IsphSolver::with_options(&scene, options).expect("solver");
    let dt = solver.stable_dt();
    match solver.step(dt) {
        Err(SphError::PpeNotConverged {
            step,
            iterations,
            residual,
        }) => {
            eprintln!("forced: step {step}, {iterations} iterations, residual {residual:e}");
            assert_eq!(step, 1);
            assert_eq!(iterations, 1);
            assert!(residual.is_finite() && residual > 1e-14, "residual {residual}");
        }
        other => panic!("expected PpeNotConverged, got {other:?}"),
    }
}

#[test]
fn a_wcsph_scene_is_rejected() {
    let scene = common::still_water(0.2, 0.2, 0.02, "");
    assert!(matches!(IsphSolver::new(&scene), Err(SphError::InvalidScene { .. })));
}
