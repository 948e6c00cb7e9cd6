//! A query asked again while nobody can answer it yet. A zenoh `get` that finds no queryable for its key ends at
//! once with no answer; it does not wait for one to appear. So a query made while the answering side's declaration
//! is still on its way — a node started as soon as its broker's session was open, asking through a router that has
//! not heard of the broker's queryable yet (seen over TLS, CI of 2026-11-28), or a link lost and restored, which
//! takes every declaration seen through it away until zenoh declares it again (`crate::link_loss`; seen in a local
//! suite run of 2026-12-06: a node's `restore` query got no answer at start-up and the run failed) — would read
//! "nobody answers" where someone will within moments. [`ask`] asks again every [`RETRY`] until its timeout
//! while no answer came. The keys asked this way are answered by every process that serves them, so asking twice
//! changes nothing.

use std::time::{Duration, Instant};

use zenoh::query::{ConsolidationMode, Reply};
use zenoh::{Session, Wait};

/// How often a query is asked again while nobody answers it.
pub const RETRY: Duration = Duration::from_millis(200);

/// Every answer to a `get` on `key`, asked again every [`RETRY`] while none came, for at most `timeout` in all: an
/// empty list means nobody answered within `timeout`. Every answer is kept (consolidation off: zenoh would
/// otherwise keep one answer per key, and a caller may need to know that two processes answered).
pub fn ask(session: &Session, key: &str, timeout: Duration) -> zenoh::Result<Vec<Reply>> {
    ask_within(session, key, timeout, timeout)
}

/// As [`ask`], but asked again only within `retry_for` of the first try: after that a query that finds nobody
/// ends the wait. For a partner that may be gone: the broker's checkpoint query to a node that died would
/// otherwise wait out the whole `timeout` (a step's), where a link lost and restored is back within
/// [`crate::link_loss::GRACE`].
pub fn ask_within(session: &Session, key: &str, timeout: Duration, retry_for: Duration) -> zenoh::Result<Vec<Reply>> {
    let start = Instant::now();
    let deadline = start + timeout;
    let retry_until = start + retry_for.min(timeout);
    loop {
        let asked = Instant::now();
        let left = deadline.saturating_duration_since(asked);
        let replies = session
            .get(key)
            .consolidation(ConsolidationMode::None)
            .timeout(left.max(RETRY))
            .wait()?;
        // The channel closes once every queryable answered (or at the timeout).
        let answers: Vec<Reply> = std::iter::from_fn(|| replies.recv().ok()).collect();
        let now = Instant::now();
        if !answers.is_empty() || now + RETRY >= deadline || now + RETRY >= retry_until {
            return Ok(answers);
        }
        // A query that found nobody returns at once: do not spin.
        std::thread::sleep(RETRY.saturating_sub(asked.elapsed()));
    }
}
