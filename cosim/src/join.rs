//! Joining a live run from another process, as `cosim inspect`, `cosim ctl` and `cosim snapshot` do: found on this
//! machine through the run registry (`registry.rs`), or given its endpoint (`--connect`, the broker's or a
//! router's, `--client` for a router).

use std::path::PathBuf;
use std::time::Duration;

use clap::Args;
use cosim_bus::session::{base_config, open_client_from, open_listening_from};
use zenoh::Session;

use crate::registry;

/// How to reach a live run.
#[derive(Args, Debug, Clone)]
pub struct JoinArgs {
    /// Endpoint of the run (its broker's, or the router's) for a run on another host; a run on this machine is
    /// found without it.
    #[arg(long)]
    pub connect: Option<String>,
    /// `--connect` is a zenoh router: join through it as a client.
    #[arg(long)]
    pub client: bool,
    /// A zenoh JSON5 config file the session starts from (as the run's `--zenoh-config`).
    #[arg(long, value_name = "FILE")]
    pub zenoh_config: Option<PathBuf>,
    /// Seconds to wait for the run's answers.
    #[arg(long, value_parser = cosim_bus::seconds::positive, default_value_t = 10.0)]
    pub timeout: f64,
}

/// Open a session on run `id`'s network; also the endpoint joined. `Err` (exit 2) for an id no run can have, a run
/// not found here without `--connect`, a bad config file, or a run that cannot be reached.
pub fn join(id: &str, how: &JoinArgs) -> anyhow::Result<(Session, String)> {
    // Said as such, not as "not running on this machine" (found 2026-12-06 by the sweep of debug tools, D25).
    anyhow::ensure!(
        cosim_proto::keys::valid_run_id(id),
        "`{id}` is not a valid run id: a run id is 1–64 letters, digits, - and _"
    );
    let (connect, client, zenoh_config) = match &how.connect {
        Some(c) => (c.clone(), how.client, how.zenoh_config.clone()),
        None => match registry::lookup(id) {
            Some(e) => (
                e.connect,
                e.client || how.client,
                how.zenoh_config.clone().or(e.zenoh_config),
            ),
            None => anyhow::bail!(
                "run `{id}` is not running on this machine ({}); give --connect ENDPOINT for a run elsewhere (an \
                 in-process run cannot be reached from another process)",
                running_here()
            ),
        },
    };
    let timeout_ms = cosim_bus::seconds::wait(how.timeout).as_millis() as u64;
    let base = zenoh_config.as_deref();
    // A bad config file is its own error, not "cannot reach the run".
    base_config(base)?;
    // Zenoh tries a refused endpoint again until the timeout: a port nothing listens on is said at once.
    if let Some(addr) = refused(&connect) {
        anyhow::bail!(
            "cannot reach run `{id}` at {connect}: nothing listens there ({addr} refused the connection); is the \
             run's broker (or router) up, and is this the endpoint it printed?"
        );
    }
    let session = match client {
        true => open_client_from(base, std::slice::from_ref(&connect), timeout_ms),
        // Listening too: the nodes learn of this process through the broker (gossip) and connect to it, which is
        // how their answers reach it (peers do not forward for each other). Zenoh gossips the addresses of a
        // wildcard listener, not of one bound to 127.0.0.1, hence 0.0.0.0 (for this process's few seconds only).
        false => open_listening_from(
            base,
            &["tcp/0.0.0.0:0".to_string()],
            std::slice::from_ref(&connect),
            timeout_ms,
        )
        .map(|(s, _)| s),
    }
    .map_err(|e| anyhow::anyhow!("cannot reach run `{id}` at {connect} within {} s: {e:#}", how.timeout))?;
    // Let zenoh learn the run's queryables (gossip) before the first question.
    std::thread::sleep(Duration::from_millis(1500));
    Ok((session, connect))
}

/// The address of a TCP or TLS endpoint (`tcp/HOST:PORT`, `tls/…`; metadata after `?` or `#` ignored) whose every
/// resolved address refused a connection: nothing listens there. `None` for any other endpoint or answer (one that
/// accepts, does not answer within a second, or cannot be resolved here: zenoh says what it finds).
fn refused(endpoint: &str) -> Option<String> {
    use std::net::{TcpStream, ToSocketAddrs};
    let rest = endpoint
        .strip_prefix("tcp/")
        .or_else(|| endpoint.strip_prefix("tls/"))?;
    let address = rest.split(['?', '#']).next()?;
    let resolved: Vec<_> = address.to_socket_addrs().ok()?.collect();
    let all_refused = !resolved.is_empty()
        && resolved.iter().all(|a| {
            TcpStream::connect_timeout(a, Duration::from_secs(1))
                .is_err_and(|e| e.kind() == std::io::ErrorKind::ConnectionRefused)
        });
    all_refused.then(|| address.to_string())
}

/// "running here: a, b" for the runs registered on this machine (`cosim inspect` lists them), or where none is.
fn running_here() -> String {
    let runs = registry::live();
    if runs.is_empty() {
        return format!("nothing in {}", registry::dir().display());
    }
    const SHOWN: usize = 5;
    let ids: Vec<&str> = runs.iter().take(SHOWN).map(|e| e.run.as_str()).collect();
    let more = match runs.len().saturating_sub(SHOWN) {
        0 => String::new(),
        n => format!(" and {n} more"),
    };
    format!("running here: {}{more}", ids.join(", "))
}

#[cfg(test)]
mod tests {
    use super::refused;

    /// A port closed on loopback is refused; one that listens, and endpoints that are not TCP, are not.
    #[test]
    fn a_closed_port_is_refused_and_a_listening_one_is_not() {
        let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        let open = listener.local_addr().unwrap().port();
        let closed = std::net::TcpListener::bind("127.0.0.1:0")
            .unwrap()
            .local_addr()
            .unwrap()
            .port();
        assert_eq!(
            refused(&format!("tcp/127.0.0.1:{closed}")).as_deref(),
            Some(&*format!("127.0.0.1:{closed}"))
        );
        assert_eq!(
            refused(&format!("tls/127.0.0.1:{closed}#iface=lo")).as_deref(),
            Some(&*format!("127.0.0.1:{closed}"))
        );
        assert_eq!(refused(&format!("tcp/127.0.0.1:{open}")), None);
        assert_eq!(refused(&format!("unixsock-stream//tmp/nothing-{closed}")), None);
        assert_eq!(refused("tcp/not an address"), None);
    }
}
