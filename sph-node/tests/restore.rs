//! A fluid node's checkpoint read back (`docs/PROTOCOL.md` §9): its own bytes are taken, for both solvers; a state
//! that decodes but does not hold together (as another tool could write it, with a checksum to match) is refused
//! with one line naming the field, and the core keeps the scene's state. The solvers' own checks, field by field,
//! are unit tests (`src/solver/restore.rs`, `src/isph/solver/restore.rs`).

mod common;

use common::dam_break;
use cosim_proto::messages::StepCommand;
use cosim_proto::scene::Scene;
use sph_node::core::{Fluid, SphCore};
use sph_node::stability::EnergyGuard;

type Saved = (String, u32, Fluid, EnergyGuard);

fn scene(solver: &str) -> Scene {
    dam_break(0.1, 0.4, 0.01, &format!("solver = \"{solver}\""))
}

fn step(dt: f64) -> StepCommand {
    StepCommand {
        dt,
        corrections: Vec::new(),
        roi: None,
        want_interface: false,
        want_snapshot: true,
        stop: false,
    }
}

/// The checkpoint of a core of `solver` after a few steps.
fn saved(solver: &str) -> Vec<u8> {
    let mut core = SphCore::new(&scene(solver)).unwrap();
    for _ in 0..3 {
        core.handle(&step(1e-3)).unwrap();
    }
    core.checkpoint()
}

/// The checkpoint with its solver and guard edited by `edit`, encoded again as the node encodes it.
fn edited(solver: &str, edit: impl FnOnce(&mut Fluid, &mut EnergyGuard)) -> Vec<u8> {
    let (tag, version, mut fluid, mut guard): Saved = bincode::deserialize(&saved(solver)).unwrap();
    edit(&mut fluid, &mut guard);
    bincode::serialize(&(tag, version, &fluid, &guard)).unwrap()
}

/// The refusal of `data` by a core of `solver` fresh from the scene, which must keep the scene's state.
fn refused(solver: &str, data: &[u8]) -> String {
    let mut core = SphCore::new(&scene(solver)).unwrap();
    let before = core.solver().state().clone();
    let e = core
        .restore(data)
        .expect_err("an inconsistent state is refused")
        .to_string();
    assert_eq!(core.solver().state(), &before, "the refused state is not taken");
    e
}

#[test]
fn its_own_checkpoint_is_taken_and_continues_bit_for_bit() {
    for solver in ["wcsph", "isph"] {
        let data = saved(solver);
        let mut a = SphCore::new(&scene(solver)).unwrap();
        a.restore(&data).unwrap();
        let mut b = SphCore::new(&scene(solver)).unwrap();
        b.restore(&data).unwrap();
        let answer = |core: &mut SphCore| {
            let mut s = core.handle(&step(1e-3)).unwrap().unwrap();
            s.compute_seconds = 0.0; // wall-clock time, the one field that is not computed
            s
        };
        assert_eq!(answer(&mut a), answer(&mut b), "{solver}");
        assert_eq!(a.checkpoint(), b.checkpoint(), "{solver}");
    }
}

#[test]
fn a_state_with_lengths_that_disagree_is_refused_naming_the_field() {
    for solver in ["wcsph", "isph"] {
        let n = SphCore::new(&scene(solver)).unwrap().solver().state().len();
        let e = refused(solver, &edited(solver, |f, _| f.state_mut().v.push([0.0; 2])));
        assert_eq!(
            e,
            format!(
                "checkpoint: state.v holds {} entries, there are {n} fluid particles",
                n + 1
            ),
            "{solver}"
        );
        let e = refused(
            solver,
            &edited(solver, |f, _| {
                f.state_mut().rho.pop();
            }),
        );
        assert_eq!(
            e,
            format!(
                "checkpoint: state.rho holds {} entries, there are {n} fluid particles",
                n - 1
            ),
            "{solver}"
        );
        let e = refused(solver, &edited(solver, |f, _| f.state_mut().p[9] = f64::NAN));
        assert_eq!(e, "checkpoint: state.p[9] = NaN is not finite", "{solver}");
    }
}

#[test]
fn a_guard_or_solver_other_than_the_scenes_is_refused() {
    let e = refused("wcsph", &edited("wcsph", |_, g| g.bound *= 2.0));
    assert!(e.starts_with("checkpoint: guard.bound = "), "{e}");
    let e = refused("isph", &saved("wcsph"));
    assert_eq!(e, "checkpoint: saved with the other fluid.solver");
    let mut data = saved("wcsph");
    data.push(0);
    let e = refused("wcsph", &data);
    assert!(e.starts_with("checkpoint: not a fluid node's state:"), "{e}");
}
