//! What the broker answers beside the steps (`docs/PROTOCOL.md` §2, §9): the run's scene, and each node's state to
//! start from. Both are queryables that answer the same bytes for as long as their handle lives.

use cosim_proto::keys::{key, topic, NodeTopics};
use zenoh::bytes::ZBytes;
use zenoh::query::Queryable;
use zenoh::{Session, Wait};

/// Answer `cosim/<run>/scene` with the resolved scene (TOML text) for as long as the returned handle lives.
pub fn serve_scene(session: &Session, run: &str, scene_toml: String) -> anyhow::Result<Queryable<()>> {
    serve(session, key(run, topic::SCENE), scene_toml.into(), "scene")
}

/// Answer `cosim/<run>/<node>/restore` (`docs/PROTOCOL.md` §9) for as long as the returned handle lives: the
/// node's state saved at step `step` (time `t`) when the run continues from a checkpoint, else an empty state
/// (start from the scene).
pub fn serve_restore(
    session: &Session,
    run: &str,
    topics: NodeTopics,
    saved: Option<(u64, f64, Vec<u8>)>,
) -> anyhow::Result<Queryable<()>> {
    let bytes = crate::checkpoint::restore_reply::restore_reply(run, topics, saved)?;
    serve(session, key(run, topics.restore), bytes.into(), "restore")
}

/// Answer every query on `key` with `reply`; `what` names it in the log when a reply cannot be sent.
fn serve(session: &Session, key: String, reply: ZBytes, what: &'static str) -> anyhow::Result<Queryable<()>> {
    session
        .declare_queryable(key)
        .callback(move |query| {
            if let Err(e) = query.reply(query.key_expr().clone(), reply.clone()).wait() {
                tracing::warn!("{what} query: {e}");
            }
        })
        .wait()
        .map_err(|e| anyhow::anyhow!("{e}"))
}
