//! `cosim`: run, check, compare, inspect, ctl, snapshot, replay, bench, router.

use std::process::ExitCode;

use clap::Parser;
use cosim::cli::{Cli, Command};

fn main() -> ExitCode {
    cosim::closed_stdout::quiet_on_closed_stdout();
    let cli = Cli::parse();
    // `cosim run` opens a zenoh session only to ask whether its run id is live (`run::run`); zenoh's own lines about
    // a router it cannot join are the broker's to log, in its log file, and its one line says what went wrong.
    let filter = match cli.command {
        Command::Run(_) => "warn,zenoh=off",
        _ => "warn,zenoh=error",
    };
    tracing_subscriber::fmt()
        .with_env_filter(tracing_subscriber::EnvFilter::try_from_default_env().unwrap_or_else(|_| filter.into()))
        .with_writer(std::io::stderr)
        // Colour codes only in a terminal: `cosim run … 2> run.log` keeps plain lines.
        .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stderr()))
        // A log line that cannot be written (stderr on a full disk) is lost rather than a panic.
        .log_internal_errors(false)
        .init();
    let result = match cli.command {
        Command::Run(args) => cosim::run::run(&args),
        Command::Check(args) => cosim::check::check(&args),
        Command::Compare(args) => cosim::compare::compare(&args),
        Command::Bench(args) => cosim::bench::bench(&args),
        Command::BenchRun(args) => cosim::bench::bench_run(&args),
        Command::Inspect(args) => cosim::inspect::inspect(&args),
        Command::Router(args) => cosim::router::router(&args),
        Command::Replay(args) => cosim::replay::replay(&args),
        Command::Ctl(args) => cosim::ctl::ctl(&args),
        Command::Snapshot(args) => cosim::snapshot::snapshot(&args),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("cosim: {}", format!("{e:#}").replace('\n', " "));
            ExitCode::from(2)
        }
    }
}
