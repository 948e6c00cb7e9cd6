//! A run id claims its key space (`docs/PROTOCOL.md` §2): every process of a run holds a liveliness token,
//! `cosim/<run>/broker/alive` for the broker, `cosim/<run>/<node>/alive` for a node, and a process that finds its
//! own token already held refuses to start, before it declares anything on the run's keys (a subscriber, a
//! queryable, a token), so that the run already there goes on undisturbed. Two runs on one id would otherwise
//! take in each other's messages: each node answers whichever broker's command comes first, and a command for
//! another run's step is refused and lost.
//!
//! Zenoh answers a liveliness query from its table of declared tokens (the router's, through a router), so the
//! check costs one round trip. What it cannot see is a process that declares its token between this check and its
//! own declaration, milliseconds later; nor, in peer mode (every process connected to the broker, no router), the
//! token of another node: a peer answers for its own tokens only. So a node also asks the broker's status
//! ([`ensure_not_started`]), and refuses a run served by two brokers (`crate::serve`).

use std::time::Duration;

use cosim_proto::keys::key;
use zenoh::{Session, Wait};

/// How long a liveliness query may take: zenoh answers it from the tokens it knows, within milliseconds; this only
/// bounds a network that does not answer at all.
pub const CLAIM_TIMEOUT: Duration = Duration::from_secs(2);

/// The run already has the process that was to start: it was refused (exit code 2, like other refused input).
#[derive(Debug, thiserror::Error)]
#[error(
    "run `{run}` already has a live {who} (its liveliness token {key} is held): refusing to start another one on \
     it, which would take in that run's messages; wait until it ends or pick another run id"
)]
pub struct Taken {
    /// The run id.
    pub run: String,
    /// The program refused (`contact-broker`, `fem-node`, `sph-node`).
    pub who: String,
    /// The liveliness key found held.
    pub key: String,
}

/// Refuse (with [`Taken`]) when the liveliness token `cosim/<run>/<alive>` of `who` is already held by a process
/// that `session` can reach. Call it before declaring anything on the run's keys.
pub fn ensure_free(session: &Session, run: &str, alive: &str, who: &str) -> anyhow::Result<()> {
    let key = key(run, alive);
    match held(session, &key, CLAIM_TIMEOUT)
        .map_err(|e| anyhow::anyhow!("cannot ask whether run `{run}` is live ({key}): {e}"))?
    {
        true => Err(Taken {
            run: run.into(),
            who: who.into(),
            key,
        }
        .into()),
        false => Ok(()),
    }
}

/// Whether a liveliness token on `key` is held by a process that `session` can reach, asked once (a liveliness
/// `get`, answered within `timeout`).
pub fn held(session: &Session, key: &str, timeout: Duration) -> zenoh::Result<bool> {
    let replies = session.liveliness().get(key).timeout(timeout).wait()?;
    // The channel closes once every answer is in (or at the timeout); any token answering means it is held.
    while let Ok(reply) = replies.recv() {
        if reply.result().is_ok() {
            return Ok(true);
        }
    }
    Ok(false)
}

/// Whether `e` is a refusal by [`ensure_free`] or [`ensure_not_started`] (or by a node that found its run served by
/// two brokers), anywhere in its chain of causes.
pub fn is_refusal(e: &anyhow::Error) -> bool {
    e.chain()
        .any(|c| c.is::<Taken>() || c.is::<Started>() || c.is::<Ambiguous>())
}

/// The run's broker is past the registration of its nodes: a node that joins now is not one it waits for.
#[derive(Debug, thiserror::Error)]
#[error(
    "run `{run}` is under way already (its contact-broker's status, {key}, says `{health}`): refusing to join it as \
     another {who}"
)]
pub struct Started {
    /// The run id.
    pub run: String,
    /// The node refused.
    pub who: String,
    /// The broker's status key.
    pub key: String,
    /// The health the broker reported.
    pub health: String,
}

/// Refuse (with [`Started`]) to join run `run` as `who` when its broker's live status (`crate::status`) says that it
/// no longer waits for its nodes (health other than `starting`). This sees what [`ensure_free`] cannot in peer mode:
/// the broker answers its status itself. A broker that does not answer (none yet, or a program of another kind) is
/// no reason to refuse.
pub fn ensure_not_started(session: &Session, run: &str, who: &str) -> anyhow::Result<()> {
    let key = key(run, cosim_proto::keys::topic::BROKER_STATUS);
    let replies = session
        .get(&key)
        .timeout(CLAIM_TIMEOUT)
        .wait()
        .map_err(|e| anyhow::anyhow!("cannot ask for the status of run `{run}` ({key}): {e}"))?;
    while let Ok(reply) = replies.recv() {
        let Ok(sample) = reply.result() else { continue };
        let status: Option<serde_json::Value> = serde_json::from_slice(&sample.payload().to_bytes()).ok();
        let health = status
            .as_ref()
            .and_then(|s| s.get("health"))
            .and_then(|h| h.as_str())
            .unwrap_or("starting");
        if health != "starting" {
            return Err(Started {
                run: run.into(),
                who: who.into(),
                key,
                health: health.into(),
            }
            .into());
        }
    }
    Ok(())
}

/// A node found its run served by more than one broker: two runs on one run id started within the moment
/// [`ensure_free`] cannot see. It refuses to join either.
#[derive(Debug, thiserror::Error)]
#[error(
    "run `{run}` is served by {brokers} brokers (each answered {key}): two runs on one run id; refusing to join \
     either, since their messages would cross"
)]
pub struct Ambiguous {
    /// The run id.
    pub run: String,
    /// How many brokers answered.
    pub brokers: usize,
    /// The scene key they answered.
    pub key: String,
}
