//! The trace file of a recorded run (`cosim run --record`, `docs/PROTOCOL.md` §10): every message of the run as it
//! went over the wire, in the order the broker sent or received it, so that one node can be run again alone on
//! exactly the inputs it saw (`cosim replay`).
//!
//! Layout: a 16-byte file header, then records back to back until the end of the file. Each record carries its
//! own length and a CRC-32 of its contents, and is written with one `write` call, so a process killed at any point
//! leaves a file whose complete records all read back; [`parse`] stops at the first record that is cut short or
//! fails its checksum and says where. Nothing here does I/O: the writer and readers hand bytes in and out.

use std::fmt;

/// First 8 bytes of every trace file.
pub const MAGIC: [u8; 8] = *b"COSIMTRC";
/// Trace format version this build writes and reads.
pub const FORMAT: u32 = 1;
/// Bytes of the file header: magic, format (u32), protocol version (u32).
pub const HEADER_BYTES: usize = 16;
/// Bytes in front of a record's contents: length (u32), CRC-32 (u32).
pub const RECORD_HEADER_BYTES: usize = 8;
/// Bytes of a record's contents before its payload: kind (u8), node (u8), step (u64).
pub const RECORD_FIXED_BYTES: usize = 10;

/// What a record holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Kind {
    /// The scene the broker served on `scene` (TOML text, no envelope), once, first.
    Scene = 1,
    /// The broker's reply to `<node>/restore`: `Envelope<NodeCheckpoint>` (empty data: start from the scene).
    Restore = 2,
    /// A node's registration (`fem/mesh`, `sph/setup`), as received.
    Setup = 3,
    /// A step command (`broker/fem`, `broker/sph`), as sent (a command sent again is not recorded again).
    Command = 4,
    /// A node's answer (`fem/state`, `sph/state`), as received and accepted.
    State = 5,
    /// A node's failure report (`fem/error`, `sph/error`), as received.
    Error = 6,
    /// The end of the run: JSON `{status, message, steps, records, bytes, record_seconds}`, no envelope, last.
    End = 7,
}

impl Kind {
    /// The kind of byte `b`, if any.
    pub fn of(b: u8) -> Option<Self> {
        Some(match b {
            1 => Self::Scene,
            2 => Self::Restore,
            3 => Self::Setup,
            4 => Self::Command,
            5 => Self::State,
            6 => Self::Error,
            7 => Self::End,
            _ => return None,
        })
    }

    /// Its name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Self::Scene => "scene",
            Self::Restore => "restore",
            Self::Setup => "setup",
            Self::Command => "command",
            Self::State => "state",
            Self::Error => "error",
            Self::End => "end",
        }
    }
}

/// Which node a record is from or for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Node {
    /// The broker's own records (scene, end).
    Broker = 0,
    /// `fem-node`.
    Fem = 1,
    /// `sph-node`.
    Sph = 2,
}

impl Node {
    /// The node of byte `b`, if any.
    pub fn of(b: u8) -> Option<Self> {
        Some(match b {
            0 => Self::Broker,
            1 => Self::Fem,
            2 => Self::Sph,
            _ => return None,
        })
    }
}

/// One record.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Record {
    /// What it holds.
    pub kind: Kind,
    /// From or for which node.
    pub node: Node,
    /// The coupling step (the envelope's; 0 for the scene and restore records, the last step for the end).
    pub step: u64,
    /// The message as it went over the wire (an encoded envelope), or the text of a scene or end record.
    pub payload: Vec<u8>,
    /// Its place in the file, 0 for the first record, counting those [`parse_with`] left out: what a message about
    /// it names (a replay said "record 5" for the file's record 10, found 2026-12-06 by the sweep of damaged traces).
    pub index: usize,
}

/// The file header for a run speaking protocol `protocol_version`.
pub fn header(protocol_version: u32) -> [u8; HEADER_BYTES] {
    let mut h = [0u8; HEADER_BYTES];
    h[..8].copy_from_slice(&MAGIC);
    h[8..12].copy_from_slice(&FORMAT.to_le_bytes());
    h[12..16].copy_from_slice(&protocol_version.to_le_bytes());
    h
}

/// One record as written: length, CRC-32 of the contents, then the contents (kind, node, step, payload). `None` for
/// a payload too long for the u32 length (over 4 GiB; no message may be over 1 GiB).
pub fn encode(kind: Kind, node: Node, step: u64, payload: &[u8]) -> Option<Vec<u8>> {
    let len = u32::try_from(RECORD_FIXED_BYTES + payload.len()).ok()?;
    let mut out = Vec::with_capacity(RECORD_HEADER_BYTES + len as usize);
    out.extend_from_slice(&len.to_le_bytes());
    out.extend_from_slice(&[0u8; 4]);
    out.push(kind as u8);
    out.push(node as u8);
    out.extend_from_slice(&step.to_le_bytes());
    out.extend_from_slice(payload);
    let crc = crc32fast::hash(&out[RECORD_HEADER_BYTES..]);
    out[4..8].copy_from_slice(&crc.to_le_bytes());
    Some(out)
}

/// Why a trace cannot be read at all.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum TraceError {
    /// Shorter than its header, or another kind of file.
    #[error("not a cosim trace (its first bytes are not `COSIMTRC` and a 16-byte header)")]
    NotATrace,
    /// Written by a build with another trace format.
    #[error("trace format {got}; this build reads format {FORMAT}")]
    Format {
        /// Format found.
        got: u32,
    },
}

/// Where and why reading stopped before the end of the file: what a killed process leaves.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Torn {
    /// Byte offset of the record that could not be read.
    pub offset: usize,
    /// Why.
    pub why: String,
}

impl fmt::Display for Torn {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "record at byte {}: {}", self.offset, self.why)
    }
}

/// A trace as read.
#[derive(Clone, Debug, PartialEq)]
pub struct Trace {
    /// Protocol version of the run's messages.
    pub protocol_version: u32,
    /// Every complete record, in file order.
    pub records: Vec<Record>,
    /// Set when the file does not end after a complete record.
    pub torn: Option<Torn>,
}

/// Read a trace: the header, then records up to the end of the file or up to the first one that is incomplete,
/// fails its checksum or has an unknown kind or node (recorded in [`Trace::torn`]; what came before is kept).
pub fn parse(bytes: &[u8]) -> Result<Trace, TraceError> {
    parse_with(bytes, |_, _| true)
}

/// [`parse`], keeping only the records `keep` accepts (by kind and node): the others are checked but not copied,
/// so a reader of one node's part of a large trace holds little more than that part.
pub fn parse_with(bytes: &[u8], mut keep: impl FnMut(Kind, Node) -> bool) -> Result<Trace, TraceError> {
    let head = bytes.get(..HEADER_BYTES).ok_or(TraceError::NotATrace)?;
    if head[..8] != MAGIC {
        return Err(TraceError::NotATrace);
    }
    let u32_at = |b: &[u8], i: usize| u32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
    let format = u32_at(head, 8);
    if format != FORMAT {
        return Err(TraceError::Format { got: format });
    }
    let protocol_version = u32_at(head, 12);
    let mut records = Vec::new();
    let mut at = HEADER_BYTES;
    let mut index = 0;
    let torn = loop {
        if at == bytes.len() {
            break None;
        }
        let stop = |why: String| Some(Torn { offset: at, why });
        let Some(rh) = bytes.get(at..at + RECORD_HEADER_BYTES) else {
            break stop(format!("cut short ({} bytes of its 8-byte header)", bytes.len() - at));
        };
        let (len, crc) = (u32_at(rh, 0) as usize, u32_at(rh, 4));
        let start = at + RECORD_HEADER_BYTES;
        let Some(body) = bytes.get(start..start.saturating_add(len)) else {
            break stop(format!("cut short ({} of {len} bytes)", bytes.len() - start));
        };
        if len < RECORD_FIXED_BYTES {
            break stop(format!(
                "length {len} is below the {RECORD_FIXED_BYTES} bytes every record has"
            ));
        }
        let found = crc32fast::hash(body);
        if found != crc {
            break stop(format!("checksum crc32 {found:08x} where the record says {crc:08x}"));
        }
        let (Some(kind), Some(node)) = (Kind::of(body[0]), Node::of(body[1])) else {
            break stop(format!("unknown kind {} or node {}", body[0], body[1]));
        };
        let mut step = [0u8; 8];
        step.copy_from_slice(&body[2..RECORD_FIXED_BYTES]);
        at = start + len;
        index += 1;
        if !keep(kind, node) {
            continue;
        }
        records.push(Record {
            kind,
            node,
            step: u64::from_le_bytes(step),
            payload: body[RECORD_FIXED_BYTES..].to_vec(),
            index: index - 1,
        });
    };
    Ok(Trace {
        protocol_version,
        records,
        torn,
    })
}

/// An encoded envelope taken apart without decoding its body (`docs/PROTOCOL.md` §4).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RawEnvelope<'a> {
    /// `protocol_version`.
    pub protocol_version: u32,
    /// `run`.
    pub run: &'a str,
    /// `step`.
    pub step: u64,
    /// `t`.
    pub t: f64,
    /// The body's bytes, to the end of the message.
    pub body: &'a [u8],
}

impl<'a> RawEnvelope<'a> {
    /// Take `bytes` apart; `None` when they are too short for the header they announce or the run is not UTF-8.
    pub fn split(bytes: &'a [u8]) -> Option<Self> {
        let u64_at = |i: usize| -> Option<u64> {
            let mut b = [0u8; 8];
            b.copy_from_slice(bytes.get(i..i.checked_add(8)?)?);
            Some(u64::from_le_bytes(b))
        };
        let mut v = [0u8; 4];
        v.copy_from_slice(bytes.get(..4)?);
        let run_len = usize::try_from(u64_at(4)?).ok()?;
        let run_end = 12usize.checked_add(run_len)?;
        let run = std::str::from_utf8(bytes.get(12..run_end)?).ok()?;
        Some(Self {
            protocol_version: u32::from_le_bytes(v),
            run,
            step: u64_at(run_end)?,
            t: f64::from_bits(u64_at(run_end + 8)?),
            body: bytes.get(run_end + 16..)?,
        })
    }

    /// The same message for run `run`: header rebuilt, body bytes unchanged.
    pub fn for_run(&self, run: &str) -> Vec<u8> {
        let mut out = Vec::with_capacity(28 + run.len() + self.body.len());
        out.extend_from_slice(&self.protocol_version.to_le_bytes());
        out.extend_from_slice(&(run.len() as u64).to_le_bytes());
        out.extend_from_slice(run.as_bytes());
        out.extend_from_slice(&self.step.to_le_bytes());
        out.extend_from_slice(&self.t.to_bits().to_le_bytes());
        out.extend_from_slice(self.body);
        out
    }
}
