//! `cosim replay TRACE --node fem|sph`: one node run again alone on the messages of a recorded run
//! (`cosim run --record`, `docs/PROTOCOL.md` §10). This process plays the broker: it serves the recorded scene and
//! restore reply on a fresh run id over loopback, starts the node (the built-in program, or `--exec`), sends it the
//! recorded commands in order, and compares each answer with the recorded one (`diff`). The first divergence is
//! named with its step, message, field, index and both values (exit 1); otherwise one line, "matched N steps".

use std::os::unix::process::CommandExt;
use std::path::Path;
use std::process::{Child, Command, ExitCode, Stdio};
use std::time::{Duration, Instant};

use anyhow::Context;
use cosim_proto::envelope::Envelope;
use cosim_proto::keys::{self, key, topic, NodeTopics};
use cosim_proto::messages::{FemMesh, FemState, NodeError, SphSetup, SphState, StepCommand};
use cosim_proto::trace::RawEnvelope;
use zenoh::handlers::FifoChannelHandler;
use zenoh::pubsub::Subscriber;
use zenoh::qos::CongestionControl;
use zenoh::sample::Sample;
use zenoh::Wait;

use crate::cli::{ExternalNode, ReplayArgs};

pub mod diff;
pub mod script;

use diff::{Divergence, Tolerance};
use script::{Answer, Exchange, Script};

/// Kills the node when dropped, so no early return leaves it running: its whole process group, which it leads, so
/// that what an `--exec` script started goes with it (a wrapper's node outlived the replay, found 2026-12-06).
struct Node(Child);

impl Drop for Node {
    fn drop(&mut self) {
        let group = nix::unistd::Pid::from_raw(self.0.id() as i32);
        let _ = nix::sys::signal::killpg(group, nix::sys::signal::Signal::SIGKILL);
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

type Sub = Subscriber<FifoChannelHandler<Sample>>;

fn zerr(e: zenoh::Error) -> anyhow::Error {
    anyhow::anyhow!("{e}")
}

/// How the replay ended short of "matched": the line to print.
struct Failed(String);

/// Run `cosim replay`. `Err` for bad input (exit 2); a divergence or a node that fails is exit 1.
pub fn replay(args: &ReplayArgs) -> anyhow::Result<ExitCode> {
    let tolerance = match (args.rtol, args.atol) {
        (None, None) => None,
        (r, a) => Some(Tolerance {
            rtol: r.unwrap_or(0.0),
            atol: a.unwrap_or(0.0),
        }),
    };
    if let Some(t) = tolerance {
        anyhow::ensure!(
            t.rtol >= 0.0 && t.atol >= 0.0 && t.rtol.is_finite() && t.atol.is_finite(),
            "--rtol and --atol must be finite and not negative, got {} and {}",
            cosim_proto::Num(t.rtol),
            cosim_proto::Num(t.atol)
        );
    }
    anyhow::ensure!(
        args.timeout.is_finite() && args.timeout > 0.0,
        "--timeout must be a positive number of seconds, got {}",
        cosim_proto::Num(args.timeout)
    );
    let script = script::read(&args.trace, args.node)?;
    if let Some(torn) = &script.torn {
        eprintln!(
            "cosim replay: {} stops before its end ({torn}): what comes before is replayed",
            script.path.display()
        );
    }
    let run = keys::fresh_run_id();
    let log = args
        .log
        .clone()
        .unwrap_or_else(|| std::env::temp_dir().join(format!("cosim-replay-{run}.log")));
    let player = Player::open(args, &run, &script, &log)?;
    match player.play(&script, tolerance) {
        Ok(steps) => {
            println!(
                "matched {steps} steps ({}, {})",
                args.node.program(),
                script.path.display()
            );
            Ok(ExitCode::SUCCESS)
        }
        Err(Failed(line)) => {
            eprintln!("cosim replay: {line} (node log: {})", log.display());
            Ok(ExitCode::from(1))
        }
    }
}

/// The broker's side of the replay: the session, what the node asks for, and the node itself.
struct Player {
    run: String,
    topics: NodeTopics,
    node_kind: ExternalNode,
    timeout: Duration,
    setup: Sub,
    state: Sub,
    error: Sub,
    command: zenoh::pubsub::Publisher<'static>,
    log: std::path::PathBuf,
    // Held for as long as the replay runs: the node asks them once, or watches them.
    _held: (
        zenoh::query::Queryable<()>,
        zenoh::query::Queryable<()>,
        zenoh::liveliness::LivelinessToken,
    ),
    node: Node,
    _session: zenoh::Session,
}

impl Player {
    /// Open a session on a free loopback port, answer the scene and restore queries with the recorded ones, and
    /// start the node on it.
    fn open(args: &ReplayArgs, run: &str, script: &Script, log: &Path) -> anyhow::Result<Self> {
        let topics = match args.node {
            ExternalNode::Fem => keys::FEM,
            ExternalNode::Sph => keys::SPH,
        };
        let (session, endpoints) = cosim_bus::session::open_listening(&["tcp/127.0.0.1:0".into()], &[], 5000)
            .context("cannot open a zenoh session on loopback")?;
        let endpoint = endpoints
            .first()
            .cloned()
            .ok_or_else(|| anyhow::anyhow!("the session listens on no endpoint"))?;
        let sub = |t: &str| session.declare_subscriber(key(run, t)).wait().map_err(zerr);
        let (setup, state, error) = (sub(topics.setup)?, sub(topics.state)?, sub(topics.error)?);
        let scene = contact_broker::transport::serve_scene(&session, run, script.scene.clone())?;
        let restore_bytes = match &script.restore {
            Some(bytes) => RawEnvelope::split(bytes)
                .ok_or_else(|| anyhow::anyhow!("{}: the restore record is not an envelope", script.path.display()))?
                .for_run(run),
            None => contact_broker::checkpoint::restore_reply::restore_reply(run, topics, None)?,
        };
        let restore = session
            .declare_queryable(key(run, topics.restore))
            .callback(move |query| {
                let _ = query.reply(query.key_expr().clone(), restore_bytes.clone()).wait();
            })
            .wait()
            .map_err(zerr)?;
        // The node leaves when this token goes, as it leaves when its broker goes.
        let alive = session
            .liveliness()
            .declare_token(key(run, topic::BROKER_ALIVE))
            .wait()
            .map_err(zerr)?;
        let command = session
            .declare_publisher(key(run, topics.command))
            .congestion_control(CongestionControl::Block)
            .express(true)
            .wait()
            .map_err(zerr)?;
        let node = spawn(args, run, &endpoint, log)?;
        Ok(Self {
            run: run.into(),
            topics,
            node_kind: args.node,
            timeout: cosim_bus::seconds::wait(args.timeout),
            setup,
            state,
            error,
            command,
            log: log.to_path_buf(),
            _held: (scene, restore, alive),
            node: Node(node),
            _session: session,
        })
    }

    /// Registration, then every command with a recorded answer: the number of answers that matched.
    fn play(mut self, script: &Script, tol: Option<Tolerance>) -> Result<u64, Failed> {
        let setup = self.registration()?;
        let what = self.topics.setup;
        let d = match self.node_kind {
            ExternalNode::Fem => diff::compare::<FemMesh>(what, &script.setup, &setup, tol, |_| {}),
            ExternalNode::Sph => diff::compare::<SphSetup>(what, &script.setup, &setup, tol, |_| {}),
        };
        self.judge(d, 0, what)?;
        let mut matched = 0;
        let mut last: Option<&Exchange> = None;
        for x in &script.exchanges {
            if !x.stop && x.answer.is_none() {
                break;
            }
            let raw = RawEnvelope::split(&x.command)
                .ok_or_else(|| Failed(format!("step {}: the recorded command is not an envelope", x.step)))?;
            self.send(raw.for_run(&self.run), x.step)?;
            last = Some(x);
            if x.stop {
                return self.wait_exit().map(|()| matched);
            }
            let answer = self.answer(x.step)?;
            self.compare(x, &answer, tol)?;
            matched += 1;
        }
        // The trace ends without the stop (a run cut short): the node is told to stop as a finished run would.
        if let Some(x) = last {
            let t = RawEnvelope::split(&x.command).map_or(0.0, |e| e.t);
            let stop = StepCommand::bare_stop();
            let _ = self.send(Envelope::new(&self.run, x.step + 1, t, stop).encode(), x.step + 1);
            let _ = self.wait_exit();
        }
        Ok(matched)
    }

    fn send(&self, bytes: Vec<u8>, step: u64) -> Result<(), Failed> {
        self.command
            .put(bytes)
            .wait()
            .map_err(|e| Failed(format!("cannot send the command of step {step}: {e}")))
    }

    /// The node's answer to step `step`: its state or its error report.
    fn answer(&mut self, step: u64) -> Result<Answer, Failed> {
        let deadline = Instant::now() + self.timeout;
        loop {
            if let Ok(Some(sample)) = self.error.try_recv() {
                return Ok(Answer::Error(sample.payload().to_bytes().into_owned()));
            }
            if let Ok(Some(sample)) = self.state.recv_timeout(Duration::from_millis(50)) {
                let bytes = sample.payload().to_bytes().into_owned();
                // An earlier step's answer again is dropped; anything else is compared (and named if wrong).
                if RawEnvelope::split(&bytes).is_none_or(|e| e.step >= step) {
                    return Ok(Answer::State(bytes));
                }
            }
            self.check_alive(&format!("its answer to step {step}"))?;
            if Instant::now() > deadline {
                return Err(Failed(format!(
                    "step {step}: no answer from {} within {:.0} s",
                    self.topics.name,
                    self.timeout.as_secs_f64()
                )));
            }
        }
    }

    /// The node's registration, within the timeout.
    fn registration(&mut self) -> Result<Vec<u8>, Failed> {
        let what = "its registration";
        let deadline = Instant::now() + self.timeout;
        loop {
            if let Ok(Some(sample)) = self.setup.recv_timeout(Duration::from_millis(50)) {
                return Ok(sample.payload().to_bytes().into_owned());
            }
            if let Ok(Some(sample)) = self.error.try_recv() {
                let why = Envelope::<NodeError>::decode(&sample.payload().to_bytes(), &self.run, self.topics.error)
                    .map_or_else(|e| e.to_string(), |e| cosim_proto::one_line(&e.body.message));
                return Err(Failed(format!("{} failed before {what}: {why}", self.topics.name)));
            }
            self.check_alive(what)?;
            if Instant::now() > deadline {
                return Err(Failed(format!(
                    "{} sent no registration within {:.0} s",
                    self.topics.name,
                    self.timeout.as_secs_f64()
                )));
            }
        }
    }

    fn check_alive(&mut self, what: &str) -> Result<(), Failed> {
        match self.node.0.try_wait() {
            Ok(Some(status)) => Err(Failed(format!(
                "{} exited ({status}) before {what}: {}",
                self.topics.name,
                crate::child_log::last_line(&self.log)
            ))),
            _ => Ok(()),
        }
    }

    fn wait_exit(&mut self) -> Result<(), Failed> {
        let deadline = Instant::now() + self.timeout.min(Duration::from_secs(10));
        while Instant::now() < deadline {
            if let Ok(Some(_)) = self.node.0.try_wait() {
                return Ok(());
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        Err(Failed(format!(
            "{} did not exit after the stop command",
            self.topics.name
        )))
    }

    fn compare(&self, x: &Exchange, got: &Answer, tol: Option<Tolerance>) -> Result<(), Failed> {
        let (error, state) = (self.topics.error, self.topics.state);
        // The one field the comparison leaves out is checked as a live run checks it (docs/PROTOCOL.md §7): a node
        // answering compute_seconds = NaN "matched" every step, where the broker would have refused it.
        if let Answer::State(rep) = got {
            let seconds = |rep: &[u8]| {
                let run = RawEnvelope::split(rep)?.run;
                match self.node_kind {
                    ExternalNode::Fem => Envelope::<FemState>::decode(rep, run, state)
                        .ok()
                        .map(|e| e.body.compute_seconds),
                    ExternalNode::Sph => Envelope::<SphState>::decode(rep, run, state)
                        .ok()
                        .map(|e| e.body.compute_seconds),
                }
            };
            if let Some(s) = seconds(rep).filter(|s| !(0.0..=1e9).contains(s)) {
                return Err(Failed(format!(
                    "step {}: {} answered {state} compute_seconds = {}: must be a number of seconds within 0…1e9",
                    x.step,
                    self.topics.name,
                    cosim_proto::Num(s)
                )));
            }
        }
        let d = match (x.answer.as_ref(), got) {
            (Some(Answer::State(rec)), Answer::State(rep)) => match self.node_kind {
                ExternalNode::Fem => diff::compare::<FemState>(state, rec, rep, tol, |s| s.compute_seconds = 0.0),
                ExternalNode::Sph => diff::compare::<SphState>(state, rec, rep, tol, |s| s.compute_seconds = 0.0),
            },
            (Some(Answer::Error(rec)), Answer::Error(rep)) => diff::compare::<NodeError>(error, rec, rep, None, |_| {}),
            (Some(Answer::State(_)), Answer::Error(rep)) => {
                let why = Envelope::<NodeError>::decode(rep, &self.run, error)
                    .map_or_else(|e| e.to_string(), |e| cosim_proto::one_line(&e.body.message));
                return Err(Failed(format!(
                    "step {}: {} failed where the recorded node answered: {why}",
                    x.step, self.topics.name
                )));
            }
            (Some(Answer::Error(_)), Answer::State(_)) => {
                return Err(Failed(format!(
                    "step {}: {} answered where the recorded node failed",
                    x.step, self.topics.name
                )))
            }
            (None, _) => Ok(None),
        };
        let what = match got {
            Answer::State(_) => state,
            Answer::Error(_) => error,
        };
        self.judge(d, x.step, what)
    }

    fn judge(&self, d: anyhow::Result<Option<Divergence>>, step: u64, what: &str) -> Result<(), Failed> {
        match d {
            Ok(None) => Ok(()),
            Ok(Some(d)) => Err(Failed(format!("divergence at step {step}, message {what}, {d}"))),
            Err(e) => Err(Failed(format!("step {step}: {what}: {e:#}"))),
        }
    }
}

/// Start the node: the built-in program, or `--exec COMMAND` through `sh`; `--run ID --connect ENDPOINT` appended.
fn spawn(args: &ReplayArgs, run: &str, endpoint: &str, log: &Path) -> anyhow::Result<Child> {
    let mut cmd = match &args.exec {
        Some(line) => {
            let mut c = Command::new("sh");
            c.arg("-c").arg(exec_script(line)).arg("sh");
            c
        }
        None => Command::new(crate::launch::find_program(args.node.program())?),
    };
    let log_file = std::fs::File::create(log).with_context(|| format!("cannot create {}", log.display()))?;
    cmd.args(["--run", run, "--connect", endpoint])
        .process_group(0)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(log_file)
        .spawn()
        .with_context(|| format!("cannot start {}", args.exec.as_deref().unwrap_or(args.node.program())))
}

/// What `sh -c` runs for `--exec COMMAND`, the arguments given after it as `"$@"`: `COMMAND "$@"`, so they go to its
/// last simple command, and a compound line runs as the shell runs it (`cd dir && ./node` starts `./node --run …` in
/// `dir`). It was `exec COMMAND "$@"`, which made that line `exec cd dir && …`: `exec cd` failed and the node never
/// started (found 2026-12-06 by the sweep of hostile external nodes, D25). Without `exec` the shell may stay as the
/// node's parent; the node leads its process group either way, which the replay ends whole ([`Node`]).
fn exec_script(line: &str) -> String {
    format!("{line} \"$@\"")
}
