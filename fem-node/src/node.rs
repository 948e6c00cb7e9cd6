//! The FEM node's zenoh adapter: joins a run, fetches the scene, registers its mesh, then answers step commands
//! until told to stop (`docs/PROTOCOL.md`).

use std::time::Duration;

use anyhow::Context;
use cosim_proto::envelope::Envelope;
use cosim_proto::keys::{key, topic};
use cosim_proto::messages::{NodeError, StepCommand};
use zenoh::qos::CongestionControl;
use zenoh::sample::SampleKind;
use zenoh::{Session, Wait};

use crate::core::FemCore;

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
}

fn zerr(e: zenoh::Error) -> anyhow::Error {
    anyhow::anyhow!("{e}")
}

fn open(opts: &NodeOptions) -> anyhow::Result<Session> {
    let mut config = zenoh::Config::default();
    for (k, v) in cosim_proto::session::peer_settings(&opts.listen, &opts.connect, opts.timeout_ms) {
        config
            .insert_json5(&k, &v)
            .map_err(|e| anyhow::anyhow!("zenoh setting {k} = {v}: {e}"))?;
    }
    zenoh::open(config).wait().map_err(zerr)
}

/// Join the run and serve it to the end. Errors are also published on `fem/error` so the broker can say why.
pub fn serve(opts: &NodeOptions) -> anyhow::Result<()> {
    let session = open(opts).with_context(|| format!("cannot connect to {}", opts.connect.join(", ")))?;
    let run = opts.run.as_str();
    let errors = session
        .declare_publisher(key(run, topic::FEM_ERROR))
        .congestion_control(CongestionControl::Block)
        .wait()
        .map_err(zerr)?;
    let report = |status: &str, message: String| {
        let body = NodeError {
            status: status.into(),
            message,
        };
        let _ = errors.put(Envelope::new(run, 0, 0.0, body).encode()).wait();
    };
    let result = serve_session(&session, opts, &report);
    if let Err(e) = &result {
        let status = if e
            .downcast_ref::<crate::error::FemError>()
            .is_some_and(|f| f.is_unstable())
        {
            "unstable"
        } else {
            "failed"
        };
        report(status, format!("{e:#}").replace('\n', " "));
        // Let the report leave before the session closes.
        std::thread::sleep(Duration::from_millis(100));
    }
    result
}

fn serve_session(session: &Session, opts: &NodeOptions, report: &dyn Fn(&str, String)) -> anyhow::Result<()> {
    let run = opts.run.as_str();
    let commands = session
        .declare_subscriber(key(run, topic::BROKER_FEM))
        .wait()
        .map_err(zerr)?;
    let broker_alive = session
        .liveliness()
        .declare_subscriber(key(run, topic::BROKER_ALIVE))
        .history(true)
        .wait()
        .map_err(zerr)?;
    let state_pub = session
        .declare_publisher(key(run, topic::FEM_STATE))
        .congestion_control(CongestionControl::Block)
        .express(true)
        .wait()
        .map_err(zerr)?;
    let _alive = session
        .liveliness()
        .declare_token(key(run, topic::FEM_ALIVE))
        .wait()
        .map_err(zerr)?;

    let scene_text = fetch_scene(session, run, Duration::from_millis(opts.timeout_ms))?;
    let scene = cosim_proto::scene::parse("(scene from the broker)", &scene_text, &[])?;
    let mut core = FemCore::new(&scene)?;
    let mesh = Envelope::new(run, 0, 0.0, core.mesh().clone()).encode();
    session
        .put(key(run, topic::FEM_MESH), mesh)
        .congestion_control(CongestionControl::Block)
        .wait()
        .map_err(zerr)?;

    let mut expected = 0u64;
    let mut t = 0.0;
    loop {
        let Some(sample) = commands.recv_timeout(Duration::from_millis(200)).map_err(zerr)? else {
            while let Ok(Some(s)) = broker_alive.try_recv() {
                if s.kind() == SampleKind::Delete {
                    anyhow::bail!("the broker of run {run} went away");
                }
            }
            continue;
        };
        let env = match Envelope::<StepCommand>::decode(&sample.payload().to_bytes(), run, "broker/fem")
            .and_then(|e| e.expect_step(expected, "broker/fem"))
        {
            Ok(env) => env,
            Err(e) => {
                // Refused, never applied: say so and keep the state as it is.
                tracing::error!("{e}");
                report("failed", format!("refused a command: {e}"));
                continue;
            }
        };
        expected += 1;
        let dt = env.body.dt;
        let Some(state) = core.handle(&env.body)? else {
            return Ok(());
        };
        t = if dt > 0.0 { env.t + dt } else { t.max(env.t) };
        state_pub
            .put(Envelope::new(run, env.step, t, state).encode())
            .wait()
            .map_err(zerr)?;
    }
}

fn fetch_scene(session: &Session, run: &str, timeout: Duration) -> anyhow::Result<String> {
    let replies = session
        .get(key(run, topic::SCENE))
        .timeout(timeout)
        .wait()
        .map_err(zerr)?;
    match replies.recv() {
        Ok(reply) => match reply.result() {
            Ok(sample) => Ok(String::from_utf8(sample.payload().to_bytes().into_owned())?),
            Err(e) => anyhow::bail!("the broker refused the scene query: {e:?}"),
        },
        Err(_) => anyhow::bail!(
            "no broker of run {run} answered within {:.0} s (is `--run` right?)",
            timeout.as_secs_f64()
        ),
    }
}
