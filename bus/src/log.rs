//! Logging of the run's processes, whose stderr is a log file in the run's output folder (`DIR/logs/`): on the very
//! disk a run may fill. A log line that cannot be written is lost, never a panic (Rust's `eprintln!` panics when
//! stderr fails, and so does `tracing-subscriber` by default, reporting the failure through `eprintln!`): a full
//! disk must end the run with its summary, not kill the process that writes it.

use std::io::{IsTerminal, Write};

/// What a node's log keeps without `RUST_LOG`: warnings from everything, and the run's own events (`info`) from
/// our crates — a checkpoint written, the contact's reaction relaxation or step bound chosen, a pause — which
/// happen a few times a run and say in the log file what the run did; zenoh's own `info` lines stay out.
pub const DEFAULT_FILTER: &str = "warn,contact_broker=info,sph_node=info,fem_node=info,cosim_bus=info";

/// Log `tracing` events on stderr (level from `RUST_LOG`, default [`DEFAULT_FILTER`]), dropping those that cannot
/// be written.
pub fn init() {
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env().unwrap_or_else(|_| DEFAULT_FILTER.into()),
        )
        .with_writer(std::io::stderr)
        // A node's stderr is its log file: colour codes only where a person reads it in a terminal.
        .with_ansi(std::io::stderr().is_terminal())
        .log_internal_errors(false)
        .init();
}

/// Write `line` and a line break on stderr; lost if stderr cannot be written.
pub fn say(line: &str) {
    let mut err = std::io::stderr().lock();
    let _ = writeln!(err, "{line}");
}
