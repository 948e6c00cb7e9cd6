//! Messages refused on the wire, logged without letting the sender fill the disk: the first [`LOGGED`] in full,
//! then one line at each power of ten with the count and the last reason. A peer that sent 50,000 well-framed
//! states for a future step wrote 7.4 MB of log lines, one a message, none in the disk estimate (found 2026-12-06 by
//! the sweep of hostile external nodes, D19).

use std::fmt::Display;

/// How many refusals are logged one by one.
pub const LOGGED: u64 = 10;

/// Whether the `n`-th refusal (from 1) gets a log line: the first [`LOGGED`], then 100, 1,000, 10,000, …
pub fn logs(n: u64) -> bool {
    n <= LOGGED || (n >= 100 && n.checked_ilog10().is_some_and(|k| 10u64.pow(k) == n))
}

/// The refusals of one kind of message from one sender.
#[derive(Debug)]
pub struct Refusals {
    /// Who refused it and what: `fem-node: refused a state message`.
    what: String,
    count: u64,
}

impl Refusals {
    /// Refusals of `what` (`"fem-node: refused a state message"`), none yet.
    pub fn new(what: impl Into<String>) -> Self {
        Self {
            what: what.into(),
            count: 0,
        }
    }

    /// Count one refusal, and log it where [`logs`] says.
    pub fn note(&mut self, why: &dyn Display) {
        self.count = self.count.saturating_add(1);
        let n = self.count;
        if !logs(n) {
            return;
        }
        let what = &self.what;
        match n {
            LOGGED => tracing::error!("{what}: {why} (the {LOGGED}th; from here on one line at 100, 1000, …)"),
            n if n < LOGGED => tracing::error!("{what}: {why}"),
            n => tracing::error!("{what}: {n} so far, the last: {why}"),
        }
    }

    /// How many were refused.
    pub fn count(&self) -> u64 {
        self.count
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 50,000 refusals are 13 lines: the first ten, then 100, 1,000 and 10,000 (and 100,000 would be the next).
    #[test]
    fn a_flood_is_logged_in_a_few_lines() {
        let lines: Vec<u64> = (1..=50_000).filter(|&n| logs(n)).collect();
        assert_eq!(lines, [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 100, 1000, 10_000]);
        assert!(logs(10u64.pow(19)));
        assert!(!logs(u64::MAX));
        let mut r = Refusals::new("fem-node: refused a state message");
        (0..1234).for_each(|_| r.note(&"for step 9"));
        assert_eq!(r.count(), 1234);
    }
}
