//! The versioned envelope every message travels in, and its bincode codec (`DESIGN.md` §3, `docs/PROTOCOL.md`).

use serde::{de::DeserializeOwned, Deserialize, Serialize};

/// Protocol version this build speaks. 2: `SphSetup::sensors` and `SphSnapshot::sensors` (interval-mean pressure
/// sensors). 3: `Correction::face` (the structure's face behind a particle a `particle_particle` pass corrected).
pub const PROTOCOL_VERSION: u32 = 3;

/// `{protocol_version, run, step, t, body}`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Envelope<B> {
    /// Must equal [`PROTOCOL_VERSION`].
    pub protocol_version: u32,
    /// Run id; must equal the receiver's.
    pub run: String,
    /// Coupling step the message belongs to.
    pub step: u64,
    /// Simulated time [s].
    pub t: f64,
    /// The message.
    pub body: B,
}

/// Why a message was refused.
#[derive(Debug, thiserror::Error)]
pub enum CodecError {
    /// The bytes do not decode as the expected message.
    #[error("malformed {what} message ({len} bytes): {error}")]
    Malformed {
        /// Expected message type.
        what: &'static str,
        /// Payload length.
        len: usize,
        /// Decoder error. In the message, not a `source`: an error chain printed whole (`{:#}`) said bincode's
        /// reason twice, "string is not valid utf8: …: string is not valid utf8: …" (the 2026-12-06 sweep, D25).
        error: bincode::Error,
    },
    /// Another protocol version.
    #[error("{what} message speaks protocol version {got}, this build speaks {PROTOCOL_VERSION}")]
    Version {
        /// Expected message type.
        what: &'static str,
        /// Version found.
        got: u32,
    },
    /// Another run.
    #[error("{what} message belongs to run `{got}`, not `{expected}`")]
    Run {
        /// Expected message type.
        what: &'static str,
        /// Run found.
        got: String,
        /// Run expected.
        expected: String,
    },
    /// Too large to send: zenoh would drop it unseen ([`MAX_SEND_BYTES`]).
    #[error(
        "{what} message of {bytes} bytes ({:.2} GiB) is over the limit of {limit} bytes a message may have \
         (docs/PROTOCOL.md §3): not sent",
        *bytes as f64 / (1u64 << 30) as f64
    )]
    TooLarge {
        /// The message's topic.
        what: &'static str,
        /// Its encoded size.
        bytes: u64,
        /// The limit.
        limit: u64,
    },
    /// Another step.
    #[error("{what} message is for step {got}, expected step {expected}")]
    Step {
        /// Expected message type.
        what: &'static str,
        /// Step found.
        got: u64,
        /// Step expected.
        expected: u64,
    },
}

/// Largest message accepted by the decoder (guards against length prefixes that claim gigabytes).
pub const MAX_MESSAGE_BYTES: u64 = 1 << 30;

/// Largest message a sender puts on the wire ([`Envelope::encode_checked`]). zenoh drops a message over its
/// `max_message_size` (1 GiB by default, on every peer and router on the way) with nothing logged above its trace
/// level, so the receiver would only time out; its own header comes on top of ours, and this leaves it 64 KiB.
pub const MAX_SEND_BYTES: u64 = MAX_MESSAGE_BYTES - (1 << 16);

/// One fixed configuration, documented byte for byte in docs/PROTOCOL.md: little endian, fixed-width integers,
/// u64 length prefixes.
fn encoder() -> impl bincode::Options {
    use bincode::Options;
    bincode::DefaultOptions::new()
        .with_little_endian()
        .with_fixint_encoding()
}

/// The encoder's layout; no trailing bytes, and no length prefix may claim more than [`MAX_MESSAGE_BYTES`].
fn options() -> impl bincode::Options {
    use bincode::Options;
    encoder().reject_trailing_bytes().with_limit(MAX_MESSAGE_BYTES)
}

impl<B: Serialize> Envelope<B> {
    /// Wrap a body for the current protocol version.
    pub fn new(run: &str, step: u64, t: f64, body: B) -> Self {
        Self {
            protocol_version: PROTOCOL_VERSION,
            run: run.to_string(),
            step,
            t,
            body,
        }
    }

    /// Encode with the fixed bincode configuration.
    pub fn encode(&self) -> Vec<u8> {
        use bincode::Options;
        // Serialising plain data into memory with no size limit has no failure path.
        encoder()
            .serialize(self)
            .expect("in-memory bincode encoding of plain data")
    }

    /// [`Envelope::encode`] for sending on topic `what`: refused ([`CodecError::TooLarge`], naming the topic and
    /// the size) over [`MAX_SEND_BYTES`], which zenoh would drop without a word.
    pub fn encode_checked(&self, what: &'static str) -> Result<Vec<u8>, CodecError> {
        self.encode_within(what, MAX_SEND_BYTES)
    }

    /// [`Envelope::encode_checked`] with the limit `limit` bytes. The size is computed before anything is encoded.
    pub fn encode_within(&self, what: &'static str, limit: u64) -> Result<Vec<u8>, CodecError> {
        use bincode::Options;
        // As in `encode`: sizing plain data has no failure path.
        let bytes = encoder().serialized_size(self).expect("bincode sizing of plain data");
        if bytes > limit {
            return Err(CodecError::TooLarge { what, bytes, limit });
        }
        Ok(self.encode())
    }
}

impl<B: DeserializeOwned> Envelope<B> {
    /// Decode and check version and run. `what` names the message in errors.
    pub fn decode(bytes: &[u8], run: &str, what: &'static str) -> Result<Self, CodecError> {
        use bincode::Options;
        // The first 4 bytes are always the version: check it before the body so a newer peer gets a version
        // error, not a decode error, whatever its layout.
        if let Some(h) = bytes.get(..4) {
            let version = u32::from_le_bytes([h[0], h[1], h[2], h[3]]);
            if version != PROTOCOL_VERSION {
                return Err(CodecError::Version { what, got: version });
            }
        }
        let env: Envelope<B> = options().deserialize(bytes).map_err(|error| CodecError::Malformed {
            what,
            len: bytes.len(),
            error,
        })?;
        if env.run != run {
            return Err(CodecError::Run {
                what,
                got: env.run,
                expected: run.to_string(),
            });
        }
        Ok(env)
    }

    /// Refuse a message for another step.
    pub fn expect_step(self, step: u64, what: &'static str) -> Result<Self, CodecError> {
        if self.step == step {
            Ok(self)
        } else {
            Err(CodecError::Step {
                what,
                got: self.step,
                expected: step,
            })
        }
    }
}
