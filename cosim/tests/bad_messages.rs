//! Well-framed messages with inconsistent contents from a node in another process (`docs/PROTOCOL.md` §7
//! "Contents"): an outside program registers as the structure node with a mesh the broker cannot use. The broker
//! used to index it and panic (exit 101; the summary said only "contact-broker died"); it now ends the run `failed`
//! with one line naming the node, the message, the field, the index and the value, and writes `summary.json`.
//! The same checks on every message type, in-process and fuzzed, are in `contact-broker/tests/message_fuzz.rs`.

mod common;

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::*;
use cosim_proto::envelope::Envelope;
use cosim_proto::keys::{key, topic};
use cosim_proto::messages::FemMesh;
use fem_node::core::FemCore;
use zenoh::Wait;

const LIMIT: Duration = Duration::from_secs(60);
const SETS: [&str; 6] = [
    "--set",
    "fluid.spacing=0.1",
    "--set",
    "solid[0].divisions=[20, 2]",
    "--set",
    "run.end_time=0.001",
];

/// Run the coarse hydrostatic plate with an outside structure node that registers `spoil(mesh)`; the run's exit
/// status, its summary and the broker's log.
fn run_with_mesh(name: &str, spoil: impl Fn(&mut FemMesh)) -> (std::process::ExitStatus, serde_json::Value, String) {
    let dir = scratch(name);
    let out = dir.join("out");
    let id = run_id(name);
    let mut run = Kill(
        Command::new(cosim())
            .current_dir(root())
            .env("COSIM_BIN_DIR", bin_dir())
            .args([
                "run",
                "scenes/hydrostatic_plate.toml",
                "--external",
                "fem",
                "--wait-external",
                "30",
            ])
            .args(["--quiet", "--run-id", &id, "--out"])
            .arg(&out)
            .args(SETS)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(std::fs::File::create(dir.join("stderr.txt")).unwrap())
            .spawn()
            .unwrap(),
    );
    let started = Instant::now();
    let announced = out.join("external.json");
    while !announced.exists() {
        assert!(
            run.0.try_wait().unwrap().is_none(),
            "the run ended before it waited for its node"
        );
        assert!(started.elapsed() < LIMIT, "the run did not announce its external node");
        std::thread::sleep(Duration::from_millis(20));
    }
    std::thread::sleep(Duration::from_millis(100));
    let joined = json(&announced);
    let endpoint = joined["connect"].as_str().unwrap().to_string();
    let scene = cosim_proto::scene::load(
        &root().join("scenes/hydrostatic_plate.toml"),
        &SETS
            .iter()
            .skip(1)
            .step_by(2)
            .map(|s| s.to_string())
            .collect::<Vec<_>>(),
    )
    .unwrap();
    let mut mesh = FemCore::new(&scene.scene).unwrap().mesh().clone();
    spoil(&mut mesh);
    let bytes = Envelope::new(&id, 0, 0.0, mesh).encode();
    let (session, _) =
        cosim_bus::session::open_listening(&["tcp/127.0.0.1:0".to_string()], &[endpoint], 5000).expect("join the run");
    // Registered once it arrives; sent again until the run ends, in case the first put beat the connection.
    let status = loop {
        session.put(key(&id, topic::FEM_MESH), bytes.clone()).wait().unwrap();
        if let Some(status) = run.0.try_wait().unwrap() {
            break status;
        }
        assert!(
            started.elapsed() < LIMIT,
            "the run did not end after an unusable registration"
        );
        std::thread::sleep(Duration::from_millis(200));
    };
    drop(session);
    let log = std::fs::read_to_string(out.join("logs/contact-broker.log")).unwrap_or_default();
    (status, json(&out.join("summary.json")), log)
}

#[test]
fn an_unusable_mesh_from_an_outside_node_fails_the_run_naming_the_field() {
    type Spoil = fn(&mut FemMesh);
    let cases: [(&str, Spoil, &str); 2] = [
        (
            "bad_messages_segment",
            |m| m.interface[3].b = m.nodes.len() as u32,
            "fem-node: sent an unusable message: fem/mesh interface[3][1] = 63: out of range (63 nodes)",
        ),
        (
            "bad_messages_masses",
            |m| m.masses.truncate(10),
            "fem-node: sent an unusable message: fem/mesh masses = 10 entries: one per node expected: 63",
        ),
    ];
    for (name, spoil, want) in cases {
        let (status, summary, log) = run_with_mesh(name, spoil);
        assert_eq!(status.code(), Some(1), "{name}: {summary}");
        assert_eq!(summary["status"], "failed", "{name}");
        let message = summary["message"].as_str().unwrap();
        assert!(message.contains(want), "{name}: `{want}` not in `{message}`");
        assert!(!log.contains("panicked"), "{name}: the broker panicked: {log}");
    }
}
