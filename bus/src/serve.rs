//! The loop a solver node runs to serve a run (`docs/PROTOCOL.md` §8): join, fetch the scene, register, then
//! answer step commands until told to stop. Generic over the node, so the structure and fluid nodes (and any
//! future one) speak the protocol through the same code.

use std::collections::BTreeMap;
use std::time::Duration;

use anyhow::Context;
use cosim_proto::envelope::Envelope;
use cosim_proto::keys::{key, topic, NodeTopics};
use cosim_proto::messages::{NodeCheckpoint, NodeError, StepCommand};
use cosim_proto::run_status::RunStatus;
use cosim_proto::scene::Scene;
use serde::Serialize;
use zenoh::bytes::ZBytes;
use zenoh::qos::CongestionControl;
use zenoh::sample::SampleKind;
use zenoh::{Session, Wait};

use crate::status::{serve_status, Board};

/// Where to join.
#[derive(Clone, Debug)]
pub struct NodeOptions {
    /// Run id.
    pub run: String,
    /// Endpoints to connect to (the broker's, or a router's).
    pub connect: Vec<String>,
    /// Endpoints to listen on (usually none).
    pub listen: Vec<String>,
    /// Milliseconds to wait for a connection and for the scene.
    pub timeout_ms: u64,
    /// Join as a zenoh client through the router at `connect` (a run spread over hosts) instead of as a peer.
    pub client: bool,
    /// A zenoh config file the session starts from (`crate::session::base_config`).
    pub zenoh_config: Option<std::path::PathBuf>,
}

/// A node's failure: a numerical blow-up (`unstable`) or anything else.
#[derive(Debug)]
pub struct Failure {
    /// True for a numerical blow-up.
    pub unstable: bool,
    /// One line.
    pub message: String,
}

impl std::fmt::Display for Failure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Failure {}

/// A solver node as the serving loop sees it.
pub trait NodeCore {
    /// Registration message.
    type Setup: Serialize;
    /// Answer to a step.
    type State: Serialize;

    /// The registration message.
    fn setup(&self) -> &Self::Setup;

    /// Apply the command's corrections, advance, answer; `None` for a stop command.
    fn handle(&mut self, cmd: &StepCommand) -> Result<Option<Self::State>, Failure>;

    /// Sizes for the live status (particles, nodes, elements, …).
    fn counts(&self) -> Vec<(&'static str, u64)> {
        Vec::new()
    }

    /// Energies for the live status, name → J per unit thickness (the structure's kinetic, strain and potential,
    /// the fluid's kinetic and potential). Asked for at most a few times a second.
    fn energy(&self) -> Vec<(&'static str, f64)> {
        Vec::new()
    }

    /// The node's whole state between two steps, for a checkpoint (`docs/PROTOCOL.md` §9); `None` for a node
    /// that cannot save one.
    fn checkpoint(&self) -> Option<Vec<u8>> {
        None
    }

    /// The simulated time the node's state has reached [s]; `None` for a node that does not keep one.
    fn time(&self) -> Option<f64> {
        None
    }

    /// Continue from the bytes [`NodeCore::checkpoint`] gave, on a node built from the same scene.
    fn restore(&mut self, _data: &[u8]) -> Result<(), Failure> {
        Err(Failure {
            unstable: false,
            message: "this node cannot continue from a checkpoint".into(),
        })
    }
}

/// A restored state must be at the checkpoint's time, `t` [s]: within a millionth of `coupling.max_dt` (a node's
/// time sums its own steps, the broker's lands on the output times, so they differ in their last bits). A state
/// saved at another time continued from the wrong place and ended `ok` (found 2026-12-06: `broker.bin` shifted from
/// t = 0.01 to 0.0149 s with its checksum rewritten ran 0.0049 s short and said it reached its end).
pub fn check_restored_time(node: Option<f64>, t: f64, max_dt: f64) -> anyhow::Result<()> {
    match node {
        Some(node) if (node - t).abs() > 1e-6 * max_dt || node.is_nan() => anyhow::bail!(
            "cannot restart from the checkpoint: its state is at t = {} s, the checkpoint at t = {} s",
            cosim_proto::Num(node),
            cosim_proto::Num(t)
        ),
        _ => Ok(()),
    }
}

/// `core`'s counts as the live status and `summary.json` hold them (name → count).
pub fn counts_of<C: NodeCore + ?Sized>(core: &C) -> BTreeMap<String, u64> {
    core.counts().into_iter().map(|(k, v)| (k.to_string(), v)).collect()
}

/// How often the live status's energies are recomputed (they cost a pass over the particles or elements).
const ENERGY_EVERY: Duration = Duration::from_millis(500);

fn zerr(e: zenoh::Error) -> anyhow::Error {
    anyhow::anyhow!("{e}")
}

/// Join the run and serve it to the end. `build` makes the node from the scene the broker serves. Errors are
/// also published on the node's error topic so the broker can say why.
pub fn serve<C: NodeCore>(
    opts: &NodeOptions,
    topics: NodeTopics,
    build: impl FnOnce(&Scene) -> Result<C, Failure>,
) -> anyhow::Result<()> {
    let base = opts.zenoh_config.as_deref();
    let session = match opts.client {
        true => crate::session::open_client_from(base, &opts.connect, opts.timeout_ms),
        false => crate::session::open_session_from(base, &opts.listen, &opts.connect, opts.timeout_ms),
    }
    .with_context(|| format!("cannot connect to {}", opts.connect.join(", ")))?;
    let result = serve_open(&session, opts, topics, build);
    crate::session::close(&session);
    result
}

/// [`serve`] on an open session; every declaration on it is undone when this returns.
fn serve_open<C: NodeCore>(
    session: &Session,
    opts: &NodeOptions,
    topics: NodeTopics,
    build: impl FnOnce(&Scene) -> Result<C, Failure>,
) -> anyhow::Result<()> {
    let run = opts.run.as_str();
    // A run id claims its key space (`crate::claim`): a second node of this kind on a live run is refused before
    // it declares anything there, and reports nothing on the run's error topic (the run is fine without it).
    crate::claim::ensure_free(session, run, topics.alive, topics.name)?;
    crate::claim::ensure_not_started(session, run, topics.name)?;
    // Live status (`cosim inspect`), answered from the start; a failure is written on it before the exit.
    let board = Board::new(topics.name, run);
    let _status = serve_status(session, key(run, topics.status), board.clone())?;
    let errors = session
        .declare_publisher(key(run, topics.error))
        .congestion_control(CongestionControl::Block)
        .wait()
        .map_err(zerr)?;
    let reported = std::cell::Cell::new(false);
    let report = |status: RunStatus, message: String| {
        let body = NodeError {
            status: status.as_str().into(),
            message,
        };
        let _ = errors.put(Envelope::new(run, 0, 0.0, body).encode()).wait();
        reported.set(true);
    };
    let result = serve_session(session, opts, topics, build, &board, &report);
    board.update(|s| {
        s.health = if result.is_ok() { "finished" } else { "failed" }.into();
        if let Err(e) = &result {
            s.message = format!("{e:#}").replace('\n', " ");
        }
    });
    if let (Err(e), false) = (&result, reported.get()) {
        let unstable = e.downcast_ref::<Failure>().is_some_and(|f| f.unstable);
        report(
            if unstable {
                RunStatus::Unstable
            } else {
                RunStatus::Failed
            },
            format!("{e:#}").replace('\n', " "),
        );
        // Let the report leave before the session closes.
        std::thread::sleep(Duration::from_millis(100));
    }
    result
}

fn serve_session<C: NodeCore>(
    session: &Session,
    opts: &NodeOptions,
    topics: NodeTopics,
    build: impl FnOnce(&Scene) -> Result<C, Failure>,
    board: &Board,
    report: &dyn Fn(RunStatus, String),
) -> anyhow::Result<()> {
    let run = opts.run.as_str();
    // The command subscription exists before the node registers, so the first command cannot be missed.
    let commands = session
        .declare_subscriber(key(run, topics.command))
        .wait()
        .map_err(zerr)?;
    let broker_alive = session
        .liveliness()
        .declare_subscriber(key(run, topic::BROKER_ALIVE))
        .history(true)
        .wait()
        .map_err(zerr)?;
    let _alive = session
        .liveliness()
        .declare_token(key(run, topics.alive))
        .wait()
        .map_err(zerr)?;

    // The broker asks for this node's state between two steps when it writes a checkpoint.
    let checkpoints = session
        .declare_queryable(key(run, topics.checkpoint))
        .wait()
        .map_err(zerr)?;

    let timeout = Duration::from_millis(opts.timeout_ms);
    let scene_text = fetch_scene(session, run, timeout)?;
    let scene = cosim_proto::scene::parse("(scene from the broker)", &scene_text, &[])?;
    let mut core = build(&scene)?;
    // A restarted run: continue from the state the broker hands out, after the step it was saved at.
    let mut expected = 0u64;
    let mut refusals = crate::refusals::Refusals::new("refused a command");
    let mut t = 0.0;
    if let Some(saved) = fetch_restore(session, run, topics, timeout)? {
        core.restore(&saved.body.data)
            .map_err(|e| anyhow::anyhow!("cannot restart from the checkpoint: {e}"))?;
        check_restored_time(core.time(), saved.t, scene.coupling.max_dt)?;
        expected = saved.step + 1;
        t = saved.t;
        board.update(|s| {
            s.step = saved.step;
            s.t = saved.t;
        });
    }
    board.update(|s| s.counts = counts_of(&core));
    // Declared once the broker has answered the node's queries, and so once its declarations, which it makes
    // before it serves the scene, have come over the same link: the publisher starts out knowing the broker's
    // subscription.
    let state_pub = session
        .declare_publisher(key(run, topics.state))
        .congestion_control(CongestionControl::Block)
        .express(true)
        .wait()
        .map_err(zerr)?;
    // Every message is sized before it is sent: zenoh drops one over 1 GiB without a word (`MAX_SEND_BYTES`).
    let setup = Envelope::new(run, 0, 0.0, core.setup()).encode_checked(topics.setup)?;
    session
        .put(key(run, topics.setup), setup)
        .congestion_control(CongestionControl::Block)
        .wait()
        .map_err(zerr)?;

    let mut idle_since = std::time::Instant::now();
    let mut energy_at = idle_since.checked_sub(ENERGY_EVERY).unwrap_or(idle_since);
    // The last command answered and its answer, to answer it again if it comes again.
    let mut last: Option<(Vec<u8>, ZBytes)> = None;
    // Between two steps: the state after step `expected - 1`, before the corrections of the next.
    let answer_checkpoints = |core: &C, expected: u64, t: f64| {
        while let Ok(Some(query)) = checkpoints.try_recv() {
            let reply = match core.checkpoint() {
                Some(data) => {
                    let body = NodeCheckpoint {
                        node: topics.name.into(),
                        data,
                    };
                    match Envelope::new(run, expected.saturating_sub(1), t, body).encode_checked(topics.checkpoint) {
                        Ok(bytes) => query.reply(query.key_expr().clone(), bytes).wait(),
                        Err(e) => query.reply_err(e.to_string()).wait(),
                    }
                }
                None => query.reply_err("this node cannot save a checkpoint").wait(),
            };
            if let Err(e) = reply {
                tracing::error!("checkpoint query: {e}");
            }
        }
    };
    loop {
        answer_checkpoints(&core, expected, t);
        let Some(sample) = commands.recv_timeout(Duration::from_millis(50)).map_err(zerr)? else {
            while let Ok(Some(s)) = broker_alive.try_recv() {
                if s.kind() == SampleKind::Delete {
                    // A link lost and restored also takes the token away for a moment (`crate::link_loss`).
                    let broker = key(run, topic::BROKER_ALIVE);
                    let (back, after) = crate::link_loss::comes_back(session, &broker, crate::link_loss::GRACE);
                    if !back {
                        anyhow::bail!(
                            "the broker of run {run} went away (its liveliness token was gone for {:.1} s)",
                            after.as_secs_f64()
                        );
                    }
                    tracing::warn!(
                        "the broker's liveliness token was away for {:.2} s (a link lost and restored): going on",
                        after.as_secs_f64()
                    );
                }
            }
            continue;
        };
        let bytes = sample.payload().to_bytes();
        // The command just answered, again: the broker sends a command again when its answer does not come
        // (`docs/PROTOCOL.md` §8), so the answer may have been lost: send the same answer again, compute nothing.
        if let Some((command, state)) = &last {
            if command[..] == bytes[..] {
                tracing::warn!("the command for step {} came again: answering it again", expected - 1);
                // Through the session, not the publisher: seen once in CI (2026-12-01), a node's answers through its
                // publisher never reached the broker while its registration, put through the session, had.
                session
                    .put(key(run, topics.state), state.clone())
                    .congestion_control(CongestionControl::Block)
                    .express(true)
                    .wait()
                    .map_err(zerr)?;
                continue;
            }
        }
        let env = match Envelope::<StepCommand>::decode(&bytes, run, topics.command)
            .and_then(|e| e.expect_step(expected, topics.command))
        {
            Ok(env) => env,
            Err(e) => {
                // Refused, never applied (`docs/PROTOCOL.md` §7): logged, counted on the status, and the node
                // keeps its state and waits for the command it expects. Not reported as a failure: a stray
                // message must not end the run; a broker whose commands this node cannot read times out on it
                // and says so.
                refusals.note(&e);
                board.update(|s| {
                    let n = s.extra.get("refused").and_then(|v| v.as_u64()).unwrap_or(0) + 1;
                    s.extra.insert("refused".into(), n.into());
                    s.extra.insert("last_refused".into(), e.to_string().into());
                });
                continue;
            }
        };
        expected += 1;
        let dt = env.body.dt;
        let computing = std::time::Instant::now();
        let waited = (computing - idle_since).as_secs_f64();
        let state = match core.handle(&env.body) {
            Ok(Some(state)) => state,
            Ok(None) => return Ok(()),
            // A blow-up is reported at once, and the node stays to be looked at (`cosim run --break unstable`,
            // `docs/PROTOCOL.md` §11): it answers checkpoint queries with the state it blew up in until the broker
            // goes or says stop.
            Err(failure) if failure.unstable => {
                let message = format!("{failure:#}").replace('\n', " ");
                board.update(|s| {
                    s.health = "failed".into();
                    s.message = message.clone();
                });
                report(RunStatus::Unstable, message);
                loop {
                    answer_checkpoints(&core, expected, t);
                    if let Ok(Some(sample)) = commands.recv_timeout(Duration::from_millis(50)) {
                        let stop = Envelope::<StepCommand>::decode(&sample.payload().to_bytes(), run, topics.command)
                            .is_ok_and(|e| e.body.stop);
                        if stop {
                            break;
                        }
                    }
                    let gone = std::iter::from_fn(|| broker_alive.try_recv().ok().flatten())
                        .any(|s| s.kind() == SampleKind::Delete);
                    if gone {
                        break;
                    }
                }
                return Err(failure.into());
            }
            Err(failure) => return Err(failure.into()),
        };
        t = if dt > 0.0 { env.t + dt } else { t.max(env.t) };
        board.step(env.step, t, dt, computing.elapsed().as_secs_f64(), waited);
        // Counts that change during the run (the fluid's wall guard), before the answer: a status asked for after
        // it (the broker's, for the summary) has this step's.
        board.update(|s| s.counts = counts_of(&core));
        idle_since = std::time::Instant::now();
        // A shared buffer: keeping it to answer a repeat costs no copy.
        let answer = ZBytes::from(Envelope::new(run, env.step, t, state).encode_checked(topics.state)?);
        state_pub.put(answer.clone()).wait().map_err(zerr)?;
        last = Some((bytes.into_owned(), answer));
        // After the answer, off the step's critical path.
        if energy_at.elapsed() >= ENERGY_EVERY {
            let energy: serde_json::Map<String, serde_json::Value> = core
                .energy()
                .into_iter()
                .map(|(k, v)| (k.to_string(), v.into()))
                .collect();
            if !energy.is_empty() {
                board.update(|s| {
                    s.extra.insert("energy".into(), energy.into());
                });
            }
            energy_at = std::time::Instant::now();
        }
    }
}

/// The state to restart from, when the broker has one for this node (`docs/PROTOCOL.md` §9): `None` for a run
/// that starts from the scene. Asked again while nobody answers ([`crate::ask`]): the broker declares this
/// queryable after the scene's, and a link lost and restored takes it away for a moment.
fn fetch_restore(
    session: &Session,
    run: &str,
    topics: NodeTopics,
    timeout: Duration,
) -> anyhow::Result<Option<Envelope<NodeCheckpoint>>> {
    let answers = crate::ask::ask(session, &key(run, topics.restore), timeout).map_err(zerr)?;
    let Some(reply) = answers.into_iter().next() else {
        anyhow::bail!(
            "the broker of run {run} did not answer {} within {:.0} s",
            topics.restore,
            timeout.as_secs_f64()
        );
    };
    let sample = reply
        .result()
        .map_err(|e| anyhow::anyhow!("the broker refused the {} query: {e:?}", topics.restore))?;
    let env = Envelope::<NodeCheckpoint>::decode(&sample.payload().to_bytes(), run, topics.restore)?;
    anyhow::ensure!(
        env.body.node == topics.name,
        "the broker offered a {} state to restart this {} from",
        env.body.node,
        topics.name
    );
    Ok((!env.body.data.is_empty()).then_some(env))
}

/// The scene from the run's broker. Every answer is collected, and a run answered by more than one broker is
/// refused ([`crate::claim::Ambiguous`]): two runs on one run id that started within the moment the brokers' own
/// check cannot see. Asked again while nobody answers ([`crate::ask`]): a node started as soon as its broker's
/// session was open can ask through a router that has not yet heard of the broker's queryable (seen over TLS: both
/// nodes gave up within a second, CI of 2026-11-28, eighth).
fn fetch_scene(session: &Session, run: &str, timeout: Duration) -> anyhow::Result<String> {
    let scene_key = key(run, topic::SCENE);
    let answers = crate::ask::ask(session, &scene_key, timeout).map_err(zerr)?;
    if answers.len() > 1 {
        return Err(crate::claim::Ambiguous {
            run: run.into(),
            brokers: answers.len(),
            key: scene_key,
        }
        .into());
    }
    match answers.into_iter().next() {
        Some(reply) => match reply.result() {
            Ok(sample) => Ok(String::from_utf8(sample.payload().to_bytes().into_owned())?),
            Err(e) => anyhow::bail!("the broker refused the scene query: {e:?}"),
        },
        None => anyhow::bail!(
            "no broker of run {run} answered within {:.0} s (is `--run` right?)",
            timeout.as_secs_f64()
        ),
    }
}
