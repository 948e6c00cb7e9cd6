//! Wire messages, the versioned envelope and its codec, key expressions, and the scene types of the
//! FEM–SPH co-simulation. Nothing here does I/O beyond reading a scene file.
#![warn(missing_docs)]

pub mod control;
pub mod envelope;
pub mod keys;
pub mod messages;
pub mod overlap;
pub mod readable;
pub mod run_status;
pub mod scene;
pub mod trace;
pub mod validate;
pub mod walls;

pub use readable::{one_line, Num};
pub use scene::sizing;

pub use envelope::{CodecError, Envelope, PROTOCOL_VERSION};
