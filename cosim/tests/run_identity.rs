//! A run id claims its key space (`docs/PROTOCOL.md` §2, `cosim_bus::claim`). Through one zenoh router (`cosim
//! router` on loopback, multicast scouting off), a run is going on; a second `cosim run` on the same `--run-id`, a
//! second `contact-broker` on it started by hand, and a second `fem-node` for it are each refused: exit code 2, one
//! line naming the run id, nothing written into their output folders. The first run finishes `ok` with the probes it
//! gives alone, byte for byte (before this, both runs ended `ok` with the same wrong probes). A node that finds its
//! run served by two brokers (two runs on one id that started at the same moment) refuses to join either; and a
//! registration that is refused is reported with its reason (`transport.rs`, `ZenohLink::register`).

mod common;

use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use common::*;
use cosim_proto::envelope::Envelope;
use cosim_proto::keys::{key, topic};
use cosim_proto::messages::SphSetup;
use zenoh::Wait;

/// Longest a run may take.
const LIMIT: Duration = Duration::from_secs(180);
/// Longest a refused process may take to say so.
const REFUSE_LIMIT: Duration = Duration::from_secs(30);
/// The structure alone, long enough (a few seconds through the router) for the refusals to happen while it runs.
const SCENE: &str = "scenes/csm3.toml";
const END: &str = "run.end_time=6.0";

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// Assert that `output` is a refusal of run `id`: exit code 2, and its last line on stderr (the only one but for
/// zenoh's own warnings) names the run id and `what`.
fn assert_refused(output: &Output, id: &str, what: &str) {
    let text = stderr(output);
    assert_eq!(output.status.code(), Some(2), "{what}: {text}");
    let lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    let (last, before) = lines.split_last().unwrap_or((&"", &[]));
    assert!(
        before.iter().all(|l| l.contains("WARN") && l.contains("zenoh")),
        "{what}: one line expected: {text}"
    );
    assert!(
        last.contains(&format!("run `{id}`")) && last.contains(what),
        "{what}: {text}"
    );
}

/// Probes of the scene run alone in one process: the reference of every run here.
fn alone(dir: &Path) -> Vec<u8> {
    let out = dir.join("alone");
    let run = run_bounded(
        Command::new(cosim())
            .current_dir(root())
            .args(["run", SCENE, "--quiet", "--set", END, "--in-process", "--out"])
            .arg(&out),
        LIMIT,
    );
    assert!(run.status.success(), "{}", stderr(&run));
    std::fs::read(out.join("probes.csv")).unwrap()
}

#[test]
fn a_live_run_id_refuses_a_second_broker_and_node_and_runs_on_undisturbed() {
    let dir = scratch("run-identity");
    let hub = format!("tcp/127.0.0.1:{}", free_port());
    let (_router, _) = start_router(&hub, None, &dir.join("router.stderr"));
    let id = run_id("identity");
    let (first, second, by_hand) = (dir.join("first"), dir.join("second"), dir.join("by_hand"));

    let mut run = Kill(
        Command::new(cosim())
            .current_dir(root())
            .env("COSIM_BIN_DIR", bin_dir())
            .args([
                "run",
                SCENE,
                "--quiet",
                "--set",
                END,
                "--connect",
                &hub,
                "--run-id",
                &id,
                "--out",
            ])
            .arg(&first)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(std::fs::File::create(dir.join("first.stderr")).unwrap())
            .spawn()
            .unwrap(),
    );
    wait_for_samples(&mut run.0, &first, 2, LIMIT);

    // A second `cosim run` on the id: refused before its output folder is touched.
    let out = run_bounded(
        Command::new(cosim())
            .current_dir(root())
            .env("COSIM_BIN_DIR", bin_dir())
            .args([
                "run",
                SCENE,
                "--quiet",
                "--set",
                END,
                "--connect",
                &hub,
                "--run-id",
                &id,
                "--out",
            ])
            .arg(&second),
        REFUSE_LIMIT,
    );
    assert_refused(&out, &id, "already has a live contact-broker");
    assert!(!second.exists(), "the refused run wrote {}", second.display());

    // A broker started by hand on it (as a second `cosim run` would start it): the same, in its own words.
    let out = run_bounded(
        Command::new(program("contact-broker"))
            .current_dir(root())
            .args([
                "--run",
                &id,
                "--scene",
                SCENE,
                "--set",
                END,
                "--connect",
                &hub,
                "--client",
                "--out",
            ])
            .arg(&by_hand),
        REFUSE_LIMIT,
    );
    assert_refused(&out, &id, "contact-broker: run");
    assert!(!by_hand.exists(), "the refused broker wrote {}", by_hand.display());

    // A second structure node for the run.
    let out = run_bounded(
        Command::new(program("fem-node")).args(["--run", &id, "--connect", &hub, "--client"]),
        REFUSE_LIMIT,
    );
    assert_refused(&out, &id, "already has a live fem-node");

    // All of that while the first run went on.
    assert!(
        run.0.try_wait().unwrap().is_none(),
        "the first run ended before the checks were done: make it longer"
    );
    let status = wait_exit(&mut run.0, Instant::now() + LIMIT, "the first run");
    let said = std::fs::read_to_string(dir.join("first.stderr")).unwrap_or_default();
    assert!(status.success(), "the first run failed: {said}");
    assert_eq!(json(&first.join("summary.json"))["status"], "ok");

    // The same run alone, in one process: the same probes, byte for byte.
    let probes = std::fs::read(first.join("probes.csv")).unwrap();
    assert!(probes.len() > 1000);
    assert!(
        probes == alone(&dir),
        "the first run's probes differ from its run alone"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_node_is_refused_by_a_run_under_way_in_peer_mode() {
    // Peer to peer (no router): a peer answers for its own liveliness tokens only, so the second node cannot see
    // the first one's; the broker's status says that the run no longer waits for nodes.
    let dir = scratch("run-identity-peer");
    let id = run_id("identity-peer");
    let first = dir.join("first");
    let mut run = Kill(
        Command::new(cosim())
            .current_dir(root())
            .env("COSIM_BIN_DIR", bin_dir())
            .args(["run", SCENE, "--quiet", "--set", END, "--run-id", &id, "--out"])
            .arg(&first)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(std::fs::File::create(dir.join("first.stderr")).unwrap())
            .spawn()
            .unwrap(),
    );
    wait_for_samples(&mut run.0, &first, 2, LIMIT);
    // Where `cosim inspect` finds the run: the broker's endpoint.
    let registry = std::env::temp_dir().join("cosim-runs").join(format!("{id}.json"));
    let endpoint = json(&registry)["connect"].as_str().unwrap().to_string();
    let out = run_bounded(
        Command::new(program("fem-node")).args(["--run", &id, "--connect", &endpoint]),
        REFUSE_LIMIT,
    );
    assert_refused(&out, &id, "is under way already");
    assert!(
        run.0.try_wait().unwrap().is_none(),
        "the run ended before the check was done: make it longer"
    );
    let status = wait_exit(&mut run.0, Instant::now() + LIMIT, "the run");
    let said = std::fs::read_to_string(dir.join("first.stderr")).unwrap_or_default();
    assert!(status.success(), "the run failed: {said}");
    assert!(
        std::fs::read(first.join("probes.csv")).unwrap() == alone(&dir),
        "the run's probes differ from its run alone"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_node_refuses_a_run_served_by_two_brokers() {
    let dir = scratch("two-brokers");
    let hub = format!("tcp/127.0.0.1:{}", free_port());
    let (_router, _) = start_router(&hub, None, &dir.join("router.stderr"));
    let id = run_id("two-brokers");
    // Two answers to the run's scene, as two brokers of one run id started at the same moment would give.
    let session = cosim_bus::session::open_client(std::slice::from_ref(&hub), 5000).expect("join the router");
    let scene = std::fs::read_to_string(root().join(SCENE)).unwrap();
    let queryables: Vec<_> = (0..2)
        .map(|_| {
            let scene = scene.clone();
            session
                .declare_queryable(key(&id, topic::SCENE))
                .callback(move |q| {
                    let _ = q.reply(q.key_expr().clone(), scene.clone()).wait();
                })
                .wait()
                .unwrap()
        })
        .collect();
    let out = run_bounded(
        Command::new(program("fem-node")).args(["--run", &id, "--connect", &hub, "--client"]),
        REFUSE_LIMIT,
    );
    assert_refused(&out, &id, "is served by 2 brokers");
    drop(queryables);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_refused_registration_is_reported_with_its_reason() {
    let dir = scratch("refused-registration");
    let out = dir.join("out");
    let id = run_id("refused-registration");
    // The fluid node is the outside program here; the test stands in for it and registers with another protocol
    // version, again and again, until the wait for it is over.
    let mut run = Kill(
        Command::new(cosim())
            .current_dir(root())
            .env("COSIM_BIN_DIR", bin_dir())
            .args([
                "run",
                "scenes/dam_break.toml",
                "--quiet",
                "--external",
                "sph",
                "--wait-external",
                "3",
            ])
            .args(["--run-id", &id, "--out"])
            .arg(&out)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(std::fs::File::create(dir.join("stderr")).unwrap())
            .spawn()
            .unwrap(),
    );
    let started = Instant::now();
    let external = out.join("external.json");
    while !external.is_file() {
        assert!(run.0.try_wait().unwrap().is_none(), "the run ended early");
        assert!(started.elapsed() < REFUSE_LIMIT, "the run did not start");
        std::thread::sleep(Duration::from_millis(20));
    }
    let connect = json(&external)["connect"].as_str().unwrap().to_string();
    let session = cosim_bus::session::open_session(&[], &[connect], 5000).expect("join the run");
    let setup = SphSetup {
        particles: 1,
        spacing: 0.01,
        h: 0.013,
        density: 1000.0,
        walls: Vec::new(),
        dt_stable: 1e-4,
        sensors: 0,
    };
    let mut bytes = Envelope::new(&id, 0, 0.0, setup).encode();
    bytes[0] = 7;
    let status = loop {
        if let Some(status) = run.0.try_wait().unwrap() {
            break status;
        }
        assert!(started.elapsed() < LIMIT, "the run did not end");
        let _ = session.put(key(&id, topic::SPH_SETUP), bytes.clone()).wait();
        std::thread::sleep(Duration::from_millis(50));
    };
    let said = std::fs::read_to_string(dir.join("stderr")).unwrap();
    assert_eq!(status.code(), Some(1), "{said}");
    let summary = json(&out.join("summary.json"));
    assert_eq!(summary["status"], "failed");
    let message = summary["message"].as_str().unwrap();
    for part in [
        "sph-node: did not register within 3 s",
        "refused: sph/setup message speaks protocol version 7",
    ] {
        assert!(message.contains(part), "summary message {message:?} lacks {part:?}");
        assert!(said.contains(part), "stderr {said:?} lacks {part:?}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
