//! A fluid node's checkpoint read back (`docs/PROTOCOL.md` §9), for both solvers through the [`FluidSolver`] trait:
//! its own bytes are taken and the run continues bit for bit as if uninterrupted; a checkpoint of another version is
//! refused naming both versions; a state that decodes but does not hold together (as another tool could write it,
//! with a checksum to match) is refused with one line naming the field, and the core keeps the scene's state. The
//! solvers' own parts are unit tests (`src/wcsph/solver/restore.rs`, `src/isph/solver/restore.rs`).
//!
//! [`FluidSolver`]: sph_node::FluidSolver

mod common;

use common::dam_break;
use cosim_proto::messages::{SphState, StepCommand};
use cosim_proto::scene::Scene;
use sph_node::core::{solver_from_scene, SphCheckpoint, SphCore, CHECKPOINT_TAG};
use sph_node::FluidSolver;

type Saved = (String, u32, SphCheckpoint);

const SOLVERS: [&str; 2] = ["wcsph", "isph"];

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

/// The core's answer to a step, without its wall-clock time (the one field that is not computed).
fn answer(core: &mut SphCore) -> SphState {
    let mut s = core.handle(&step(1e-3)).unwrap().unwrap();
    s.compute_seconds = 0.0;
    s
}

/// The checkpoint of a core of `solver` after a few steps.
fn saved(solver: &str) -> Vec<u8> {
    let mut core = SphCore::new(&scene(solver)).unwrap();
    for _ in 0..3 {
        answer(&mut core);
    }
    core.checkpoint()
}

/// The checkpoint with its contents edited by `edit`, encoded again as the node encodes it.
fn edited(solver: &str, edit: impl FnOnce(&mut SphCheckpoint)) -> Vec<u8> {
    let (tag, version, mut saved): Saved = bincode::deserialize(&saved(solver)).unwrap();
    edit(&mut saved);
    bincode::serialize(&(tag, version, &saved)).unwrap()
}

/// The refusal of `data` by a core of `solver` fresh from the scene, which must keep the scene's state.
fn refused(solver: &str, data: &[u8]) -> String {
    let mut core = SphCore::new(&scene(solver)).unwrap();
    let before = core.checkpoint();
    let e = core
        .restore(data)
        .expect_err("an inconsistent state is refused")
        .to_string();
    assert_eq!(core.checkpoint(), before, "the refused state is not taken");
    e
}

#[test]
fn its_own_checkpoint_is_taken_and_continues_as_the_uninterrupted_run() {
    for solver in SOLVERS {
        let mut whole = SphCore::new(&scene(solver)).unwrap();
        let mut first = SphCore::new(&scene(solver)).unwrap();
        for _ in 0..3 {
            assert_eq!(answer(&mut whole), answer(&mut first), "{solver}");
        }
        let data = first.checkpoint();
        let mut continued = SphCore::new(&scene(solver)).unwrap();
        continued.restore(&data).unwrap();
        assert_eq!(continued.checkpoint(), data, "{solver}: restored as saved");
        for k in 0..4 {
            assert_eq!(
                answer(&mut whole),
                answer(&mut continued),
                "{solver}: step {k} after the restart"
            );
        }
        assert_eq!(whole.checkpoint(), continued.checkpoint(), "{solver}");
    }
}

#[test]
fn a_checkpoint_of_another_version_is_refused_naming_both() {
    for solver in SOLVERS {
        let old = bincode::serialize(&(CHECKPOINT_TAG.0, 6u32, vec![0u8; 64])).unwrap();
        assert_eq!(
            refused(solver, &old),
            format!(
                "sph.bin: holds `cosim-sph-checkpoint` version 6, this sph-node reads `cosim-sph-checkpoint` \
                 version {} (restart the run from its start)",
                CHECKPOINT_TAG.1
            ),
            "{solver}"
        );
    }
}

#[test]
fn a_state_with_lengths_that_disagree_is_refused_naming_the_field() {
    for solver in SOLVERS {
        let n = SphCore::new(&scene(solver)).unwrap().solver().state().len();
        let e = refused(solver, &edited(solver, |s| s.solver.state.v.push([0.0; 2])));
        assert_eq!(
            e,
            format!(
                "sph.bin: state.v holds {} entries, there are {n} fluid particles",
                n + 1
            ),
            "{solver}"
        );
        let e = refused(
            solver,
            &edited(solver, |s| {
                s.solver.state.rho.pop();
            }),
        );
        assert_eq!(
            e,
            format!(
                "sph.bin: state.rho holds {} entries, there are {n} fluid particles",
                n - 1
            ),
            "{solver}"
        );
        let e = refused(solver, &edited(solver, |s| s.solver.state.p[9] = f64::NAN));
        assert_eq!(e, "sph.bin: state.p[9] = NaN is not finite within ±1e50", "{solver}");
        let e = refused(solver, &edited(solver, |s| s.solver.state.x[2] = [1e6, 0.0]));
        assert_eq!(
            e, "sph.bin: state.x[2] = [1000000.0, 0.0] is outside the fluid's domain",
            "{solver}"
        );
        let e = refused(solver, &edited(solver, |s| s.solver.walls.p.push(0.0)));
        assert!(e.starts_with("sph.bin: walls.p holds"), "{solver}: {e}");
        let e = refused(solver, &edited(solver, |s| s.solver.state.m[2] *= 2.0));
        assert!(e.starts_with("sph.bin: state.m[2] = "), "{solver}: {e}");
        let e = refused(solver, &edited(solver, |s| s.solver.own.truncate(3)));
        assert!(e.starts_with(&format!("sph.bin: {solver} state: ")), "{solver}: {e}");
    }
}

#[test]
fn a_guard_or_solver_other_than_the_scenes_is_refused() {
    let e = refused("wcsph", &edited("wcsph", |s| s.guard.bound *= 2.0));
    assert!(e.starts_with("sph.bin: guard.bound = "), "{e}");
    let e = refused("isph", &saved("wcsph"));
    assert_eq!(
        e,
        "sph.bin: saved with fluid.solver = \"wcsph\", the scene has \"isph\""
    );
    let mut data = saved("wcsph");
    data.push(0);
    let e = refused("wcsph", &data);
    assert!(e.starts_with("sph.bin: not a fluid node's state:"), "{e}");
}

/// Steps `solver` `n` times at its stable step, after a contact-like correction of particle 0 before the
/// `edit_at`-th (none when out of range).
fn run(solver: &mut dyn FluidSolver, n: usize, edit_at: usize) {
    for k in 0..n {
        if k == edit_at {
            edit(solver);
        }
        let dt = solver.stable_dt();
        solver.step(dt).unwrap();
    }
}

/// A correction of particle 0, as the broker sends them between two steps.
fn edit(solver: &mut dyn FluidSolver) {
    let state = solver.state_mut();
    state.x[0][0] += 1e-5;
    state.v[0][0] -= 1e-3;
}

/// For both solvers and their options: a solver restored from another's saved state (after steps, one of them
/// after a correction; and, for WCSPH, with a correction made but not yet stepped) continues as the other, bit
/// for bit. (ISPH's contact layer refuses a state edited since its last step, `ContactLayer::check`: the node
/// saves between steps, where no correction is pending.)
#[test]
fn a_saved_solver_continues_bit_for_bit() {
    let cases = [
        ("wcsph", ""),
        ("wcsph", "density_filter = \"mls\"\ndensity_filter_interval = 2"),
        (
            "wcsph",
            "density_filter = \"shepard\"\ndensity_filter_interval = 2\napd = 0.04\nxsph = 0.5\ndensity_diffusion = 0.1",
        ),
        ("isph", ""),
        ("isph", "apd = 0.04\nxsph = 0.5"),
        ("isph", "ppe_source = \"density_invariant\""),
    ];
    for (kind, sets) in cases {
        let pending: &[bool] = if kind == "wcsph" { &[false, true] } else { &[false] };
        for &pending in pending {
            let scene = dam_break(0.1, 0.4, 0.01, &format!("solver = \"{kind}\"\n{sets}"));
            let mut a = solver_from_scene(&scene).unwrap();
            run(a.as_mut(), 5, 3);
            if pending {
                edit(a.as_mut());
            }
            let mut b = solver_from_scene(&scene).unwrap();
            b.restore(a.save()).unwrap();
            assert_eq!(b.name(), kind);
            assert_eq!(
                bincode::serialize(&b.save()).unwrap(),
                bincode::serialize(&a.save()).unwrap(),
                "{kind} {sets:?} pending {pending}"
            );
            for k in 0..4 {
                let dt = a.stable_dt();
                assert_eq!(dt.to_bits(), b.stable_dt().to_bits(), "{kind} {sets:?} step {k}");
                a.step(dt).unwrap();
                b.step(dt).unwrap();
                let (sa, sb) = (
                    bincode::serialize(&a.save()).unwrap(),
                    bincode::serialize(&b.save()).unwrap(),
                );
                assert!(
                    sa == sb,
                    "{kind} {sets:?} pending {pending}: step {k} after the restore"
                );
            }
        }
    }
}
