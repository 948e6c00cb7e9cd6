//! The answer to a node's restore query (`docs/PROTOCOL.md` §9): the node's saved checkpoint, or an empty one for
//! a fresh start, in its envelope. The broker serves it (`transport::serve_restore`), the recorder keeps it and
//! `cosim replay` serves it again.

use cosim_proto::envelope::Envelope;
use cosim_proto::keys::NodeTopics;
use cosim_proto::messages::NodeCheckpoint;

/// The reply `transport::serve_restore` gives, encoded: `saved` is the node's (step, t, checkpoint bytes), `None`
/// for a fresh start.
pub fn restore_reply(run: &str, topics: NodeTopics, saved: Option<(u64, f64, Vec<u8>)>) -> anyhow::Result<Vec<u8>> {
    let (step, t, data) = saved.unwrap_or((0, 0.0, Vec::new()));
    let body = NodeCheckpoint {
        node: topics.name.into(),
        data,
    };
    Ok(Envelope::new(run, step, t, body).encode_checked(topics.restore)?)
}
