//! What the broker answers beside the steps (`docs/PROTOCOL.md` §2, §9): the run's scene, and each node's state to
//! start from. Both are queryables that answer the same bytes for as long as their handle lives.

use cosim_proto::keys::{key, topic, NodeTopics};
use zenoh::query::Queryable;
use zenoh::{Session, Wait};

/// Answer `cosim/<run>/scene` with the resolved scene (TOML text) for as long as the returned handle lives.
pub fn serve_scene(session: &Session, run: &str, scene_toml: String) -> anyhow::Result<Queryable<()>> {
    session
        .declare_queryable(key(run, topic::SCENE))
        .callback(move |query| {
            if let Err(e) = query.reply(query.key_expr().clone(), scene_toml.clone()).wait() {
                tracing::warn!("scene query: {e}");
            }
        })
        .wait()
        .map_err(|e| anyhow::anyhow!("{e}"))
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
    session
        .declare_queryable(key(run, topics.restore))
        .callback(move |query| {
            if let Err(e) = query.reply(query.key_expr().clone(), bytes.clone()).wait() {
                tracing::warn!("restore query: {e}");
            }
        })
        .wait()
        .map_err(|e| anyhow::anyhow!("{e}"))
}
