//! Opening zenoh sessions with the project's settings (loopback peers, multicast scouting off).

use anyhow::Context;
use zenoh::{Session, Wait};

/// Open a peer session: listen on `listen`, connect to `connect`; a connect endpoint that does not answer
/// within `timeout_ms` is an error, not an endless retry.
pub fn open_session(listen: &[String], connect: &[String], timeout_ms: u64) -> anyhow::Result<Session> {
    let mut config = zenoh::Config::default();
    for (k, v) in cosim_proto::session::peer_settings(listen, connect, timeout_ms) {
        config
            .insert_json5(&k, &v)
            .map_err(|e| anyhow::anyhow!("zenoh setting {k} = {v}: {e}"))?;
    }
    zenoh::open(config).wait().map_err(|e| anyhow::anyhow!("{e}"))
}

/// Open a client session through the router(s) at `connect` (`cosim_proto::session::client_settings`): how every
/// process of a run joins when the run goes through a router instead of peer to peer.
pub fn open_client(connect: &[String], timeout_ms: u64) -> anyhow::Result<Session> {
    anyhow::ensure!(
        !connect.is_empty(),
        "client mode needs a router to connect to (--connect)"
    );
    let mut config = zenoh::Config::default();
    for (k, v) in cosim_proto::session::client_settings(connect, timeout_ms) {
        config
            .insert_json5(&k, &v)
            .map_err(|e| anyhow::anyhow!("zenoh setting {k} = {v}: {e}"))?;
    }
    zenoh::open(config).wait().map_err(|e| anyhow::anyhow!("{e}"))
}

/// Open a session that listens. A TCP listen endpoint with port 0 gets a free port picked here (zenoh's own
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
