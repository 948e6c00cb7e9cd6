//! Opening zenoh sessions with the project's settings (loopback peers, multicast scouting off).
//!
//! Every session starts from a base config: zenoh's defaults, or a zenoh JSON5 config file (`--zenoh-config FILE`
//! on every binary). The project's own settings (`settings`: mode, multicast scouting off, endpoints,
//! timeouts) are inserted on top of it, so the file contributes everything else: `transport/auth/usrpwd` (user and
//! password, or a router's dictionary file), `transport/link/tls` (certificates and keys), and so on.

use std::path::Path;

use anyhow::Context;
use zenoh::{Session, Wait};

mod endpoint;
mod settings;

pub use endpoint::{endpoint, TRANSPORTS};

/// The base config: zenoh's defaults without a file, else the file (JSON5, `.json5` or `.json`; YAML `.yaml`)
/// read with `zenoh::Config::from_file`. A file that cannot be read or parsed is one error naming it.
pub fn base_config(file: Option<&Path>) -> anyhow::Result<zenoh::Config> {
    let Some(file) = file else {
        return Ok(zenoh::Config::default());
    };
    // zenoh's own message for a missing file does not name it; ours does, with the reason.
    std::fs::metadata(file).with_context(|| format!("zenoh config {}: cannot read it", file.display()))?;
    zenoh::Config::from_file(file).map_err(|e| anyhow::anyhow!("zenoh config {}: {}", file.display(), one_line(&e)))
}

/// A zenoh error on one line, without the source location zenoh appends (` at …/lib.rs:1483.`).
fn one_line(e: &dyn std::fmt::Display) -> String {
    let text = e.to_string();
    let text = match text.rfind(" at ") {
        Some(i) if text.trim_end().ends_with('.') && text[i..].contains(".rs:") => &text[..i],
        _ => text.as_str(),
    };
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// `base` with `settings` inserted on top.
fn with_settings(base: Option<&Path>, settings: Vec<(String, String)>) -> anyhow::Result<zenoh::Config> {
    let mut config = base_config(base)?;
    for (k, v) in settings {
        config
            .insert_json5(&k, &v)
            .map_err(|e| anyhow::anyhow!("zenoh setting {k} = {v}: {e}"))?;
    }
    Ok(config)
}

fn open(config: zenoh::Config) -> anyhow::Result<Session> {
    zenoh::open(config)
        .wait()
        .map_err(|e| anyhow::anyhow!("{}", one_line(&e)))
}

/// Open a peer session: listen on `listen`, connect to `connect`; a connect endpoint that does not answer
/// within `timeout_ms` is an error, not an endless retry.
pub fn open_session(listen: &[String], connect: &[String], timeout_ms: u64) -> anyhow::Result<Session> {
    open_session_from(None, listen, connect, timeout_ms)
}

/// [`open_session`] on top of the config file `base` (see [`base_config`]).
pub fn open_session_from(
    base: Option<&Path>,
    listen: &[String],
    connect: &[String],
    timeout_ms: u64,
) -> anyhow::Result<Session> {
    open(with_settings(
        base,
        settings::peer_settings(listen, connect, timeout_ms),
    )?)
}

/// Open a client session through the router(s) at `connect` (`settings::client_settings`): how every
/// process of a run joins when the run goes through a router instead of peer to peer.
pub fn open_client(connect: &[String], timeout_ms: u64) -> anyhow::Result<Session> {
    open_client_from(None, connect, timeout_ms)
}

/// [`open_client`] on top of the config file `base` (see [`base_config`]).
pub fn open_client_from(base: Option<&Path>, connect: &[String], timeout_ms: u64) -> anyhow::Result<Session> {
    anyhow::ensure!(
        !connect.is_empty(),
        "client mode needs a router to connect to (--connect)"
    );
    let session = open(with_settings(base, settings::client_settings(connect, timeout_ms))?);
    // A router that refuses a user, a password or a certificate only closes the link: say where to look.
    match (session, base) {
        (Err(e), Some(file)) => Err(e.context(format!(
            "the router did not let this process in (check the address, and the user, password or TLS settings \
             of {})",
            file.display()
        ))),
        (session, _) => session,
    }
}

/// Open a session that listens. A TCP (or TLS) listen endpoint with port 0 gets a free port picked here (zenoh's
/// own listing of bound locators is an unstable API), retried a few times in case another program takes it
/// first. Returns the session and the endpoints it listens on.
pub fn open_listening(
    listen: &[String],
    connect: &[String],
    timeout_ms: u64,
) -> anyhow::Result<(Session, Vec<String>)> {
    open_listening_from(None, listen, connect, timeout_ms)
}

/// [`open_listening`] on top of the config file `base` (see [`base_config`]).
pub fn open_listening_from(
    base: Option<&Path>,
    listen: &[String],
    connect: &[String],
    timeout_ms: u64,
) -> anyhow::Result<(Session, Vec<String>)> {
    // A bad file is reported once, not hidden behind the retries.
    base_config(base)?;
    retry_ports(listen, |endpoints| {
        open_session_from(base, endpoints, connect, timeout_ms)
    })
}

/// Open a zenoh router (`settings::router_settings`) listening on `listen`, on top of the config
/// file `base`: the hub of a run spread over hosts, where every process joins as a client. It is the router
/// `zenohd` runs. Returns the session and the endpoints it listens on (port 0 replaced as in [`open_listening`]).
pub fn open_router(base: Option<&Path>, listen: &[String], timeout_ms: u64) -> anyhow::Result<(Session, Vec<String>)> {
    anyhow::ensure!(!listen.is_empty(), "a router needs an endpoint to listen on (--listen)");
    base_config(base)?;
    retry_ports(listen, |endpoints| {
        open(with_settings(base, settings::router_settings(endpoints, timeout_ms))?)
    })
}

/// Call `open` with `listen` made concrete ([`concrete`]), up to five times while it fails because another
/// program took a port picked here. Any other failure (a connect endpoint that does not answer within the timeout)
/// is returned at once: it would fail the same way again, each time after the whole timeout (`cosim ctl` on a
/// closed port took 5 × 10 s).
fn retry_ports(
    listen: &[String],
    mut open: impl FnMut(&[String]) -> anyhow::Result<Session>,
) -> anyhow::Result<(Session, Vec<String>)> {
    let mut last = None;
    for _ in 0..5 {
        let endpoints = listen.iter().map(|e| concrete(e)).collect::<anyhow::Result<Vec<_>>>()?;
        match open(&endpoints) {
            Ok(session) => return Ok((session, endpoints)),
            Err(e) => last = Some(e),
        }
        // A fixed port that failed fails the same way again; a picked one is tried again only if it was taken.
        if !endpoints.iter().zip(listen).any(|(e, l)| e != l && taken(e)) {
            break;
        }
    }
    Err(last.expect("at least one attempt"))
}

/// Whether the TCP port of `endpoint` (`tcp/HOST:PORT` or `tls/HOST:PORT`) is bound by another program now.
fn taken(endpoint: &str) -> bool {
    let Some((_, address)) = endpoint.split_once('/') else {
        return false;
    };
    std::net::TcpListener::bind(address).is_err()
}

/// `tcp/HOST:0` (or `tls/HOST:0`) with a free port of HOST; other endpoints unchanged.
fn concrete(endpoint: &str) -> anyhow::Result<String> {
    let (scheme, rest) = match endpoint.split_once('/') {
        Some((s @ ("tcp" | "tls"), rest)) => (s, rest),
        _ => return Ok(endpoint.to_string()),
    };
    match rest.strip_suffix(":0") {
        Some(host) => {
            let port = std::net::TcpListener::bind((host, 0))
                .and_then(|l| l.local_addr())
                .with_context(|| format!("no free port on {host}"))?
                .port();
            Ok(format!("{scheme}/{host}:{port}"))
        }
        None => Ok(endpoint.to_string()),
    }
}

/// Close `session` and wait until it is closed (its last handle dropped does the same, without saying when).
pub fn close(session: &Session) {
    if let Err(e) = session.close().wait() {
        tracing::debug!("closing the zenoh session: {e}");
    }
}

/// Stop zenoh's runtime threads (`zenoh_runtime::ZRuntimePoolGuard`, as zenoh-c's `zc_stop_z_runtime`), each given up
/// to 1 s, before the process exits; every session must be closed and dropped first, and nothing of zenoh used
/// after. A process that exited with them running now and then put a panic and a backtrace in its log, in runs that
/// ended as they should: a receiving thread reached a shared-memory static that `exit` had already destroyed
/// (`static_init`: "AccessError { phase: … FINALIZED … }"; found 2026-12-06 by the sweep of hostile external nodes,
/// D24, in an sph-node and a contact-broker log, 1 of 7 runs of its D12b).
///
/// The pool's drop takes every runtime out of its table before it shuts them down, so a zenoh task still running
/// on one of them that reaches for another panics there ("The hashmap should contains app after initialization",
/// zenoh-runtime 1.10 `ZRuntimePool::get`; found 2026-12-08 in a fresh clone's suite, in the log of a broker that had
/// ended its run as it should, once in the session's four suites). That panic, and only that one, is said in one
/// line from here on instead of as a panic with its backtrace: the process has done its work and is leaving.
pub fn stop_runtime() {
    let previous = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        if is_teardown_panic(info.payload()) {
            eprintln!("zenoh: a runtime task met the runtime's teardown as the process exits (ignored)");
        } else {
            previous(info);
        }
    }));
    drop(zenoh_runtime::ZRuntimePoolGuard);
}

/// Whether a panic's payload is zenoh-runtime's at a runtime taken out of its pool ([`stop_runtime`]).
fn is_teardown_panic(payload: &(dyn std::any::Any + Send)) -> bool {
    let message = payload
        .downcast_ref::<String>()
        .map(String::as_str)
        .or_else(|| payload.downcast_ref::<&str>().copied());
    message.is_some_and(|m| m.starts_with("The hashmap should contains ") && m.ends_with(" after initialization"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// zenoh-runtime's teardown panic is recognised by its message, and no other panic is.
    #[test]
    fn only_zenohs_teardown_panic_is_told_in_one_line() {
        let teardown = std::panic::catch_unwind(|| {
            let zrt = "app";
            panic!("The hashmap should contains {zrt} after initialization")
        })
        .unwrap_err();
        assert!(is_teardown_panic(teardown.as_ref()));
        let other = std::panic::catch_unwind(|| panic!("index out of bounds")).unwrap_err();
        assert!(!is_teardown_panic(other.as_ref()));
        let other = std::panic::catch_unwind(|| panic!("The hashmap should contains {} entries", 3)).unwrap_err();
        assert!(!is_teardown_panic(other.as_ref()));
    }

    /// A failure with the picked port still free (what a connect endpoint that does not answer gives) is not tried
    /// again; one whose picked port another program holds is, with a new port each time.
    #[test]
    fn only_a_taken_port_is_tried_again() {
        let mut tried = Vec::new();
        let err = retry_ports(&["tcp/127.0.0.1:0".to_string()], |endpoints| {
            tried.push(endpoints.to_vec());
            anyhow::bail!("Unable to connect to any of [tcp/127.0.0.1:9]. Timeout!")
        })
        .unwrap_err();
        assert_eq!(tried.len(), 1, "{tried:?}");
        assert!(err.to_string().contains("Unable to connect"), "{err}");

        let mut held = Vec::new();
        let _ = retry_ports(&["tcp/127.0.0.1:0".to_string()], |endpoints| {
            // Another program binds the port picked for us before we do.
            let address = endpoints[0].strip_prefix("tcp/").unwrap();
            held.push(std::net::TcpListener::bind(address).unwrap());
            anyhow::bail!("Can not create a new TCP listener bound to {address}")
        });
        assert_eq!(held.len(), 5, "tried five times while the port was taken");
        let ports: std::collections::HashSet<_> = held.iter().map(|l| l.local_addr().unwrap().port()).collect();
        assert_eq!(ports.len(), 5, "a new port each time");
    }
}
