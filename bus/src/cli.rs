//! The command line every solver node binary shares:
//! `--run ID --connect ENDPOINT [--client] [--zenoh-config FILE] [--threads N]`.

use std::path::PathBuf;

use clap::Parser;
use cosim_proto::keys::NodeTopics;
use cosim_proto::scene::Scene;

use crate::serve::{serve, Failure, NodeCore, NodeOptions};

/// A solver node of the co-simulation: joins run ID through ENDPOINT and serves it to the end.
#[derive(Parser, Debug)]
#[command(version)]
struct Args {
    /// Run id to join.
    #[arg(long)]
    run: String,
    /// Endpoint of the broker or a router, e.g. tcp/127.0.0.1:7447.
    #[arg(long, required = true, value_parser = crate::session::endpoint)]
    connect: Vec<String>,
    /// Endpoints to listen on.
    #[arg(long, value_parser = crate::session::endpoint)]
    listen: Vec<String>,
    /// Seconds to wait for the connection and the scene.
    #[arg(long, value_parser = crate::seconds::positive, default_value_t = 5.0)]
    timeout: f64,
    /// Worker threads (default: all cores; 1 to 1024).
    #[arg(long, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..=1024))]
    threads: Option<usize>,
    /// `--connect` is a zenoh router (`zenohd`): join through it as a client, as every process of the run must.
    #[arg(long, conflicts_with = "listen")]
    client: bool,
    /// A zenoh JSON5 config file the session starts from (user and password, TLS certificates, …); the node's own
    /// settings (mode, endpoints, multicast scouting off, timeouts) are put on top of it.
    #[arg(long, value_name = "FILE")]
    zenoh_config: Option<PathBuf>,
}

/// The whole `main` of a node binary: parse the arguments, serve, and exit non-zero with one line on stderr (2 for a
/// run that refuses it, `crate::claim`; 1 for any other failure).
pub fn node_main<C: NodeCore>(topics: NodeTopics, build: impl FnOnce(&Scene) -> Result<C, Failure>) -> ! {
    crate::log::init();
    let args = Args::parse();
    let fail = |message: String, code: i32| -> ! {
        crate::log::say(&format!("{}: {}", topics.name, message.replace('\n', " ")));
        crate::session::stop_runtime();
        std::process::exit(code)
    };
    if let Some(n) = args.threads {
        if let Err(e) = rayon::ThreadPoolBuilder::new().num_threads(n).build_global() {
            fail(format!("--threads {n}: {e}"), 1);
        }
    }
    let opts = NodeOptions {
        run: args.run,
        connect: args.connect,
        listen: args.listen,
        timeout_ms: crate::seconds::wait(args.timeout).as_millis() as u64,
        client: args.client,
        zenoh_config: args.zenoh_config,
    };
    match serve(&opts, topics, build) {
        Ok(()) => {
            crate::session::stop_runtime();
            std::process::exit(0)
        }
        // A run id that is taken (`crate::claim`) is refused input, as for `cosim run`: exit code 2.
        Err(e) => fail(format!("{e:#}"), if crate::claim::is_refusal(&e) { 2 } else { 1 }),
    }
}
