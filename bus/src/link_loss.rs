//! A partner's liveliness token that disappears is not always a partner that died: a link lost and restored
//! (a router restarted, a connection reset on a loaded host) undeclares every token seen through it, and zenoh,
//! which reconnects at once, declares them again when the link is back. The broker and the nodes watch each
//! other's tokens (`docs/PROTOCOL.md` §8), so before one of them calls its partner gone it waits up to [`GRACE`]
//! for the token to be held again; the messages lost meanwhile are sent again by the broker's resend (§8).
//!
//! What this costs: a partner killed without a word is called gone [`GRACE`] later. A partner that fails says so
//! first (its error topic), and a broker that ends a run tells its nodes to stop, so neither waits.

use std::time::{Duration, Instant};

use zenoh::Session;

/// How long a partner's token may be away before the partner is called gone: a zenoh client retries its router
/// at once and then every second, so a router back within a second or two is joined again within this.
pub const GRACE: Duration = Duration::from_secs(4);

/// How often the token is asked for while it is away.
const POLL: Duration = Duration::from_millis(200);

/// After `key`'s token disappeared: whether it is held again within `grace`, asked every [`POLL`], and how long
/// it was looked for. A query that cannot be sent (the session's link is down) counts as not held yet.
pub fn comes_back(session: &Session, key: &str, grace: Duration) -> (bool, Duration) {
    let start = Instant::now();
    loop {
        let asked = Instant::now();
        if crate::claim::held(session, key, POLL).unwrap_or(false) {
            return (true, start.elapsed());
        }
        if start.elapsed() >= grace {
            return (false, start.elapsed());
        }
        // Without a link the query returns at once: do not spin.
        std::thread::sleep(POLL.saturating_sub(asked.elapsed()));
    }
}
