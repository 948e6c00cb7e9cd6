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

/// A stable step that would need more than 2^32 sub-steps in one coupling step (here a viscosity of 1e40 m²/s,
/// 0.125 h²/ν ≈ 8.5e-45 s; scenes take physical values up to 1e50) is a typed error at once, for both solvers, not a coupling step that never ends.
#[test]
fn a_collapsed_step_is_an_error_not_an_endless_subcycle() {
    use cosim_proto::messages::StepCommand;
    use sph_node::core::SphCore;
    for solver in ["wcsph", "isph"] {
        let scene = common::still_water(
            0.2,
            0.2,
            0.02,
            &format!("solver = \"{solver}\"\nkinematic_viscosity = 1e40"),
        );
        let mut core = SphCore::new(&scene).expect("core");
        let command = StepCommand {
            dt: 1e-3,
            corrections: Vec::new(),
            roi: None,
            want_interface: false,
            want_snapshot: false,
            stop: false,
        };
        let started = std::time::Instant::now();
        let err = core.handle(&command).expect_err("no usable step");
        assert!(
            started.elapsed().as_secs_f64() < 10.0,
            "{solver}: the error comes at once"
        );
        match &err {
            SphError::StepCollapsed { step, stable, left } => {
                assert_eq!(*step, 1, "{solver}");
                assert!(*stable < 1e-40 && *left == 1e-3, "{solver}: {err}");
            }
            other => panic!("{solver}: expected StepCollapsed, got {other}"),
        }
        assert!(err.is_unstable(), "{solver}");
    }
}

/// A coupling step of many fluid steps, interrupted: the sub-cycle is left between two of its steps once the
/// interrupt is overdue (`cosim run --in-process` and Ctrl-C), for both solvers; one that never arrives changes
/// nothing.
#[test]
fn an_overdue_interrupt_leaves_the_sub_cycle_between_two_steps() {
    use cosim_bus::interrupt::Interrupt;
    use cosim_proto::messages::StepCommand;
    use sph_node::core::SphCore;
    use std::sync::atomic::AtomicBool;
    use std::sync::Arc;
    for solver in ["wcsph", "isph"] {
        let mut scene = common::still_water(0.2, 0.2, 0.02, &format!("solver = \"{solver}\""));
        scene.coupling.max_dt = 1.0;
        let command = |core: &SphCore| StepCommand {
            dt: 10.5 * core.solver().stable_dt(),
            corrections: Vec::new(),
            roi: None,
            want_interface: false,
            want_snapshot: false,
            stop: false,
        };
        let mut core = SphCore::new(&scene).expect("core");
        let signal = Arc::new(AtomicBool::new(true));
        core.stop_on(Interrupt::from_flag(signal).with_wait(std::time::Duration::ZERO));
        let err = core.handle(&command(&core)).expect_err("stopped");
        match &err {
            SphError::Stopped { done: 1, .. } => assert!(!err.is_unstable(), "{solver}"),
            other => panic!("{solver}: expected Stopped after 1 step, got {other}"),
        }
        assert_eq!(core.solver().state().step, 1, "{solver}");
        let mut core = SphCore::new(&scene).expect("core");
        core.stop_on(Interrupt::from_flag(Arc::new(AtomicBool::new(false))).with_wait(std::time::Duration::ZERO));
        let state = core.handle(&command(&core)).expect("no signal").expect("a state");
        assert!(state.substeps >= 11, "{solver}: {}", state.substeps);
    }
}
