//! `cosim`: run, check, compare, bench, inspect, router.

use std::process::ExitCode;

use clap::Parser;
use cosim::cli::{Cli, Command};

fn main() -> ExitCode {
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env().unwrap_or_else(|_| "warn,zenoh=error".into()),
        )
        .with_writer(std::io::stderr)
        .init();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run(args) => cosim::run::run(&args),
        Command::Check(args) => cosim::check::check(&args),
        Command::Compare(args) => cosim::compare::compare(&args),
        Command::Bench(args) => cosim::bench::bench(&args),
        Command::BenchRun(args) => cosim::bench::bench_run(&args),
        Command::Inspect(args) => cosim::inspect::inspect(&args),
        Command::Router(args) => cosim::router::router(&args),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("cosim: {}", format!("{e:#}").replace('\n', " "));
            ExitCode::from(2)
        }
    }
}
