//! The broker's zenoh side: session, node registration and the per-step exchange with a node in another process
//! (the queryables it answers beside the steps, the scene and the restore states, are in `served.rs`). Everything
//! the coordinator needs is behind [`NodeLink`].

use std::collections::BTreeMap;
use std::time::{Duration, Instant};

use cosim_proto::envelope::{CodecError, Envelope};
use cosim_proto::keys::{key, NodeTopics};
use cosim_proto::messages::{NodeCheckpoint, NodeError, StepCommand};
use cosim_proto::run_status::RunStatus;
use serde::de::DeserializeOwned;
use zenoh::bytes::ZBytes;
use zenoh::handlers::FifoChannelHandler;
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::qos::CongestionControl;
use zenoh::sample::{Sample, SampleKind};
use zenoh::{Session, Wait};

use crate::link::{LinkError, NodeLink, Reply};
use crate::recorder::Tap;
use cosim_bus::interrupt::{Interrupt, REASON};
use cosim_bus::link_loss;
use cosim_bus::refusals::Refusals;
use cosim_proto::trace::Kind;

pub use crate::served::{serve_restore, serve_scene};
pub use cosim_bus::session::{
    open_client, open_client_from, open_listening, open_listening_from, open_session, open_session_from,
};

type Sub = Subscriber<FifoChannelHandler<Sample>>;

/// Subscriptions the broker declares before any node can register, so that no message is missed.
pub struct Subscriptions {
    topics: NodeTopics,
    setup: Sub,
    state: Sub,
    error: Sub,
    alive: Sub,
}

/// Declare the broker's subscriptions for one node.
pub fn subscribe(session: &Session, run: &str, topics: NodeTopics) -> anyhow::Result<Subscriptions> {
    let sub = |t: &str| {
        session
            .declare_subscriber(key(run, t))
            .wait()
            .map_err(|e| anyhow::anyhow!("{e}"))
    };
    Ok(Subscriptions {
        topics,
        setup: sub(topics.setup)?,
        state: sub(topics.state)?,
        error: sub(topics.error)?,
        alive: session
            .liveliness()
            .declare_subscriber(key(run, topics.alive))
            .history(true)
            .wait()
            .map_err(|e| anyhow::anyhow!("{e}"))?,
    })
}

/// A node in another process.
pub struct ZenohLink<S, T> {
    session: Session,
    run: String,
    topics: NodeTopics,
    setup: S,
    command: Publisher<'static>,
    state: Sub,
    error: Sub,
    alive: Sub,
    step_timeout: Duration,
    /// The last command sent (its step, time and bytes), to send again when its answer does not come.
    last_command: Option<(u64, f64, ZBytes)>,
    /// The registration as received (its step and bytes), for the trace.
    registration: (u64, Vec<u8>),
    /// Where every message sent and accepted is recorded (`--record`).
    tap: Option<Tap>,
    /// Ctrl-C or SIGTERM: a wait for an answer that still goes on
    /// [`STOP_WAIT`](cosim_bus::interrupt::STOP_WAIT) after it is given up.
    stop: Option<Interrupt>,
    /// The node's messages refused so far, by kind.
    refusals: LinkRefusals,
    _state: std::marker::PhantomData<T>,
}

/// The messages of one node refused, by kind, each logged in a few lines however many come
/// ([`cosim_bus::refusals`]).
struct LinkRefusals {
    registrations: Refusals,
    states: Refusals,
    errors: Refusals,
}

impl LinkRefusals {
    fn new(node: &str) -> Self {
        Self {
            registrations: Refusals::new(format!("{node}: refused a registration")),
            states: Refusals::new(format!("{node}: refused a state message")),
            errors: Refusals::new(format!("{node}: refused an error report")),
        }
    }
}

/// Turn an error sample into the error the run ends with; `None` for a message that does not decode as this
/// run's error report (logged and dropped: a stray message must not end the run; a node that really fails also
/// exits, and its liveliness token says so).
fn node_error(sample: &Sample, run: &str, topics: &NodeTopics, refusals: &mut Refusals) -> Option<LinkError> {
    let node = topics.name.to_string();
    match Envelope::<NodeError>::decode(&sample.payload().to_bytes(), run, topics.error) {
        Ok(env) => {
            let message = cosim_proto::one_line(&env.body.message);
            Some(match RunStatus::of_node_report(&env.body.status) {
                RunStatus::Unstable => LinkError::Unstable { node, message },
                _ => LinkError::Failed { node, message },
            })
        }
        Err(e) => {
            refusals.note(&e);
            None
        }
    }
}

impl<S: DeserializeOwned, T: DeserializeOwned + Reply> ZenohLink<S, T> {
    /// Wait (at most `wait`, and until `interrupt` arrives) for the node to register, then build the link.
    pub fn register(
        session: &Session,
        run: &str,
        subs: Subscriptions,
        wait: Duration,
        interrupt: &Interrupt,
        step_timeout: Duration,
    ) -> anyhow::Result<Self> {
        let topics = subs.topics;
        let deadline = Instant::now() + wait;
        // The last registration refused, kept over the whole wait: when no good one comes, it is the reason.
        let mut refused: Option<String> = None;
        let mut refusals = LinkRefusals::new(topics.name);
        let (setup, registration) = loop {
            let got = subs
                .setup
                .recv_timeout(Duration::from_millis(50))
                .map_err(|e| anyhow::anyhow!("{e}"))?;
            // A registration that does not decode as this run's is refused: logged, and the wait goes on.
            if let Some(sample) = got {
                let bytes = sample.payload().to_bytes();
                match Envelope::<S>::decode(&bytes, run, topics.setup) {
                    Ok(env) => break (env.body, (env.step, bytes.into_owned())),
                    Err(e) => {
                        refusals.registrations.note(&e);
                        refused = Some(e.to_string());
                    }
                }
            }
            if let Some(sample) = subs.error.try_recv().map_err(|e| anyhow::anyhow!("{e}"))? {
                if let Some(e) = node_error(&sample, run, &topics, &mut refusals.errors) {
                    return Err(e.into());
                }
            }
            // Ctrl-C while a node is awaited (an outside node not started yet): the run ends at once, as between two
            // steps (it went on waiting until `cosim run` killed it 10 s later, found 2026-12-06).
            if interrupt.arrived() {
                anyhow::bail!("{REASON}, while waiting for {} to register", topics.name);
            }
            if Instant::now() > deadline {
                let why = refused.map(|r| format!(" (refused: {r})")).unwrap_or_default();
                anyhow::bail!(
                    "{}: did not register within {:.0} s{why}",
                    topics.name,
                    wait.as_secs_f64()
                );
            }
        };
        let command = session
            .declare_publisher(key(run, topics.command))
            .congestion_control(CongestionControl::Block)
            .express(true)
            .wait()
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        Ok(Self {
            session: session.clone(),
            run: run.to_string(),
            topics,
            setup,
            command,
            state: subs.state,
            error: subs.error,
            alive: subs.alive,
            step_timeout,
            last_command: None,
            registration,
            tap: None,
            stop: None,
            refusals,
            _state: std::marker::PhantomData,
        })
    }

    /// Record every message of this node from now on into `tap` (`--record`), starting with its registration.
    pub fn record_to(&mut self, tap: Tap) {
        tap.record(Kind::Setup, self.registration.0, &self.registration.1);
        self.tap = Some(tap);
    }

    /// Give up waiting for an answer [`STOP_WAIT`](cosim_bus::interrupt::STOP_WAIT) after `interrupt` arrived
    /// ([`Interrupt::overdue`]): a run whose coupling step takes minutes (a fine mesh) then stops with its outputs so
    /// far written, instead of being killed by `cosim run` with none (10 s after the Ctrl-C). A step that ends within
    /// that time is still taken.
    pub fn stop_on(&mut self, interrupt: Interrupt) {
        self.stop = Some(interrupt);
    }

    fn failed(&self, message: impl Into<String>) -> LinkError {
        LinkError::Failed {
            node: self.topics.name.into(),
            message: message.into(),
        }
    }

    /// Send the command of `step` again, byte for byte (a node that answered it answers again).
    fn send_again(&self, step: u64, bytes: &ZBytes) {
        if let Err(e) = self.command.put(bytes.clone()).wait() {
            tracing::warn!("{}: cannot send step {step} again: {e}", self.topics.name);
        }
    }

    /// A failure the node reported or its death, if either happened.
    fn check_node(&mut self) -> Result<(), LinkError> {
        while let Ok(Some(sample)) = self.error.try_recv() {
            if let Some(e) = self.node_error(&sample) {
                return Err(e);
            }
        }
        while let Ok(Some(sample)) = self.alive.try_recv() {
            if sample.kind() == SampleKind::Delete {
                // It may have reported why just before it went.
                if let Ok(Some(sample)) = self.error.recv_timeout(Duration::from_millis(200)) {
                    if let Some(e) = self.node_error(&sample) {
                        return Err(e);
                    }
                }
                // A link lost and restored also takes the token away for a moment (`cosim_bus::link_loss`).
                let alive = key(&self.run, self.topics.alive);
                let (back, after) = link_loss::comes_back(&self.session, &alive, link_loss::GRACE);
                if back {
                    tracing::warn!(
                        "{}'s liveliness token was away for {:.2} s (a link lost and restored): going on",
                        self.topics.name,
                        after.as_secs_f64()
                    );
                    // What was sent while the link was down is lost: the last command goes again at once rather
                    // than at the next resend (a node that answered it answers again, computing nothing).
                    if let Some((step, _, bytes)) = &self.last_command {
                        self.send_again(*step, bytes);
                    }
                    continue;
                }
                return Err(self.failed(format!(
                    "the node died (its liveliness token disappeared, and was not back within {:.1} s)",
                    after.as_secs_f64()
                )));
            }
        }
        Ok(())
    }

    /// [`node_error`], recorded when it is this run's error report: under the step of the last command sent (a node
    /// reports its failure with step 0 in its envelope; it fails while it works on that command).
    fn node_error(&mut self, sample: &Sample) -> Option<LinkError> {
        let e = node_error(sample, &self.run, &self.topics, &mut self.refusals.errors)?;
        if let Some(tap) = &self.tap {
            let step = self.last_command.as_ref().map_or(0, |(s, _, _)| *s);
            tap.record(Kind::Error, step, &sample.payload().to_bytes());
        }
        Some(e)
    }
}

/// How long the broker waits for a node's live status at the end of a run (for the summary's counts). A node
/// answers it from its zenoh threads whatever it is computing, within milliseconds; one that is gone (a failed run)
/// costs the whole wait.
const COUNTS_TIMEOUT: Duration = Duration::from_millis(500);

impl<S: DeserializeOwned, T: DeserializeOwned + Reply> NodeLink for ZenohLink<S, T> {
    type Setup = S;
    type State = T;

    fn setup(&self) -> &S {
        &self.setup
    }

    fn send(&mut self, step: u64, t: f64, cmd: StepCommand) -> Result<(), LinkError> {
        // A shared buffer: keeping it to send again costs no copy.
        let bytes = Envelope::new(&self.run, step, t, cmd)
            .encode_checked(self.topics.command)
            .map_err(|e| self.failed(e.to_string()))?;
        if let Some(tap) = &self.tap {
            tap.command(step, t, &bytes);
        }
        let bytes = ZBytes::from(bytes);
        self.command
            .put(bytes.clone())
            .wait()
            .map_err(|e| self.failed(format!("cannot send step {step}: {e}")))?;
        self.last_command = Some((step, t, bytes));
        Ok(())
    }

    fn farewell(&mut self) {
        // The node waits for the step after the last command it was sent (or is still computing that one: it
        // answers, then reads this). Not recorded: a trace holds the run's own messages.
        let (step, t) = self.last_command.as_ref().map_or((0, 0.0), |(s, t, _)| (s + 1, *t));
        let stop = StepCommand::bare_stop();
        let sent = Envelope::new(&self.run, step, t, stop)
            .encode_checked(self.topics.command)
            .map_err(|e| e.to_string())
            .and_then(|bytes| self.command.put(bytes).wait().map_err(|e| e.to_string()));
        if let Err(e) = sent {
            tracing::debug!("cannot tell {} to stop: {e}", self.topics.name);
        }
    }

    fn checkpoint(&mut self, step: u64) -> Result<Vec<u8>, LinkError> {
        let what = self.topics.checkpoint;
        let asked = std::time::Instant::now();
        // Asked again while nobody answers, for as long as a link lost and restored takes to come back (it takes the
        // node's queryable away for a moment); a node that died is not waited for longer.
        let answers = cosim_bus::ask::ask_within(
            &self.session,
            &key(&self.run, what),
            self.step_timeout,
            link_loss::GRACE,
        )
        .map_err(|e| self.failed(format!("cannot ask for a checkpoint: {e}")))?;
        // Nobody there is known within the grace, not the step's timeout (a node that says "did not answer within
        // 60 s" after 4 s misled, found 2026-12-07).
        let reply = answers.into_iter().next().ok_or_else(|| {
            self.failed(format!(
                "did not answer {what} (asked for {:.0} s; an outside program in a node's place may not save \
                 checkpoints)",
                asked.elapsed().as_secs_f64()
            ))
        })?;
        let sample = reply.result().map_err(|e| {
            let why = e
                .payload()
                .try_to_string()
                .map_or_else(|_| "(no reason given)".into(), |s| s.into_owned());
            self.failed(format!("refused the checkpoint: {why}"))
        })?;
        let env = Envelope::<NodeCheckpoint>::decode(&sample.payload().to_bytes(), &self.run, what)
            .and_then(|e| e.expect_step(step, what))
            .map_err(|e| self.failed(format!("sent an unusable checkpoint: {e}")))?;
        if env.body.node != self.topics.name {
            return Err(self.failed(format!("sent a checkpoint of a {}", env.body.node)));
        }
        // Empty bytes stand for "no such node" where a checkpoint or a snapshot is read (docs/PROTOCOL.md §11): a
        // node of the run sending none read as a run without a structure (found 2026-12-06).
        if env.body.data.is_empty() {
            return Err(self.failed(format!("sent an empty {what}: a node of the run saves its state")));
        }
        Ok(env.body.data)
    }

    fn counts(&mut self) -> Option<BTreeMap<String, u64>> {
        // The node's live status (`cosim/<run>/<node>/status`, JSON), whose counts it refreshes before each answer.
        let replies = self
            .session
            .get(key(&self.run, self.topics.status))
            .timeout(COUNTS_TIMEOUT)
            .wait()
            .ok()?;
        let sample = replies.recv().ok()?.into_result().ok()?;
        let status: serde_json::Value = serde_json::from_slice(&sample.payload().to_bytes()).ok()?;
        let counts = status.get("counts")?.as_object()?;
        Some(
            counts
                .iter()
                .filter_map(|(k, v)| Some((k.clone(), v.as_u64()?)))
                .collect(),
        )
    }

    fn receive(&mut self, step: u64) -> Result<T, LinkError> {
        let started = Instant::now();
        let deadline = started + self.step_timeout;
        // Without an answer after a third of the step timeout the command goes again (a node answers a command it
        // already answered with the same answer, `docs/PROTOCOL.md` §8), so that a message lost on the way does
        // not fail the run.
        let resend_every = self.step_timeout / 3;
        let mut resend_at = started + resend_every;
        // A message that is not this run's answer to this step (malformed, another version, run or step) is
        // refused: logged, never applied, and the wait goes on (`docs/PROTOCOL.md` §7).
        let mut refused: Option<String> = None;
        // The last answer to an earlier step that came instead: a node that numbers its answers one behind was
        // said to have sent nothing (found 2026-12-06).
        let mut earlier: Option<u64> = None;
        loop {
            match self.state.recv_timeout(Duration::from_millis(100)) {
                Ok(Some(sample)) => {
                    let bytes = sample.payload().to_bytes();
                    match Envelope::<T>::decode(&bytes, &self.run, self.topics.state)
                        .and_then(|e| e.expect_step(step, self.topics.state))
                    {
                        Ok(env) => {
                            // A failure the node reported before this answer ends the run: a node that says
                            // `unstable` and keeps answering must not end `ok` (docs/PROTOCOL.md §7).
                            while let Ok(Some(sample)) = self.error.try_recv() {
                                if let Some(e) = self.node_error(&sample) {
                                    return Err(e);
                                }
                            }
                            if let Some(tap) = &self.tap {
                                tap.record(Kind::State, step, &bytes);
                            }
                            return Ok(env.body);
                        }
                        // An answer to an earlier step, sent again after the broker sent its command again.
                        Err(CodecError::Step { got, .. }) if got < step => {
                            tracing::debug!("{}: a repeated answer to step {got}, dropped", self.topics.name);
                            earlier = Some(got);
                        }
                        Err(e) => {
                            let e: CodecError = e;
                            self.refusals.states.note(&e);
                            refused = Some(e.to_string());
                        }
                    }
                }
                Ok(None) => {}
                Err(e) => return Err(self.failed(format!("state channel closed: {e}"))),
            }
            self.check_node()?;
            if let Some(after) = self.stop.as_ref().filter(|s| s.overdue()).and_then(Interrupt::seen_for) {
                return Err(self.failed(format!(
                    "still computing coupling step {step} after {:.1} s, {:.0} s after the signal: {REASON}",
                    started.elapsed().as_secs_f64(),
                    after.as_secs_f64()
                )));
            }
            if Instant::now() > resend_at && Instant::now() < deadline {
                resend_at += resend_every;
                if let Some((_, _, bytes)) = self.last_command.as_ref().filter(|(s, _, _)| *s == step) {
                    tracing::warn!(
                        "{}: no answer to step {step} after {:.0} s: sending the command again",
                        self.topics.name,
                        started.elapsed().as_secs_f64()
                    );
                    self.send_again(step, bytes);
                }
            }
            if Instant::now() > deadline {
                let why = match (refused, earlier) {
                    (Some(r), _) => format!("; refused instead: {r}"),
                    (None, Some(got)) => format!("; it answered step {got} instead, an earlier step's number"),
                    (None, None) => String::new(),
                };
                return Err(self.failed(format!(
                    "no answer to step {step} within {:.0} s (coupling.step_timeout){why}",
                    self.step_timeout.as_secs_f64()
                )));
            }
        }
    }
}
