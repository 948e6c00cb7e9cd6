//! The broker's zenoh side: session, the `scene` queryable, node registration and the per-step exchange with a
//! structure node in another process. Everything the coordinator needs is behind [`FemLink`].

use std::time::{Duration, Instant};

use anyhow::Context;
use cosim_proto::envelope::{CodecError, Envelope};
use cosim_proto::keys::{key, topic};
use cosim_proto::messages::{FemMesh, FemState, NodeError, StepCommand};
use zenoh::handlers::FifoChannelHandler;
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::qos::CongestionControl;
use zenoh::query::Queryable;
use zenoh::sample::{Sample, SampleKind};
use zenoh::{Session, Wait};

use crate::link::{FemLink, LinkError};

/// Open a peer session with the project's settings (loopback by default, multicast scouting off).
pub fn open_session(listen: &[String], connect: &[String], timeout_ms: u64) -> anyhow::Result<Session> {
    let mut config = zenoh::Config::default();
    for (k, v) in cosim_proto::session::peer_settings(listen, connect, timeout_ms) {
        config
            .insert_json5(&k, &v)
            .map_err(|e| anyhow::anyhow!("zenoh setting {k} = {v}: {e}"))?;
    }
    zenoh::open(config).wait().map_err(|e| anyhow::anyhow!("{e}"))
}

/// Open the broker's session. A TCP listen endpoint with port 0 gets a free port picked here (zenoh's own
/// listing of bound locators is an unstable API), retried a few times in case another program takes it first.
/// Returns the session and the endpoints it listens on.
pub fn open_listening(
    listen: &[String],
    connect: &[String],
    timeout_ms: u64,
) -> anyhow::Result<(Session, Vec<String>)> {
    let mut last = None;
    for _ in 0..5 {
        let endpoints = listen.iter().map(|e| concrete(e)).collect::<anyhow::Result<Vec<_>>>()?;
        match open_session(&endpoints, connect, timeout_ms) {
            Ok(session) => return Ok((session, endpoints)),
            Err(e) => last = Some(e),
        }
    }
    Err(last.expect("at least one attempt"))
}

/// `tcp/HOST:0` with a free port of HOST; other endpoints unchanged.
fn concrete(endpoint: &str) -> anyhow::Result<String> {
    match endpoint.strip_prefix("tcp/").and_then(|a| a.strip_suffix(":0")) {
        Some(host) => {
            let port = std::net::TcpListener::bind((host, 0))
                .and_then(|l| l.local_addr())
                .with_context(|| format!("no free port on {host}"))?
                .port();
            Ok(format!("tcp/{host}:{port}"))
        }
        None => Ok(endpoint.to_string()),
    }
}

/// Answer `cosim/<run>/scene` with the resolved scene (TOML text) for as long as the returned handle lives.
pub fn serve_scene(session: &Session, run: &str, scene_toml: String) -> anyhow::Result<Queryable<()>> {
    session
        .declare_queryable(key(run, topic::SCENE))
        .callback(move |query| {
            if let Err(e) = query.reply(query.key_expr().clone(), scene_toml.clone()).wait() {
                tracing::warn!("scene query: {e}");
            }
        })
        .wait()
        .map_err(|e| anyhow::anyhow!("{e}"))
}

type Sub = Subscriber<FifoChannelHandler<Sample>>;

/// A structure node in another process.
pub struct ZenohFemLink {
    run: String,
    mesh: FemMesh,
    command: Publisher<'static>,
    state: Sub,
    error: Sub,
    alive: Sub,
    step_timeout: Duration,
}

/// Subscribers the broker declares before any node can register, so that no message is missed.
pub struct FemSubscriptions {
    mesh: Sub,
    state: Sub,
    error: Sub,
    alive: Sub,
}

/// Declare the broker's subscriptions for the FEM node.
pub fn subscribe_fem(session: &Session, run: &str) -> anyhow::Result<FemSubscriptions> {
    let sub = |t: &str| {
        session
            .declare_subscriber(key(run, t))
            .wait()
            .map_err(|e| anyhow::anyhow!("{e}"))
    };
    Ok(FemSubscriptions {
        mesh: sub(topic::FEM_MESH)?,
        state: sub(topic::FEM_STATE)?,
        error: sub(topic::FEM_ERROR)?,
        alive: session
            .liveliness()
            .declare_subscriber(key(run, topic::FEM_ALIVE))
            .history(true)
            .wait()
            .map_err(|e| anyhow::anyhow!("{e}"))?,
    })
}

fn failed(message: impl Into<String>) -> LinkError {
    LinkError::Failed {
        node: "fem-node".into(),
        message: message.into(),
    }
}

/// Turn a `fem/error` sample into the error the run ends with.
fn node_error(sample: &Sample, run: &str) -> LinkError {
    match Envelope::<NodeError>::decode(&sample.payload().to_bytes(), run, "fem/error") {
        Ok(env) if env.body.status == "unstable" => LinkError::Unstable {
            node: "fem-node".into(),
            message: env.body.message,
        },
        Ok(env) => failed(env.body.message),
        Err(e) => failed(format!("sent an undecodable error report: {e}")),
    }
}

impl ZenohFemLink {
    /// Wait (at most `wait`) for a FEM node to register its mesh, then build the link.
    pub fn register(
        session: &Session,
        run: &str,
        subs: FemSubscriptions,
        wait: Duration,
        step_timeout: Duration,
    ) -> anyhow::Result<Self> {
        let deadline = Instant::now() + wait;
        let mesh = loop {
            if let Some(sample) = subs
                .mesh
                .recv_timeout(Duration::from_millis(50))
                .map_err(|e| anyhow::anyhow!("{e}"))?
            {
                let env = Envelope::<FemMesh>::decode(&sample.payload().to_bytes(), run, "fem/mesh")
                    .context("fem-node registration refused")?;
                break env.body;
            }
            if let Some(sample) = subs.error.try_recv().map_err(|e| anyhow::anyhow!("{e}"))? {
                return Err(node_error(&sample, run).into());
            }
            if Instant::now() > deadline {
                anyhow::bail!("fem-node: did not register within {:.0} s", wait.as_secs_f64());
            }
        };
        let command = session
            .declare_publisher(key(run, topic::BROKER_FEM))
            .congestion_control(CongestionControl::Block)
            .express(true)
            .wait()
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        Ok(Self {
            run: run.to_string(),
            mesh,
            command,
            state: subs.state,
            error: subs.error,
            alive: subs.alive,
            step_timeout,
        })
    }

    /// A failure the node reported or its death, if either happened.
    fn check_node(&self) -> Result<(), LinkError> {
        if let Ok(Some(sample)) = self.error.try_recv() {
            return Err(node_error(&sample, &self.run));
        }
        while let Ok(Some(sample)) = self.alive.try_recv() {
            if sample.kind() == SampleKind::Delete {
                // It may have reported why just before it went.
                if let Ok(Some(sample)) = self.error.recv_timeout(Duration::from_millis(200)) {
                    return Err(node_error(&sample, &self.run));
                }
                return Err(failed("the node died (its liveliness token disappeared)"));
            }
        }
        Ok(())
    }
}

impl FemLink for ZenohFemLink {
    fn mesh(&self) -> &FemMesh {
        &self.mesh
    }

    fn exchange(&mut self, step: u64, t: f64, cmd: StepCommand) -> Result<Option<FemState>, LinkError> {
        let stop = cmd.stop;
        let bytes = Envelope::new(&self.run, step, t, cmd).encode();
        self.command
            .put(bytes)
            .wait()
            .map_err(|e| failed(format!("cannot send step {step}: {e}")))?;
        if stop {
            return Ok(None);
        }
        let deadline = Instant::now() + self.step_timeout;
        loop {
            match self.state.recv_timeout(Duration::from_millis(100)) {
                Ok(Some(sample)) => {
                    let env = Envelope::<FemState>::decode(&sample.payload().to_bytes(), &self.run, "fem/state")
                        .and_then(|e| e.expect_step(step, "fem/state"))
                        .map_err(|e: CodecError| failed(format!("refused its state: {e}")))?;
                    return Ok(Some(env.body));
                }
                Ok(None) => {}
                Err(e) => return Err(failed(format!("state channel closed: {e}"))),
            }
            self.check_node()?;
            if Instant::now() > deadline {
                return Err(failed(format!(
                    "no answer to step {step} within {:.0} s (coupling.step_timeout)",
                    self.step_timeout.as_secs_f64()
                )));
            }
        }
    }
}
