//! A message lost on the way does not fail a run (`docs/PROTOCOL.md` §8): the broker sends a command again when
//! its answer has not come after a third of `coupling.step_timeout`, and a node answers a command it already
//! answered with the same answer, computing nothing.
//!
//! - `a_lost_command_is_sent_again`: `contact-broker` with a structure node written here (the `fem-node` core, its
//!   own zenoh loop) that drops the first delivery of the command of step 3: the run finishes `ok`, its probes
//!   byte-identical to the same scene in one process.
//! - `a_node_answers_a_repeated_command_again`: a broker written here sends `fem-node` the command of step 0
//!   twice, and gets the same answer twice, byte for byte; the next step then runs as usual.
//! - `a_node_asks_again_while_nobody_answers_its_query`: a query that finds nobody to answer it yet ends at once
//!   in zenoh (a router that has not heard of the queryable, a link lost and restored): a broker written here
//!   declares the `restore` queryable only 0.5 s after `fem-node` got the scene, and the node still registers.

mod common;

use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use common::*;
use cosim_proto::envelope::Envelope;
use cosim_proto::keys::{key, topic};
use cosim_proto::messages::{FemMesh, FemState, NodeCheckpoint, StepCommand};
use fem_node::core::FemCore;
use zenoh::Wait;

const LIMIT: Duration = Duration::from_secs(60);

fn scene_path() -> String {
    root().join("scenes/csm3.toml").display().to_string()
}

fn session(listen: &[String], connect: &[String]) -> zenoh::Session {
    cosim_bus::session::open_session(listen, connect, 5000).expect("zenoh session")
}

/// The broker's liveliness token, held by a broker written in a test.
fn broker_token(s: &zenoh::Session, id: &str) -> zenoh::liveliness::LivelinessToken {
    s.liveliness()
        .declare_token(key(id, topic::BROKER_ALIVE))
        .wait()
        .unwrap()
}

/// Answer the structure node's `restore` query with "start from the scene", counting the queries in `asked`.
fn no_restart_state(s: &zenoh::Session, id: &str, asked: Arc<AtomicUsize>) -> zenoh::query::Queryable<()> {
    let run = id.to_string();
    s.declare_queryable(key(id, topic::FEM_RESTORE))
        .callback(move |q| {
            let none = NodeCheckpoint {
                node: "fem-node".into(),
                data: Vec::new(),
            };
            q.reply(q.key_expr().clone(), Envelope::new(&run, 0, 0.0, none).encode())
                .wait()
                .unwrap();
            asked.fetch_add(1, Ordering::SeqCst);
        })
        .wait()
        .unwrap()
}

/// `fem-node` joining run `id` at `endpoint`, its stderr to `stderr`.
fn fem_node(id: &str, endpoint: &str, stderr: Stdio) -> Kill {
    Kill(
        Command::new(program("fem-node"))
            .args(["--run", id, "--connect", endpoint])
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(stderr)
            .spawn()
            .unwrap(),
    )
}

#[test]
fn a_lost_command_is_sent_again() {
    let dir = scratch("resend-command");
    let (out, reference) = (dir.join("out"), dir.join("reference"));
    let id = run_id("resend");
    let sets = ["--set", "run.end_time=0.02", "--set", "coupling.step_timeout=1.5"];
    let mut broker = Kill(
        Command::new(program("contact-broker"))
            .args(["--run", &id, "--scene", &scene_path(), "--out"])
            .arg(&out)
            .args(sets)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(std::fs::File::create(dir.join("broker.log")).unwrap())
            .spawn()
            .unwrap(),
    );
    let mut lines = BufReader::new(broker.0.stdout.take().unwrap()).lines();
    let listening: serde_json::Value = serde_json::from_str(&lines.next().unwrap().unwrap()).unwrap();
    let endpoint = listening["endpoints"][0].as_str().unwrap().to_string();

    // The structure node, by hand: the protocol of §8 around the fem-node core.
    let s = session(&[], &[endpoint]);
    let commands = s.declare_subscriber(key(&id, topic::BROKER_FEM)).wait().unwrap();
    let states = s.declare_publisher(key(&id, topic::FEM_STATE)).wait().unwrap();
    let _alive = s.liveliness().declare_token(key(&id, topic::FEM_ALIVE)).wait().unwrap();
    let reply = s
        .get(key(&id, topic::SCENE))
        .timeout(LIMIT)
        .wait()
        .unwrap()
        .recv()
        .unwrap();
    let text = String::from_utf8(reply.result().unwrap().payload().to_bytes().into_owned()).unwrap();
    let scene = cosim_proto::scene::parse("(from the broker)", &text, &[]).unwrap();
    let mut core = FemCore::new(&scene).unwrap();
    let mesh: &FemMesh = core.mesh();
    s.put(
        key(&id, topic::FEM_MESH),
        Envelope::new(&id, 0, 0.0, mesh.clone()).encode(),
    )
    .wait()
    .unwrap();
    let (mut dropped, mut answered) = (0, 0);
    let started = Instant::now();
    loop {
        assert!(started.elapsed() < LIMIT, "the run did not end");
        let Some(sample) = commands.recv_timeout(Duration::from_millis(100)).unwrap() else {
            continue;
        };
        let env = Envelope::<StepCommand>::decode(&sample.payload().to_bytes(), &id, "command").unwrap();
        if env.step == 3 && dropped == 0 {
            dropped += 1;
            continue;
        }
        let Some(state) = core.handle(&env.body).unwrap() else {
            break;
        };
        let t = env.t + env.body.dt;
        states
            .put(Envelope::<FemState>::new(&id, env.step, t, state).encode())
            .wait()
            .unwrap();
        answered += 1;
    }
    let status = wait_exit(&mut broker.0, Instant::now() + LIMIT, "contact-broker");
    let log = std::fs::read_to_string(dir.join("broker.log")).unwrap();
    assert!(status.success(), "{log}");
    assert_eq!(dropped, 1);
    assert!(answered > 5);
    assert!(log.contains("sending the command again"), "{log}");
    assert_eq!(json(&out.join("summary.json"))["status"], "ok");

    let reference_s = reference.display().to_string();
    let done = cosim_run(
        &[
            &["run", &scene_path(), "--quiet", "--in-process", "--out", &reference_s][..],
            &sets[..],
        ]
        .concat(),
        LIMIT,
    );
    assert!(done.status.success());
    let probes = |d: &std::path::Path| std::fs::read(d.join("probes.csv")).unwrap();
    assert!(
        probes(&out) == probes(&reference),
        "the run with a lost command differs"
    );
}

#[test]
fn a_node_answers_a_repeated_command_again() {
    let id = run_id("reanswer");
    let port = free_port();
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let s = session(std::slice::from_ref(&endpoint), &[]);
    let scene = cosim_proto::scene::load(std::path::Path::new(&scene_path()), &[]).unwrap();
    let text = scene.scene.to_toml();
    let _scene = s
        .declare_queryable(key(&id, topic::SCENE))
        .callback(move |q| {
            q.reply(q.key_expr().clone(), text.clone()).wait().unwrap();
        })
        .wait()
        .unwrap();
    let _restore = no_restart_state(&s, &id, Arc::default());
    let _alive = broker_token(&s, &id);
    let mesh = s.declare_subscriber(key(&id, topic::FEM_MESH)).wait().unwrap();
    let states = s.declare_subscriber(key(&id, topic::FEM_STATE)).wait().unwrap();
    let mut node = fem_node(&id, &endpoint, Stdio::null());
    mesh.recv_timeout(LIMIT).unwrap().expect("the node registers");
    let command = |step: u64, t: f64, dt: f64, stop: bool| {
        let body = StepCommand {
            dt,
            corrections: Vec::new(),
            roi: None,
            want_interface: false,
            want_snapshot: true,
            stop,
        };
        Envelope::new(&id, step, t, body).encode()
    };
    let answer = || {
        states
            .recv_timeout(LIMIT)
            .unwrap()
            .expect("an answer")
            .payload()
            .to_bytes()
            .into_owned()
    };
    let first = command(0, 0.0, 1e-3, false);
    s.put(key(&id, topic::BROKER_FEM), first.clone()).wait().unwrap();
    let a = answer();
    s.put(key(&id, topic::BROKER_FEM), first).wait().unwrap();
    let b = answer();
    assert!(a == b, "the same command, the same answer");
    let decoded = Envelope::<FemState>::decode(&a, &id, "state").unwrap();
    assert_eq!(decoded.step, 0);
    // The repeat computed nothing: step 1 starts from where step 0 ended, 1 ms in.
    s.put(key(&id, topic::BROKER_FEM), command(1, 1e-3, 1e-3, false))
        .wait()
        .unwrap();
    let c = Envelope::<FemState>::decode(&answer(), &id, "state").unwrap();
    assert_eq!(c.step, 1);
    assert_eq!(c.t, 2e-3, "one step of 1 ms after the first");
    s.put(key(&id, topic::BROKER_FEM), command(2, 2e-3, 0.0, true))
        .wait()
        .unwrap();
    let status = wait_exit(&mut node.0, Instant::now() + LIMIT, "fem-node");
    assert!(status.success());
    assert!(states.try_recv().unwrap().is_none(), "nothing after the stop");
}

#[test]
fn a_node_asks_again_while_nobody_answers_its_query() {
    let id = run_id("ask-again");
    let endpoint = format!("tcp/127.0.0.1:{}", free_port());
    let s = session(std::slice::from_ref(&endpoint), &[]);
    let text = cosim_proto::scene::load(std::path::Path::new(&scene_path()), &[])
        .unwrap()
        .scene
        .to_toml();
    let scenes_served = Arc::new(AtomicUsize::new(0));
    let served = scenes_served.clone();
    let _scene = s
        .declare_queryable(key(&id, topic::SCENE))
        .callback(move |q| {
            q.reply(q.key_expr().clone(), text.clone()).wait().unwrap();
            served.fetch_add(1, Ordering::SeqCst);
        })
        .wait()
        .unwrap();
    let _alive = broker_token(&s, &id);
    let mesh = s.declare_subscriber(key(&id, topic::FEM_MESH)).wait().unwrap();
    let mut node = fem_node(&id, &endpoint, Stdio::piped());
    let started = Instant::now();
    while scenes_served.load(Ordering::SeqCst) == 0 {
        assert!(started.elapsed() < LIMIT, "the node never asked for the scene");
        std::thread::sleep(Duration::from_millis(10));
    }
    // The node asks for its restart state right after the scene, and finds nobody to answer.
    std::thread::sleep(Duration::from_millis(500));
    assert!(
        node.0.try_wait().unwrap().is_none(),
        "the node gave up on a query nobody could answer yet"
    );
    let asked = Arc::new(AtomicUsize::new(0));
    let _restore = no_restart_state(&s, &id, asked.clone());
    let registered = mesh.recv_timeout(LIMIT).unwrap();
    if registered.is_none() {
        node.0.kill().unwrap();
        let mut log = String::new();
        std::io::Read::read_to_string(&mut node.0.stderr.take().unwrap(), &mut log).unwrap();
        panic!("the node did not register: {log}");
    }
    assert_eq!(
        asked.load(Ordering::SeqCst),
        1,
        "one answered query for the restart state"
    );
    let stop = StepCommand::bare_stop();
    s.put(key(&id, topic::BROKER_FEM), Envelope::new(&id, 0, 0.0, stop).encode())
        .wait()
        .unwrap();
    let status = wait_exit(&mut node.0, Instant::now() + LIMIT, "fem-node");
    assert!(status.success());
}
