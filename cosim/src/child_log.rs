//! What a child process's log says, in one line: the panic when it panicked (its message, not the backtrace
//! after it), else its last non-empty line. `cosim run` says it where a node or the broker failed.

use std::path::Path;

/// What a log says last, to explain a failure in one line: the panic when the process panicked (its message, not
/// the backtrace after it), else the last non-empty line.
pub fn last_line(log: &Path) -> String {
    let text = std::fs::read_to_string(log).unwrap_or_default();
    panic_in(&text)
        .or_else(|| text.lines().rev().find(|l| !l.trim().is_empty()).map(str::to_string))
        .unwrap_or_else(|| "(no message)".into())
}

/// The last panic in a log, as "panicked at FILE:LINE:COL: MESSAGE" (Rust writes the message on the next line).
fn panic_in(text: &str) -> Option<String> {
    let mut lines = text.lines();
    let mut found = None;
    while let Some(line) = lines.next() {
        if let Some(at) = line.find("panicked at ") {
            let place = line[at..].trim_end().trim_end_matches(':');
            let message = lines.next().map(str::trim).unwrap_or_default();
            found = Some(format!("{place}: {message}"));
        }
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A panic is said by its message, not by the backtrace's last line.
    #[test]
    fn a_panic_is_said_by_its_message() {
        let log = "2026-12-06T14:30:08Z  WARN zenoh: Scouting delay elapsed\n\
                   thread 'main' (19754) panicked at library/core/src/time.rs:962:23:\n\
                   cannot convert float seconds to Duration: value is either too big or NaN\n\
                   stack backtrace:\n   5: main\nnote: Some details are omitted\n";
        assert_eq!(
            panic_in(log).as_deref(),
            Some(
                "panicked at library/core/src/time.rs:962:23: cannot convert float seconds to Duration: value is \
                 either too big or NaN"
            )
        );
        assert_eq!(panic_in("contact-broker: fem-node failed\n"), None);
    }
}
