//! `fem-node`: the structure solver as its own process.

use clap::Parser;
use fem_node::node::{serve, NodeOptions};

/// Explicit 2D FEM structure node of the co-simulation.
#[derive(Parser, Debug)]
#[command(version, about)]
struct Args {
    /// Run id to join.
    #[arg(long)]
    run: String,
    /// Endpoint of the broker or a router, e.g. tcp/127.0.0.1:7447.
    #[arg(long, required = true)]
    connect: Vec<String>,
    /// Endpoints to listen on.
    #[arg(long)]
    listen: Vec<String>,
    /// Seconds to wait for the connection and the scene.
    #[arg(long, default_value_t = 5.0)]
    timeout: f64,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
}

fn main() {
    tracing_subscriber::fmt()
        .with_env_filter(tracing_subscriber::EnvFilter::try_from_default_env().unwrap_or_else(|_| "warn".into()))
        .with_writer(std::io::stderr)
        .init();
    let args = Args::parse();
    if let Some(n) = args.threads {
        if let Err(e) = rayon::ThreadPoolBuilder::new().num_threads(n).build_global() {
            eprintln!("fem-node: --threads {n}: {e}");
            std::process::exit(1);
        }
    }
    let opts = NodeOptions {
        run: args.run,
        connect: args.connect,
        listen: args.listen,
        timeout_ms: (args.timeout * 1000.0) as u64,
    };
    if let Err(e) = serve(&opts) {
        eprintln!("fem-node: {}", format!("{e:#}").replace('\n', " "));
        std::process::exit(1);
    }
}
