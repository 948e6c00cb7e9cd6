//! Logging of the run's processes, whose stderr is a log file in the run's output folder (`DIR/logs/`): on the very
//! disk a run may fill. A log line that cannot be written is lost, never a panic (Rust's `eprintln!` panics when
//! stderr fails, and so does `tracing-subscriber` by default, reporting the failure through `eprintln!`): a full
//! disk must end the run with its summary, not kill the process that writes it.

use std::io::Write;

/// Log `tracing` events on stderr (level from `RUST_LOG`, default `warn`), dropping those that cannot be written.
pub fn init() {
    tracing_subscriber::fmt()
        .with_env_filter(tracing_subscriber::EnvFilter::try_from_default_env().unwrap_or_else(|_| "warn".into()))
        .with_writer(std::io::stderr)
        .log_internal_errors(false)
        .init();
}

/// Write `line` and a line break on stderr; lost if stderr cannot be written.
pub fn say(line: &str) {
    let mut err = std::io::stderr().lock();
    let _ = writeln!(err, "{line}");
}
