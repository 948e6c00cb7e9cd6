//! Bad input on the wire (`docs/PROTOCOL.md` §7): while a coupled run goes on as three processes, an intruder on
//! the same zenoh network publishes random bytes, truncated messages, messages with trailing bytes, another
//! protocol version, another run id and the wrong step on every topic of the run. Each is refused with a logged
//! error and never applied: the run finishes `ok` with probes byte-identical to the same run undisturbed, and the
//! logs show the refusals. (The decoder itself is fuzzed over random bytes in `proto/tests`.)

mod common;

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::*;
use cosim_proto::envelope::Envelope;
use cosim_proto::keys::{key, topic};
use cosim_proto::messages::{Correction, NodeError, StepCommand};
use zenoh::Wait;

const LIMIT: Duration = Duration::from_secs(180);
const SETS: [&str; 4] = ["--set", "fluid.spacing=0.004", "--set", "run.end_time=0.2"];

/// Deterministic pseudo-random bytes (a 64-bit LCG; no dependency needed for noise).
fn noise(seed: u64, len: usize) -> Vec<u8> {
    let mut x = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    (0..len)
        .map(|_| {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (x >> 56) as u8
        })
        .collect()
}

/// The bad messages for one topic of run `run`: none of them may be taken in.
fn bad_messages(run: &str, seed: u64) -> Vec<Vec<u8>> {
    let command = StepCommand {
        dt: 1e-3,
        corrections: vec![Correction {
            id: 0,
            dx: [1.0, 1.0],
            dv: [100.0, 100.0],
            face: None,
        }],
        roi: None,
        want_interface: true,
        want_snapshot: false,
        stop: false,
    };
    let good = Envelope::new(run, 3, 0.0, command.clone()).encode();
    let mut version = good.clone();
    version[0] = 2;
    let mut trailing = good.clone();
    trailing.push(0);
    vec![
        noise(seed, 0),
        noise(seed + 1, 7),
        noise(seed + 2, 64),
        noise(seed + 3, 300),
        good[..good.len() - 1].to_vec(),
        good[..good.len() / 2].to_vec(),
        trailing,
        version,
        // Well formed, but for another run.
        Envelope::new("intruder", 3, 0.0, command.clone()).encode(),
        Envelope::new(
            "intruder",
            0,
            0.0,
            NodeError {
                status: "failed".into(),
                message: "not yours".into(),
            },
        )
        .encode(),
        // Well formed, this run, a step long gone (and a command, not the topic's type, on state topics).
        Envelope::new(run, 1_000_000, 0.0, command).encode(),
    ]
}

fn probes(out: &Path) -> Vec<u8> {
    let bytes = std::fs::read(out.join("probes.csv")).unwrap();
    assert!(bytes.len() > 100);
    bytes
}

#[test]
fn bad_messages_on_every_topic_are_refused_and_change_nothing() {
    let dir = scratch("wire");
    let (out, reference) = (dir.join("out"), dir.join("reference"));
    let id = run_id("wire");
    let mut run = Kill(
        Command::new(cosim())
            .current_dir(root())
            .env("COSIM_BIN_DIR", bin_dir())
            .args(["run", "scenes/elastic_gate.toml", "--quiet", "--run-id", &id, "--out"])
            .arg(&out)
            .args(SETS)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(std::fs::File::create(dir.join("stderr.txt")).unwrap())
            .spawn()
            .unwrap(),
    );
    let started = Instant::now();
    let registry = std::env::temp_dir().join("cosim-runs").join(format!("{id}.json"));
    while !registry.exists() {
        assert!(run.0.try_wait().unwrap().is_none(), "the run ended early");
        assert!(started.elapsed() < LIMIT, "the run did not start");
        std::thread::sleep(Duration::from_millis(20));
    }
    let endpoint = json(&registry)["connect"].as_str().unwrap().to_string();
    // Joins like `cosim inspect`: listening, so that the nodes connect to it too and hear what it publishes.
    let (session, _) =
        cosim_bus::session::open_listening(&["tcp/0.0.0.0:0".to_string()], &[endpoint], 5000).expect("join the run");
    std::thread::sleep(Duration::from_millis(1000));
    let topics = [
        topic::BROKER_FEM,
        topic::BROKER_SPH,
        topic::FEM_STATE,
        topic::SPH_STATE,
        topic::FEM_MESH,
        topic::SPH_SETUP,
        topic::FEM_ERROR,
        topic::SPH_ERROR,
    ];
    let mut sent = 0;
    for round in 0..3u64 {
        for (k, t) in topics.iter().enumerate() {
            for m in bad_messages(&id, 100 * round + 10 * k as u64) {
                session.put(key(&id, t), m).wait().unwrap();
                sent += 1;
            }
        }
        std::thread::sleep(Duration::from_millis(300));
    }
    let status = wait_exit(&mut run.0, started + LIMIT, "the disturbed run");
    drop(session);
    let stderr = std::fs::read_to_string(dir.join("stderr.txt")).unwrap();
    assert!(status.success(), "the run failed: {stderr}");
    let summary = json(&out.join("summary.json"));
    assert_eq!(summary["status"], "ok");

    // Every process refused what it got, and said so in its log.
    let log = |name: &str| std::fs::read_to_string(out.join("logs").join(format!("{name}.log"))).unwrap();
    assert!(log("fem-node").contains("refused a command"), "{}", log("fem-node"));
    assert!(log("sph-node").contains("refused a command"), "{}", log("sph-node"));
    assert!(
        log("contact-broker").contains("refused a state message"),
        "{}",
        log("contact-broker")
    );
    eprintln!(
        "{sent} bad messages sent; refusals logged: fem-node {}, sph-node {}, contact-broker {}",
        log("fem-node").matches("refused").count(),
        log("sph-node").matches("refused").count(),
        log("contact-broker").matches("refused").count()
    );

    // And nothing changed: the same run in one process, undisturbed, gives the same probes.
    let mut args = vec!["run", "scenes/elastic_gate.toml", "--quiet", "--in-process", "--out"];
    args.push(reference.to_str().unwrap());
    args.extend_from_slice(&SETS);
    let alone = run_bounded(
        Command::new(cosim())
            .current_dir(root())
            .env("COSIM_BIN_DIR", bin_dir())
            .args(&args),
        LIMIT,
    );
    assert!(alone.status.success(), "{}", String::from_utf8_lossy(&alone.stderr));
    assert!(probes(&out) == probes(&reference), "the disturbed run's probes differ");
}
