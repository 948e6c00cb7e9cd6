//! A structure node's checkpoint read back (`docs/PROTOCOL.md` §9): its own bytes continue the run bit for bit; a
//! state that decodes but does not hold together (as another tool could write it, with a checksum to match) is
//! refused with one line naming the field, the node and the value, and the core keeps the scene's state.

use cosim_proto::messages::StepCommand;
use cosim_proto::scene::{parse, Scene};
use fem_node::core::FemCore;
use fem_node::FemState;

/// A 2 × 1 quad cantilever (6 nodes), clamped at its left end, under gravity.
fn scene() -> Scene {
    let text = r#"
version = 1
[run]
name = "bar"
end_time = 1.0
output_interval = 0.1
gravity = [0.0, -9.81]
[[solid]]
name = "bar"
min = [0.0, 0.0]
max = [0.2, 0.1]
divisions = [2, 1]
material = { model = "linear_elastic", density = 1000.0, youngs_modulus = 1e6, poisson_ratio = 0.3 }
fixed = [{ min = [-0.001, -0.001], max = [0.001, 0.101] }]
"#;
    parse("bar.toml", text, &[]).expect("a valid scene")
}

fn step(dt: f64) -> StepCommand {
    StepCommand {
        dt,
        corrections: Vec::new(),
        roi: None,
        want_interface: true,
        want_snapshot: true,
        stop: false,
    }
}

/// A core after a few steps, and its checkpoint.
fn saved() -> (FemCore, Vec<u8>) {
    let mut core = FemCore::new(&scene()).unwrap();
    for _ in 0..3 {
        core.handle(&step(1e-3)).unwrap();
    }
    let data = core.checkpoint();
    (core, data)
}

type Saved = (String, u32, FemState, bool);

/// The checkpoint with its state edited by `edit`, encoded again as the node encodes it.
fn edited(edit: impl FnOnce(&mut FemState)) -> Vec<u8> {
    let (_, data) = saved();
    let (tag, version, mut state, stale): Saved = bincode::deserialize(&data).unwrap();
    edit(&mut state);
    bincode::serialize(&(tag, version, state, stale)).unwrap()
}

/// The refusal of `data` by a core fresh from the scene, which must keep the scene's state.
fn refused(data: &[u8]) -> String {
    let mut core = FemCore::new(&scene()).unwrap();
    let before = core.solver().state().clone();
    let e = core
        .restore(data)
        .expect_err("an inconsistent state is refused")
        .to_string();
    assert_eq!(core.solver().state(), &before, "the refused state is not taken");
    e
}

#[test]
fn its_own_checkpoint_continues_bit_for_bit() {
    let (mut original, data) = saved();
    let mut restored = FemCore::new(&scene()).unwrap();
    restored.restore(&data).unwrap();
    let answer = |core: &mut FemCore| {
        let mut a = core.handle(&step(1e-3)).unwrap().unwrap();
        a.compute_seconds = 0.0; // wall-clock time, the one field that is not computed
        a
    };
    assert_eq!(answer(&mut original), answer(&mut restored));
    assert_eq!(original.solver().state(), restored.solver().state());
}

#[test]
fn lengths_that_disagree_are_refused_naming_the_field() {
    assert_eq!(
        refused(&edited(|s| {
            s.v.pop();
        })),
        "fem.bin: state.v holds 5 nodes, the model has 6"
    );
    assert_eq!(
        refused(&edited(|s| s.a.push([0.0; 2]))),
        "fem.bin: state.a holds 7 nodes, the model has 6"
    );
    assert_eq!(
        refused(&edited(|s| s.x.clear())),
        "fem.bin: state.x holds 0 nodes, the model has 6"
    );
}

#[test]
fn values_that_are_not_finite_or_not_where_clamped_are_refused() {
    assert_eq!(
        refused(&edited(|s| s.x[4] = [f64::NAN, 0.1])),
        "fem.bin: state.x[4] = [NaN, 0.1] is not finite within ±1e50"
    );
    // Finite but beyond any state (2026-12-06): the run failed at its first step as a collapsed element.
    assert_eq!(
        refused(&edited(|s| s.x[4] = [1e300, 0.1])),
        "fem.bin: state.x[4] = [1e300, 0.1] is not finite within ±1e50"
    );
    assert_eq!(
        refused(&edited(|s| s.t = f64::INFINITY)),
        "fem.bin: state.t = inf is not a time"
    );
    // Node 3 is (0, 0.1), on the clamped edge.
    let e = refused(&edited(|s| s.v[3] = [0.0, -1.0]));
    assert_eq!(
        e,
        "fem.bin: state: node 3 is clamped at [0.0, 0.1] but has x [0.0, 0.1], v [0.0, -1.0], a [0.0, 0.0]"
    );
}

#[test]
fn bytes_that_are_not_a_state_are_refused() {
    let (_, mut data) = saved();
    data.push(0);
    let e = refused(&data);
    assert!(e.starts_with("fem.bin: not a structure node's state:"), "{e}");
    let e = refused(&data[..data.len() - 9]);
    assert!(e.starts_with("fem.bin: not a structure node's state:"), "{e}");
}
