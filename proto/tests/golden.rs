//! Golden bytes: the wire encoding of every message, pinned byte for byte.
//!
//! Each expected hex string below was written by hand from the layout rules of `docs/PROTOCOL.md` (§3–§5), one
//! line per field, not pasted from the encoder's output. A failure here means the wire format changed: either
//! the change is a bug, or it needs a new `PROTOCOL_VERSION` and an updated `docs/PROTOCOL.md`.
//!
//! f64 constants used (IEEE-754 binary64, little endian):
//!   0.0 = 00 00 00 00 00 00 00 00    0.0625 = .. b0 3f    0.125 = .. c0 3f    0.25 = .. d0 3f
//!   0.5 = .. e0 3f    0.625 = .. e4 3f    1.0 = .. f0 3f    1.5 = .. f8 3f    2.0 = .. 00 40
//!   -0.125 = .. c0 bf    -0.5 = .. e0 bf    -1.0 = .. f0 bf    -2.0 = .. 00 c0   (`..` = six 00 bytes)

use std::fmt::Debug;

use cosim_proto::messages::{
    ContactFace, Correction, Energies, FemMesh, FemSnapshot, FemState, NodeCheckpoint, NodeError, Segment, StepCommand,
};
use cosim_proto::{Envelope, PROTOCOL_VERSION};
use serde::{de::DeserializeOwned, Serialize};

/// Bytes from hex text; whitespace is ignored and `#` starts a comment that runs to the end of the line.
fn hex(text: &str) -> Vec<u8> {
    let digits: String = text
        .lines()
        .map(|line| line.split('#').next().unwrap_or(""))
        .flat_map(|line| line.chars().filter(|c| !c.is_whitespace()))
        .collect();
    assert_eq!(digits.len() % 2, 0, "odd number of hex digits");
    (0..digits.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&digits[i..i + 2], 16).expect("hex digit"))
        .collect()
}

fn to_hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect::<Vec<_>>().join(" ")
}

/// Encode `env`, compare with `expected_hex`, decode the expected bytes back and compare with `env`.
fn check_golden<B>(env: &Envelope<B>, expected_hex: &str)
where
    B: Serialize + DeserializeOwned + PartialEq + Debug,
{
    let expected = hex(expected_hex);
    let encoded = env.encode();
    assert_eq!(
        encoded,
        expected,
        "\nencoded:  {}\nexpected: {}\n",
        to_hex(&encoded),
        to_hex(&expected)
    );
    let decoded = Envelope::<B>::decode(&expected, &env.run, "golden").expect("golden bytes decode");
    assert_eq!(&decoded, env);
}

/// The worked example of `docs/PROTOCOL.md` §6: the same hex, line for line.
const STEP_COMMAND_DOC_EXAMPLE: &str = "
    03 00 00 00                         # protocol_version u32 = 3
    02 00 00 00 00 00 00 00             # run: length u64 = 2
    72 31                               #      UTF-8 \"r1\"
    03 00 00 00 00 00 00 00             # step u64 = 3
    00 00 00 00 00 00 e0 3f             # t f64 = 0.5
    00 00 00 00 00 00 c0 3f             # body.dt f64 = 0.125
    01 00 00 00 00 00 00 00             # body.corrections: count u64 = 1
    07 00 00 00                         #   [0].id u32 = 7
    00 00 00 00 00 00 f0 3f             #   [0].dx[0] f64 = 1.0
    00 00 00 00 00 00 00 c0             #   [0].dx[1] f64 = -2.0
    00 00 00 00 00 00 00 00             #   [0].dv[0] f64 = 0.0
    00 00 00 00 00 00 d0 3f             #   [0].dv[1] f64 = 0.25
    00                                  #   [0].face: Option tag 0 = None
    00                                  # body.roi: Option tag 0 = None
    01                                  # body.want_interface bool = true
    00                                  # body.want_snapshot bool = false
    00                                  # body.stop bool = false
";

fn step_command_doc_example() -> Envelope<StepCommand> {
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
            roi: None,
            want_interface: true,
            want_snapshot: false,
            stop: false,
        },
    )
}

#[test]
fn protocol_version_is_3() {
    // Every golden string below starts with `03 00 00 00`; bumping the version must revisit them all.
    assert_eq!(PROTOCOL_VERSION, 3);
}

#[test]
fn step_command_doc_example_is_87_bytes() {
    // Header 4 + (8 + 2) + 8 + 8 = 30, body 8 + (8 + 1 × 37) + 1 + 3 = 57 (`docs/PROTOCOL.md` §6).
    assert_eq!(hex(STEP_COMMAND_DOC_EXAMPLE).len(), 87);
    assert_eq!(step_command_doc_example().encode().len(), 87);
}

#[test]
fn step_command_doc_example_matches_protocol_md() {
    // The first ```text block of docs/PROTOCOL.md is the worked example: leading hex bytes of each line.
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/PROTOCOL.md");
    let doc = std::fs::read_to_string(path).expect("docs/PROTOCOL.md");
    let block = doc
        .split("```text\n")
        .nth(1)
        .and_then(|b| b.split("```").next())
        .expect("a ```text block");
    let doc_hex: String = block
        .lines()
        .flat_map(|line| {
            line.split_whitespace()
                .take_while(|w| w.len() == 2 && w.chars().all(|c| c.is_ascii_hexdigit()))
        })
        .collect::<Vec<_>>()
        .join(" ");
    assert_eq!(
        hex(&doc_hex),
        hex(STEP_COMMAND_DOC_EXAMPLE),
        "docs/PROTOCOL.md §6 drifted from the golden bytes"
    );
}

#[test]
fn step_command_doc_example_golden() {
    check_golden(&step_command_doc_example(), STEP_COMMAND_DOC_EXAMPLE);
}

#[test]
fn a_fluid_correction_with_its_face_golden() {
    // Protocol version 3: the structure's face behind a particle a `particle_particle` pass corrected.
    let env = Envelope::new(
        "r1",
        2,
        0.25,
        StepCommand {
            dt: 0.0625,
            corrections: vec![Correction {
                id: 4,
                dx: [0.0; 2],
                dv: [0.0, 0.5],
                face: Some(ContactFace {
                    point: [1.0, -0.5],
                    normal: [0.0, 1.0],
                }),
            }],
            roi: None,
            want_interface: false,
            want_snapshot: false,
            stop: false,
        },
    );
    check_golden(
        &env,
        "
        03 00 00 00                     # protocol_version = 3
        02 00 00 00 00 00 00 00 72 31   # run = \"r1\"
        02 00 00 00 00 00 00 00         # step = 2
        00 00 00 00 00 00 d0 3f         # t = 0.25
        00 00 00 00 00 00 b0 3f         # dt = 0.0625
        01 00 00 00 00 00 00 00         # corrections: count 1
        04 00 00 00                     #   id = 4
        00 00 00 00 00 00 00 00         #   dx[0] = 0.0
        00 00 00 00 00 00 00 00         #   dx[1] = 0.0
        00 00 00 00 00 00 00 00         #   dv[0] = 0.0
        00 00 00 00 00 00 e0 3f         #   dv[1] = 0.5
        01                              #   face: Some
        00 00 00 00 00 00 f0 3f         #     point[0] = 1.0
        00 00 00 00 00 00 e0 bf         #     point[1] = -0.5
        00 00 00 00 00 00 00 00         #     normal[0] = 0.0
        00 00 00 00 00 00 f0 3f         #     normal[1] = 1.0
        00                              # roi = None
        00 00 00                        # want_interface, want_snapshot, stop = false
        ",
    );
}

#[test]
fn step_command_with_roi_and_stop_golden() {
    let env = Envelope::new(
        "r1",
        9,
        1.0,
        StepCommand {
            dt: 0.0,
            corrections: vec![],
            roi: Some([0.0, -0.5, 2.0, 1.5]),
            want_interface: false,
            want_snapshot: true,
            stop: true,
        },
    );
    check_golden(
        &env,
        "
        03 00 00 00                     # protocol_version = 3
        02 00 00 00 00 00 00 00 72 31   # run = \"r1\"
        09 00 00 00 00 00 00 00         # step = 9
        00 00 00 00 00 00 f0 3f         # t = 1.0
        00 00 00 00 00 00 00 00         # dt = 0.0
        00 00 00 00 00 00 00 00         # corrections: count 0
        01                              # roi: Some
        00 00 00 00 00 00 00 00         #   xmin = 0.0
        00 00 00 00 00 00 e0 bf         #   ymin = -0.5
        00 00 00 00 00 00 00 40         #   xmax = 2.0
        00 00 00 00 00 00 f8 3f         #   ymax = 1.5
        00                              # want_interface = false
        01                              # want_snapshot = true
        01                              # stop = true
        ",
    );
}

#[test]
fn fem_mesh_golden() {
    // One triangle of solid 0 ("gate"), node 0 clamped.
    let env = Envelope::new(
        "r1",
        0,
        0.0,
        FemMesh {
            solid_names: vec!["gate".to_string()],
            nodes: vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
            masses: vec![0.25, 0.5, 0.25],
            node_solid: vec![0, 0, 0],
            cells: vec![vec![0, 1, 2]],
            cell_solid: vec![0],
            interface: vec![Segment { a: 0, b: 1 }, Segment { a: 1, b: 2 }, Segment { a: 2, b: 0 }],
            fixed: vec![0],
            dt_stable: 0.0625,
        },
    );
    check_golden(
        &env,
        "
        03 00 00 00                     # protocol_version = 3
        02 00 00 00 00 00 00 00 72 31   # run = \"r1\"
        00 00 00 00 00 00 00 00         # step = 0
        00 00 00 00 00 00 00 00         # t = 0.0
        01 00 00 00 00 00 00 00         # solid_names: count 1
        04 00 00 00 00 00 00 00         #   [0]: length 4
        67 61 74 65                     #        \"gate\"
        03 00 00 00 00 00 00 00         # nodes: count 3
        00 00 00 00 00 00 00 00  00 00 00 00 00 00 00 00   # [0] = (0.0, 0.0)
        00 00 00 00 00 00 f0 3f  00 00 00 00 00 00 00 00   # [1] = (1.0, 0.0)
        00 00 00 00 00 00 00 00  00 00 00 00 00 00 f0 3f   # [2] = (0.0, 1.0)
        03 00 00 00 00 00 00 00         # masses: count 3
        00 00 00 00 00 00 d0 3f         #   0.25
        00 00 00 00 00 00 e0 3f         #   0.5
        00 00 00 00 00 00 d0 3f         #   0.25
        03 00 00 00 00 00 00 00         # node_solid: count 3
        00 00 00 00  00 00 00 00  00 00 00 00              # 0, 0, 0
        01 00 00 00 00 00 00 00         # cells: count 1
        03 00 00 00 00 00 00 00         #   [0]: count 3
        00 00 00 00  01 00 00 00  02 00 00 00              #        0, 1, 2
        01 00 00 00 00 00 00 00         # cell_solid: count 1
        00 00 00 00                     #   0
        03 00 00 00 00 00 00 00         # interface: count 3
        00 00 00 00  01 00 00 00        #   (a 0, b 1)
        01 00 00 00  02 00 00 00        #   (a 1, b 2)
        02 00 00 00  00 00 00 00        #   (a 2, b 0)
        01 00 00 00 00 00 00 00         # fixed: count 1
        00 00 00 00                     #   0
        00 00 00 00 00 00 b0 3f         # dt_stable = 0.0625
        ",
    );
}

#[test]
fn fem_state_without_snapshot_golden() {
    let env = Envelope::new(
        "r1",
        3,
        0.625,
        FemState {
            ids: vec![4],
            x: vec![[1.0, 2.0]],
            v: vec![[-1.0, 0.0]],
            substeps: 2,
            dt_stable: 0.0625,
            compute_seconds: 0.25,
            snapshot: None,
        },
    );
    check_golden(
        &env,
        "
        03 00 00 00                     # protocol_version = 3
        02 00 00 00 00 00 00 00 72 31   # run = \"r1\"
        03 00 00 00 00 00 00 00         # step = 3
        00 00 00 00 00 00 e4 3f         # t = 0.625
        01 00 00 00 00 00 00 00         # ids: count 1
        04 00 00 00                     #   4
        01 00 00 00 00 00 00 00         # x: count 1
        00 00 00 00 00 00 f0 3f  00 00 00 00 00 00 00 40   # (1.0, 2.0)
        01 00 00 00 00 00 00 00         # v: count 1
        00 00 00 00 00 00 f0 bf  00 00 00 00 00 00 00 00   # (-1.0, 0.0)
        02 00 00 00                     # substeps u32 = 2
        00 00 00 00 00 00 b0 3f         # dt_stable = 0.0625
        00 00 00 00 00 00 d0 3f         # compute_seconds = 0.25
        00                              # snapshot: None
        ",
    );
}

#[test]
fn fem_state_with_snapshot_golden() {
    let env = Envelope::new(
        "r1",
        4,
        1.0,
        FemState {
            ids: vec![],
            x: vec![],
            v: vec![],
            substeps: 1,
            dt_stable: 0.0625,
            compute_seconds: 0.0,
            snapshot: Some(FemSnapshot {
                x: vec![[0.0, 1.0]],
                v: vec![[0.5, 0.0]],
                stress: vec![[1.0, 2.0, -1.0]],
                energies: vec![Energies {
                    kinetic: 0.5,
                    strain: 0.25,
                    potential: -0.125,
                }],
            }),
        },
    );
    check_golden(
        &env,
        "
        03 00 00 00                     # protocol_version = 3
        02 00 00 00 00 00 00 00 72 31   # run = \"r1\"
        04 00 00 00 00 00 00 00         # step = 4
        00 00 00 00 00 00 f0 3f         # t = 1.0
        00 00 00 00 00 00 00 00         # ids: count 0
        00 00 00 00 00 00 00 00         # x: count 0
        00 00 00 00 00 00 00 00         # v: count 0
        01 00 00 00                     # substeps = 1
        00 00 00 00 00 00 b0 3f         # dt_stable = 0.0625
        00 00 00 00 00 00 00 00         # compute_seconds = 0.0
        01                              # snapshot: Some
        01 00 00 00 00 00 00 00         #   x: count 1
        00 00 00 00 00 00 00 00  00 00 00 00 00 00 f0 3f   # (0.0, 1.0)
        01 00 00 00 00 00 00 00         #   v: count 1
        00 00 00 00 00 00 e0 3f  00 00 00 00 00 00 00 00   # (0.5, 0.0)
        01 00 00 00 00 00 00 00         #   stress: count 1
        00 00 00 00 00 00 f0 3f         #     sxx = 1.0
        00 00 00 00 00 00 00 40         #     syy = 2.0
        00 00 00 00 00 00 f0 bf         #     sxy = -1.0
        01 00 00 00 00 00 00 00         #   energies: count 1
        00 00 00 00 00 00 e0 3f         #     kinetic = 0.5
        00 00 00 00 00 00 d0 3f         #     strain = 0.25
        00 00 00 00 00 00 c0 bf         #     potential = -0.125
        ",
    );
}

#[test]
fn node_checkpoint_golden() {
    let env = Envelope::new(
        "r1",
        7,
        0.5,
        NodeCheckpoint {
            node: "fem-node".to_string(),
            data: vec![0xde, 0xad, 0xbe],
        },
    );
    check_golden(
        &env,
        "
        03 00 00 00                     # protocol_version = 3
        02 00 00 00 00 00 00 00 72 31   # run = \"r1\"
        07 00 00 00 00 00 00 00         # step = 7
        00 00 00 00 00 00 e0 3f         # t = 0.5
        08 00 00 00 00 00 00 00         # node: length 8
        66 65 6d 2d 6e 6f 64 65         #   \"fem-node\"
        03 00 00 00 00 00 00 00         # data: length 3
        de ad be                        #   the node's bytes
        ",
    );
}

#[test]
fn node_error_golden() {
    let env = Envelope::new(
        "r1",
        5,
        0.5,
        NodeError {
            status: "unstable".to_string(),
            message: "NaN at node 3".to_string(),
        },
    );
    check_golden(
        &env,
        "
        03 00 00 00                     # protocol_version = 3
        02 00 00 00 00 00 00 00 72 31   # run = \"r1\"
        05 00 00 00 00 00 00 00         # step = 5
        00 00 00 00 00 00 e0 3f         # t = 0.5
        08 00 00 00 00 00 00 00         # status: length 8
        75 6e 73 74 61 62 6c 65         #   \"unstable\"
        0d 00 00 00 00 00 00 00         # message: length 13
        4e 61 4e 20 61 74 20 6e 6f 64 65 20 33   # \"NaN at node 3\"
        ",
    );
}

#[test]
fn run_id_bytes_are_utf8_with_u64_length() {
    // A longer run id, as `keys::fresh_run_id` makes them, only changes the length prefix and the bytes.
    let env = Envelope::new(
        "run-A_7",
        1,
        0.0,
        NodeError {
            status: String::new(),
            message: String::new(),
        },
    );
    check_golden(
        &env,
        "
        03 00 00 00
        07 00 00 00 00 00 00 00  72 75 6e 2d 41 5f 37    # \"run-A_7\"
        01 00 00 00 00 00 00 00
        00 00 00 00 00 00 00 00
        00 00 00 00 00 00 00 00         # status: empty string
        00 00 00 00 00 00 00 00         # message: empty string
        ",
    );
}
