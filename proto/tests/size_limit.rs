//! Messages over the size limit (`docs/PROTOCOL.md` §3). zenoh drops a message over its `max_message_size` (1 GiB by
//! default, on every peer and router on the way) with nothing logged above its trace level, so the sender checks the
//! size first and refuses with one line naming the topic and the size. No gigabyte is needed here: the check takes its
//! limit as an argument. (A receiver refuses a length prefix that claims more than the payload holds:
//! `codec.rs`, `huge_length_prefixes_are_malformed_without_allocating`.)

use cosim_proto::envelope::{CodecError, Envelope, MAX_MESSAGE_BYTES, MAX_SEND_BYTES};
use cosim_proto::messages::NodeCheckpoint;

fn checkpoint(bytes: usize) -> NodeCheckpoint {
    NodeCheckpoint {
        node: "sph-node".into(),
        data: vec![7; bytes],
    }
}

#[test]
fn a_message_over_the_limit_is_refused_by_its_sender_naming_the_topic_and_the_size() {
    let env = Envelope::new("r1", 3, 0.5, checkpoint(1000));
    let size = env.encode().len() as u64;
    // At the limit it goes, byte for byte what `encode` gives.
    assert_eq!(env.encode_within("sph/checkpoint", size).unwrap(), env.encode());
    let e = env.encode_within("sph/checkpoint", size - 1).unwrap_err();
    assert!(
        matches!(e, CodecError::TooLarge { what: "sph/checkpoint", bytes, limit } if bytes == size && limit == size - 1),
        "{e:?}"
    );
    let text = e.to_string();
    assert!(
        text.contains("sph/checkpoint") && text.contains(&format!("{size} bytes")),
        "{text}"
    );
    // The wire's own limit leaves zenoh room for its header under its 1 GiB.
    const { assert!(MAX_SEND_BYTES < MAX_MESSAGE_BYTES) };
    assert!(env.encode_checked("sph/checkpoint").is_ok());
}
