//! How the codec refuses a message (`docs/PROTOCOL.md` §7) and how it behaves on arbitrary input.

use cosim_proto::keys::{key, topic, valid_run_id};
use cosim_proto::messages::{
    ContactFace, Correction, Energies, FemMesh, FemSnapshot, FemState, NodeError, Segment, StepCommand,
};
use cosim_proto::{CodecError, Envelope, PROTOCOL_VERSION};
use proptest::prelude::*;

fn step_command() -> Envelope<StepCommand> {
    Envelope::new(
        "r1",
        3,
        0.5,
        StepCommand {
            dt: 0.125,
            corrections: vec![Correction {
                id: 7,
                dx: [1.0, -2.0],
                dv: [0.0, 0.25],
                face: None,
            }],
            roi: Some([0.0, 0.0, 1.0, 1.0]),
            want_interface: true,
            want_snapshot: false,
            stop: false,
        },
    )
}

fn fem_state() -> Envelope<FemState> {
    Envelope::new(
        "r1",
        3,
        0.625,
        FemState {
            ids: vec![4, 5],
            x: vec![[1.0, 2.0], [3.0, 4.0]],
            v: vec![[0.0, 0.0], [-1.0, 0.5]],
            substeps: 2,
            dt_stable: 1e-4,
            compute_seconds: 0.01,
            snapshot: Some(FemSnapshot {
                x: vec![[1.0, 2.0]],
                v: vec![[0.0, 0.0]],
                stress: vec![[1.0, 2.0, 3.0]],
                energies: vec![Energies::default()],
            }),
        },
    )
}

fn assert_malformed<B: std::fmt::Debug>(result: Result<Envelope<B>, CodecError>, len: usize) {
    match result {
        Err(CodecError::Malformed { what, len: got_len, .. }) => {
            assert_eq!(what, "test");
            assert_eq!(got_len, len);
        }
        other => panic!("expected CodecError::Malformed, got {other:?}"),
    }
}

#[test]
fn another_protocol_version_is_refused_with_version() {
    let mut env = step_command();
    env.protocol_version = PROTOCOL_VERSION + 1;
    let err = Envelope::<StepCommand>::decode(&env.encode(), "r1", "test").unwrap_err();
    assert!(
        matches!(err, CodecError::Version { what: "test", got } if got == PROTOCOL_VERSION + 1),
        "{err:?}"
    );
    assert!(err.to_string().contains("protocol version 4"), "{err}");
}

#[test]
fn another_version_is_reported_even_when_the_body_does_not_decode() {
    // A newer peer may change the body layout: it still gets a version error, not a decode error, as long as
    // the first two header fields (u32 version, String run) are in place.
    let mut bytes = Envelope::new(
        "r1",
        3,
        0.5,
        NodeError {
            status: "x".into(),
            message: "y".into(),
        },
    )
    .encode();
    bytes[0] = 4;
    let err = Envelope::<StepCommand>::decode(&bytes, "r1", "test").unwrap_err();
    assert!(matches!(err, CodecError::Version { got: 4, .. }), "{err:?}");
    // Version is checked before the run.
    let err = Envelope::<StepCommand>::decode(&bytes, "other", "test").unwrap_err();
    assert!(matches!(err, CodecError::Version { got: 4, .. }), "{err:?}");
}

#[test]
fn another_run_is_refused_with_run() {
    let bytes = step_command().encode();
    let err = Envelope::<StepCommand>::decode(&bytes, "r2", "test").unwrap_err();
    match &err {
        CodecError::Run { what, got, expected } => {
            assert_eq!(*what, "test");
            assert_eq!(got, "r1");
            assert_eq!(expected, "r2");
        }
        other => panic!("expected CodecError::Run, got {other:?}"),
    }
    assert_eq!(err.to_string(), "test message belongs to run `r1`, not `r2`");
}

#[test]
fn another_step_is_refused_with_step() {
    let env = Envelope::<FemState>::decode(&fem_state().encode(), "r1", "test").unwrap();
    let err = env.clone().expect_step(4, "test").unwrap_err();
    assert!(
        matches!(
            err,
            CodecError::Step {
                what: "test",
                got: 3,
                expected: 4
            }
        ),
        "{err:?}"
    );
    assert_eq!(err.to_string(), "test message is for step 3, expected step 4");
    assert_eq!(env.clone().expect_step(3, "test").unwrap(), env);
}

#[test]
fn trailing_bytes_are_malformed() {
    for extra in [&[0u8][..], &[1, 2, 3], &[0; 64]] {
        let mut bytes = step_command().encode();
        bytes.extend_from_slice(extra);
        let len = bytes.len();
        assert_malformed(Envelope::<StepCommand>::decode(&bytes, "r1", "test"), len);
    }
}

#[test]
fn every_truncation_is_malformed() {
    let full = fem_state().encode();
    for cut in 0..full.len() {
        assert_malformed(Envelope::<FemState>::decode(&full[..cut], "r1", "test"), cut);
    }
    let full = step_command().encode();
    for cut in 0..full.len() {
        assert_malformed(Envelope::<StepCommand>::decode(&full[..cut], "r1", "test"), cut);
    }
}

#[test]
fn invalid_bool_option_tag_and_utf8_are_malformed() {
    let good = step_command().encode();
    let n = good.len();
    // Layout tail: ... roi tag, 4 × f64, want_interface, want_snapshot, stop.
    let mut bad_bool = good.clone();
    bad_bool[n - 1] = 2;
    assert_malformed(Envelope::<StepCommand>::decode(&bad_bool, "r1", "test"), n);

    let mut bad_tag = good.clone();
    bad_tag[n - 3 - 33] = 2;
    assert_malformed(Envelope::<StepCommand>::decode(&bad_tag, "r1", "test"), n);

    // Run bytes at offsets 12..14; 0xff is never valid UTF-8.
    let mut bad_utf8 = good;
    bad_utf8[12] = 0xff;
    assert_malformed(Envelope::<StepCommand>::decode(&bad_utf8, "r1", "test"), n);
}

/// The whole error chain, as `{:#}` prints it (what the broker logs and a summary says).
fn chain(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut at = e.source();
    while let Some(s) = at {
        text += &format!(": {s}");
        at = s.source();
    }
    text
}

/// Bincode's reason said once: "malformed fem/mesh … string is not valid utf8: …: string is not valid utf8: …"
/// (found 2026-12-06 by the sweep of hostile external nodes, D25).
#[test]
fn a_malformed_message_says_its_reason_once() {
    let mut bad_utf8 = step_command().encode();
    bad_utf8[12] = 0xff;
    let n = bad_utf8.len();
    let err = Envelope::<StepCommand>::decode(&bad_utf8, "r1", "test").unwrap_err();
    let text = chain(&err);
    assert!(
        text.starts_with(&format!(
            "malformed test message ({n} bytes): string is not valid utf8: "
        )),
        "{text}"
    );
    assert_eq!(text.matches("not valid utf8").count(), 1, "{text}");
    assert_eq!(text.matches("invalid utf-8").count(), 1, "{text}");
}

#[test]
fn huge_length_prefixes_are_malformed_without_allocating() {
    // corrections count at offset 38 (header 30 + dt 8) claims 2^62 items; run length claims 2^40 bytes.
    let mut bytes = step_command().encode();
    bytes[38..46].copy_from_slice(&(1u64 << 62).to_le_bytes());
    let n = bytes.len();
    assert_malformed(Envelope::<StepCommand>::decode(&bytes, "r1", "test"), n);

    let mut bytes = step_command().encode();
    bytes[4..12].copy_from_slice(&(1u64 << 40).to_le_bytes());
    assert_malformed(Envelope::<StepCommand>::decode(&bytes, "r1", "test"), n);
}

#[test]
fn another_message_type_is_not_taken_for_a_step_command() {
    let bytes = Envelope::new(
        "r1",
        3,
        0.5,
        NodeError {
            status: "failed".into(),
            message: "boom".into(),
        },
    )
    .encode();
    let n = bytes.len();
    assert_malformed(Envelope::<StepCommand>::decode(&bytes, "r1", "test"), n);
}

#[test]
fn keys_are_under_cosim_run() {
    assert_eq!(key("r1", topic::SCENE), "cosim/r1/scene");
    assert_eq!(key("r1", topic::FEM_MESH), "cosim/r1/fem/mesh");
    assert_eq!(key("r1", topic::FEM_STATE), "cosim/r1/fem/state");
    assert_eq!(key("r1", topic::FEM_ERROR), "cosim/r1/fem/error");
    assert_eq!(key("r1", topic::BROKER_FEM), "cosim/r1/broker/fem");
    assert_eq!(key("r1", topic::FEM_ALIVE), "cosim/r1/fem/alive");
    assert_eq!(key("r1", topic::BROKER_ALIVE), "cosim/r1/broker/alive");
    assert_eq!(key("r1", topic::FEM_STATUS), "cosim/r1/fem/status");
    assert_eq!(key("r1", topic::BROKER_STATUS), "cosim/r1/broker/status");
    assert!(valid_run_id("run-A_7"));
    for bad in ["", "a/b", "a*", "a b", "é", &"x".repeat(65)] {
        assert!(!valid_run_id(bad), "{bad:?}");
    }
}

/// The decoder must return (never panic, never allocate what the input only claims) for any bytes.
fn decode_all(bytes: &[u8]) {
    let _ = Envelope::<StepCommand>::decode(bytes, "r1", "fuzz");
    let _ = Envelope::<FemState>::decode(bytes, "r1", "fuzz");
    let _ = Envelope::<FemMesh>::decode(bytes, "r1", "fuzz");
    let _ = Envelope::<NodeError>::decode(bytes, "r1", "fuzz");
}

fn finite() -> impl Strategy<Value = f64> {
    -1e6..1e6f64
}

fn vec2() -> impl Strategy<Value = [f64; 2]> {
    [finite(), finite()]
}

fn step_command_strategy() -> impl Strategy<Value = StepCommand> {
    (
        finite(),
        prop::collection::vec((any::<u32>(), vec2(), vec2(), prop::option::of((vec2(), vec2()))), 0..8),
        prop::option::of([finite(), finite(), finite(), finite()]),
        any::<(bool, bool, bool)>(),
    )
        .prop_map(|(dt, corr, roi, (want_interface, want_snapshot, stop))| StepCommand {
            dt,
            corrections: corr
                .into_iter()
                .map(|(id, dx, dv, face)| Correction {
                    id,
                    dx,
                    dv,
                    face: face.map(|(point, normal)| ContactFace { point, normal }),
                })
                .collect(),
            roi,
            want_interface,
            want_snapshot,
            stop,
        })
}

fn fem_mesh_strategy() -> impl Strategy<Value = FemMesh> {
    (
        prop::collection::vec("[a-z0-9_ é]{0,6}", 0..3),
        prop::collection::vec(vec2(), 0..5),
        prop::collection::vec(finite(), 0..5),
        prop::collection::vec(prop::collection::vec(any::<u32>(), 3..=4), 0..3),
        prop::collection::vec((any::<u32>(), any::<u32>()), 0..4),
        finite(),
    )
        .prop_map(|(solid_names, nodes, masses, cells, segs, dt_stable)| FemMesh {
            node_solid: vec![0; nodes.len()],
            cell_solid: vec![1; cells.len()],
            interface: segs.into_iter().map(|(a, b)| Segment { a, b }).collect(),
            fixed: vec![2; masses.len()],
            solid_names,
            nodes,
            masses,
            cells,
            dt_stable,
        })
}

proptest! {
    #[test]
    fn random_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..512)) {
        decode_all(&bytes);
    }

    #[test]
    fn random_bodies_after_a_valid_header_never_panic(body in prop::collection::vec(any::<u8>(), 0..512)) {
        // Get past the header so the fuzzing reaches the body decoders.
        let mut bytes = Envelope::new("r1", 0, 0.0, ()).encode();
        bytes.extend_from_slice(&body);
        decode_all(&bytes);
    }

    #[test]
    fn mutated_messages_never_panic(index in any::<prop::sample::Index>(), byte in any::<u8>()) {
        let mut bytes = fem_state().encode();
        let i = index.index(bytes.len());
        bytes[i] = byte;
        decode_all(&bytes);
    }

    #[test]
    fn step_command_round_trips_with_documented_size(
        run in "[A-Za-z0-9_-]{1,64}", step in any::<u64>(), t in finite(), body in step_command_strategy(),
    ) {
        let env = Envelope::new(&run, step, t, body);
        let bytes = env.encode();
        // Size formula of docs/PROTOCOL.md §5: header 28 + run bytes; body 8 + 8 + 37 per correction + 32 per face
        // + roi + 3.
        let roi = if env.body.roi.is_some() { 33 } else { 1 };
        let faces = env.body.corrections.iter().filter(|c| c.face.is_some()).count();
        prop_assert_eq!(
            bytes.len(),
            28 + run.len() + 8 + 8 + 37 * env.body.corrections.len() + 32 * faces + roi + 3
        );
        prop_assert_eq!(Envelope::<StepCommand>::decode(&bytes, &run, "test").unwrap(), env);
    }

    #[test]
    fn fem_mesh_round_trips(body in fem_mesh_strategy()) {
        let env = Envelope::new("r1", 0, 0.0, body);
        prop_assert_eq!(Envelope::<FemMesh>::decode(&env.encode(), "r1", "test").unwrap(), env);
    }
}
