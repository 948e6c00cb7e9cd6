//! Well-framed messages with inconsistent contents from a node in another process (`docs/PROTOCOL.md` §7
//! "Contents"): an outside program registers as the structure node with a mesh the broker cannot use. The broker
//! used to index it and panic (exit 101; the summary said only "contact-broker died"); it now ends the run `failed`
//! with one line naming the node, the message, the field, the index and the value, and writes `summary.json`.
//! The same checks on every message type, in-process and fuzzed, are in `contact-broker/tests/message_fuzz/`.

mod common;

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::*;
use cosim_proto::envelope::Envelope;
use cosim_proto::keys::{key, topic};
use cosim_proto::messages::{FemMesh, FemState, NodeCheckpoint, NodeError, StepCommand};
use fem_node::core::FemCore;
use zenoh::qos::CongestionControl;
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

/// The coarse hydrostatic plate with an outside structure node: `cosim run` waiting for it, and where to join.
struct Outside {
    run: Kill,
    /// The test's folder, kept while the run is.
    _dir: Scratch,
    out: std::path::PathBuf,
    id: String,
    endpoint: String,
    started: Instant,
    scene: cosim_proto::scene::LoadedScene,
}

fn outside(name: &str) -> Outside {
    outside_with(name, &[])
}

/// [`outside`] with more arguments to `cosim run`.
fn outside_with(name: &str, more: &[&str]) -> Outside {
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
            .args(more)
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
    Outside {
        run,
        _dir: dir,
        out,
        id,
        endpoint,
        started,
        scene,
    }
}

impl Outside {
    /// The run's exit status, its summary and the broker's log, once it ended.
    fn ended(mut self, status: std::process::ExitStatus) -> (std::process::ExitStatus, serde_json::Value, String) {
        let _ = self.run.0.wait();
        let log = std::fs::read_to_string(self.out.join("logs/contact-broker.log")).unwrap_or_default();
        (status, json(&self.out.join("summary.json")), log)
    }
}

/// Run the coarse hydrostatic plate with an outside structure node that registers `spoil(mesh)`; the run's exit
/// status, its summary and the broker's log.
fn run_with_mesh(name: &str, spoil: impl Fn(&mut FemMesh)) -> (std::process::ExitStatus, serde_json::Value, String) {
    let mut o = outside(name);
    let mut mesh = FemCore::new(&o.scene.scene).unwrap().mesh().clone();
    spoil(&mut mesh);
    let bytes = Envelope::new(&o.id, 0, 0.0, mesh).encode();
    let (session, _) = cosim_bus::session::open_listening(
        &["tcp/127.0.0.1:0".to_string()],
        std::slice::from_ref(&o.endpoint),
        5000,
    )
    .expect("join the run");
    // Registered once it arrives; sent again until the run ends, in case the first put beat the connection.
    let status = loop {
        session.put(key(&o.id, topic::FEM_MESH), bytes.clone()).wait().unwrap();
        if let Some(status) = o.run.0.try_wait().unwrap() {
            break status;
        }
        assert!(
            o.started.elapsed() < LIMIT,
            "the run did not end after an unusable registration"
        );
        std::thread::sleep(Duration::from_millis(200));
    };
    drop(session);
    o.ended(status)
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

/// An outside structure node that reports itself `unstable` on its error topic and then goes on answering, as a
/// node whose watchdog fires on another thread would (found 2026-12-06 by a sweep of hostile external nodes): the run
/// ended `ok`, exit 0, because the broker read the node's error topic only while it waited for an answer that did
/// not come. Now a failure reported before an answer ends the run with it, naming the node and its message.
/// An outside structure node that answers every command with the real solver, under the step number `tamper(step)`,
/// sends what `extra(session, run, step, t)` sends before each answer, and answers a checkpoint query with no bytes;
/// the run's exit status, summary and the broker's log once it ended.
fn answering(
    mut o: Outside,
    tamper: impl Fn(u64) -> u64,
    extra: impl Fn(&zenoh::Session, &str, u64, f64),
) -> (std::process::ExitStatus, serde_json::Value, String) {
    let mut core = FemCore::new(&o.scene.scene).unwrap();
    let mesh = Envelope::new(&o.id, 0, 0.0, core.mesh().clone()).encode();
    let (session, _) = cosim_bus::session::open_listening(
        &["tcp/127.0.0.1:0".to_string()],
        std::slice::from_ref(&o.endpoint),
        5000,
    )
    .expect("join the run");
    let _token = session
        .liveliness()
        .declare_token(key(&o.id, topic::FEM_ALIVE))
        .wait()
        .unwrap();
    let commands = session
        .declare_subscriber(key(&o.id, topic::BROKER_FEM))
        .wait()
        .unwrap();
    let checkpoints = session
        .declare_queryable(key(&o.id, topic::FEM_CHECKPOINT))
        .wait()
        .unwrap();
    let (mut registered, mut answered) = (false, (0u64, 0.0f64));
    let status = loop {
        while let Ok(Some(query)) = checkpoints.try_recv() {
            let empty = NodeCheckpoint {
                node: "fem-node".into(),
                data: Vec::new(),
            };
            let bytes = Envelope::new(&o.id, answered.0, answered.1, empty).encode();
            query.reply(query.key_expr().clone(), bytes).wait().unwrap();
        }
        if let Some(status) = o.run.0.try_wait().unwrap() {
            break status;
        }
        assert!(o.started.elapsed() < LIMIT, "the run did not end");
        if !registered {
            session.put(key(&o.id, topic::FEM_MESH), mesh.clone()).wait().unwrap();
        }
        let Ok(Some(sample)) = commands.recv_timeout(Duration::from_millis(200)) else {
            continue;
        };
        registered = true;
        let bytes = sample.payload().to_bytes();
        let Ok(cmd) = Envelope::<StepCommand>::decode(&bytes, &o.id, topic::BROKER_FEM) else {
            continue;
        };
        let (step, t) = (cmd.step, cmd.t);
        extra(&session, &o.id, step, t);
        if let Ok(Some(state)) = core.handle(&cmd.body) {
            let bytes = Envelope::new(&o.id, tamper(step), t, state).encode();
            session.put(key(&o.id, topic::FEM_STATE), bytes).wait().unwrap();
            answered = (step, t + cmd.body.dt);
        }
    };
    drop((commands, checkpoints));
    drop(session);
    o.ended(status)
}

/// An outside structure node that reports itself `unstable` on its error topic and then goes on answering, as a
/// node whose watchdog fires on another thread would (found 2026-12-06 by a sweep of hostile external nodes): the run
/// ended `ok`, exit 0, because the broker read the node's error topic only while it waited for an answer that did
/// not come. Now a failure reported before an answer ends the run with it, naming the node and its message.
#[test]
fn a_node_that_reports_a_failure_and_keeps_answering_ends_the_run() {
    let o = outside("bad_messages_error_then_answers");
    let report = |session: &zenoh::Session, id: &str, step: u64, t: f64| {
        if step == 2 {
            let report = NodeError {
                status: "unstable".into(),
                message: "the outside node's own check failed".into(),
            };
            let bytes = Envelope::new(id, step, t, report).encode();
            session.put(key(id, topic::FEM_ERROR), bytes).wait().unwrap();
        }
    };
    let (status, summary, _) = answering(o, |step| step, report);
    assert_eq!(status.code(), Some(1), "{summary}");
    assert_eq!(summary["status"], "unstable", "{summary}");
    let message = summary["message"].as_str().unwrap();
    assert!(
        message.contains("fem-node") && message.contains("the outside node's own check failed"),
        "{message}"
    );
    let steps = summary["steps"].as_u64().unwrap();
    assert!(steps < 10, "the run went on to its end: {steps} steps");
}

/// A node that numbers its answers one step behind from step 3 on is said to have answered an earlier step, not
/// to have sent nothing (found 2026-12-06: "no answer to step 3 within … s").
#[test]
fn answers_under_an_earlier_step_are_said_in_the_timeout() {
    let o = outside_with("bad_messages_one_behind", &["--set", "coupling.step_timeout=1.5"]);
    let (status, summary, _) = answering(o, |step| if step >= 3 { step - 1 } else { step }, |_, _, _, _| ());
    assert_eq!(status.code(), Some(1), "{summary}");
    let message = summary["message"].as_str().unwrap();
    assert!(
        message.contains(
            "fem-node: no answer to step 3 within 2 s (coupling.step_timeout); it answered step 2 \
                          instead, an earlier step's number"
        ),
        "{message}"
    );
}

/// SIGTERM to `cosim run` while it waits for an outside node that never comes ends the run at once, as between two
/// steps: `failed`, "interrupted (SIGINT or SIGTERM)", exit 1 (found 2026-12-06: the broker went on waiting, `cosim
/// run` killed it 10 s later, and the summary said "contact-broker died (signal 9); ").
#[test]
fn an_interrupt_while_a_node_is_awaited_ends_the_run_at_once() {
    let mut o = outside("bad_messages_interrupt_waiting");
    let pid = o.run.0.id().to_string();
    let sent = Instant::now();
    assert!(Command::new("kill").args(["-TERM", &pid]).status().unwrap().success());
    let status = loop {
        if let Some(status) = o.run.0.try_wait().unwrap() {
            break status;
        }
        assert!(sent.elapsed() < LIMIT, "the run did not end after SIGTERM");
        std::thread::sleep(Duration::from_millis(20));
    };
    let took = sent.elapsed().as_secs_f64();
    let (status, summary, _) = o.ended(status);
    assert_eq!(status.code(), Some(1), "{summary}");
    assert_eq!(summary["status"], "failed", "{summary}");
    let message = summary["message"].as_str().unwrap_or_default();
    assert!(
        message.contains("interrupted (SIGINT or SIGTERM), while waiting for fem-node to register"),
        "{message}"
    );
    assert!(took < 5.0, "ended {took:.1} s after SIGTERM");
}

/// A node of the run that answers a checkpoint query with no bytes is refused, naming it: empty bytes stand for "the
/// run has no such node" where a paused run's state is read, and `cosim snapshot` of a paused run whose outside
/// structure node did so wrote no structure frame, said "0 contact(s)" and exited 0 (found 2026-12-06).
#[test]
fn an_empty_checkpoint_from_a_node_of_the_run_is_refused() {
    let o = outside_with("bad_messages_empty_checkpoint", &["--break", "step=3"]);
    let (id, out) = (o.id.clone(), o.out.clone());
    let node = std::thread::spawn(move || answering(o, |step| step, |_, _, _, _| ()));
    let ctl = |args: &[&str]| {
        let mut cmd = Command::new(cosim());
        cmd.current_dir(root()).args(args);
        run_bounded(&mut cmd, Duration::from_secs(30))
    };
    let since = Instant::now();
    loop {
        let status = ctl(&["ctl", &id, "status"]);
        if String::from_utf8_lossy(&status.stdout).contains("paused at step 3") {
            break;
        }
        assert!(since.elapsed() < LIMIT, "the run did not pause");
        std::thread::sleep(Duration::from_millis(100));
    }
    let snap = ctl(&["snapshot", &id, "--out", out.join("snap").to_str().unwrap()]);
    let said = format!(
        "{}{}",
        String::from_utf8_lossy(&snap.stdout),
        String::from_utf8_lossy(&snap.stderr)
    );
    let _ = ctl(&["ctl", &id, "stop"]);
    let _ = node.join();
    assert_ne!(snap.status.code(), Some(0), "{said}");
    assert!(
        said.contains("fem-node: sent an empty fem/checkpoint: a node of the run saves its state"),
        "{said}"
    );
}

/// A node that floods the broker with well-framed states for a future step gets them refused and the run goes on,
/// its refusals logged in a few lines however many come: the first ten, then one at 100 and one at 1,000 with the
/// count (found 2026-12-06 by a sweep of hostile external nodes: 50,000 such messages wrote 7.4 MB of log, a line
/// each, none of it in the disk estimate).
#[test]
fn a_flood_of_refused_messages_is_logged_in_a_few_lines() {
    const FLOOD: usize = 1500;
    let o = outside("bad_messages_flood");
    let flood = |session: &zenoh::Session, id: &str, step: u64, t: f64| {
        if step == 2 {
            let future = FemState {
                ids: Vec::new(),
                x: Vec::new(),
                v: Vec::new(),
                substeps: 1,
                dt_stable: 1e-4,
                compute_seconds: 0.0,
                snapshot: None,
            };
            let bytes = Envelope::new(id, 1_000_000, t, future).encode();
            for _ in 0..FLOOD {
                session
                    .put(key(id, topic::FEM_STATE), bytes.clone())
                    .congestion_control(CongestionControl::Block)
                    .wait()
                    .unwrap();
            }
        }
    };
    let (status, summary, log) = answering(o, |step| step, flood);
    assert_eq!(status.code(), Some(0), "{summary}");
    assert_eq!(summary["status"], "ok", "{summary}");
    let lines: Vec<&str> = log.lines().filter(|l| l.contains("refused a state message")).collect();
    assert_eq!(lines.len(), 12, "{lines:#?}");
    assert!(
        lines[9].contains("(the 10th; from here on one line at 100, 1000, …)"),
        "{}",
        lines[9]
    );
    assert!(
        lines[11].contains("fem-node: refused a state message: 1000 so far, the last: "),
        "{}",
        lines[11]
    );
}
