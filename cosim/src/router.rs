//! `cosim router --listen ENDPOINT [--zenoh-config FILE]`: a zenoh router as its own process, the hub of a run
//! spread over hosts (every process of the run joins it as a client, `--connect ENDPOINT --client`). It is the
//! router `zenohd` runs (`zenohd -l ENDPOINT --no-multicast-scouting [-c FILE]`), with the project's settings:
//! router mode, multicast scouting off, listen on the given endpoints and connect to nothing.
//!
//! Prints one JSON line on stdout, `{"event":"listening","endpoints":[...]}`, once it listens, then serves until
//! it is killed (SIGTERM, SIGINT).

use std::io::Write;
use std::process::ExitCode;

use anyhow::Context;

use crate::cli::RouterArgs;

/// How long binding a listen endpoint may take.
const LISTEN_TIMEOUT_MS: u64 = 5000;

/// Run `cosim router`; returns only on an error (exit 2).
pub fn router(args: &RouterArgs) -> anyhow::Result<ExitCode> {
    let base = args.zenoh_config.as_deref();
    // A bad config file is its own error, not "cannot listen".
    cosim_bus::session::base_config(base)?;
    let (_session, endpoints) = cosim_bus::session::open_router(base, &args.listen, LISTEN_TIMEOUT_MS)
        .with_context(|| format!("cannot open a zenoh router listening on {:?}", args.listen))?;
    let mut out = std::io::stdout().lock();
    writeln!(
        out,
        "{}",
        serde_json::json!({"event": "listening", "endpoints": endpoints})
    )?;
    out.flush()?;
    drop(out);
    // zenoh serves on its own threads; this one only keeps the session alive until the process is killed.
    loop {
        std::thread::park();
    }
}
