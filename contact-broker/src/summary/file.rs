//! Writing `DIR/summary.json`, which must succeed however little disk space is left.
//!
//! A run reserves the file when it starts ([`reserve`]): a placeholder summary (status `failed`, message
//! [`PLACEHOLDER`]) padded with spaces to [`RESERVED_BYTES`]. The end of the run overwrites it in place ([`write`])
//! and cuts it to size, so the final summary takes no disk space that was not already the file's: a disk that
//! filled up during the run (the frames, the probes) still gets its summary, saying which file could not be
//! written. No temporary file is involved (a rename would need room for a second copy); JSON allows the trailing
//! spaces, so the file is a valid summary at every moment a write completes.

use std::io::{Seek, Write};
use std::path::Path;

use super::Summary;
use crate::output::{OutputError, Result};

/// The summary's file name in the output folder.
pub const FILE: &str = "summary.json";

/// Bytes reserved for `summary.json` when a run starts; a summary runs to 1–2 kB, and one that would not fit (a
/// message of many kB) has its message cut to fit.
pub const RESERVED_BYTES: u64 = 16 * 1024;

/// The message of the placeholder summary [`reserve`] writes: read after the run, it means that the process that
/// ran it died before it could write its own.
pub const PLACEHOLDER: &str =
    "the run ended without writing its summary (this is the placeholder written when it started)";

/// Reserve `out/summary.json` for run `run_id` (launched in `mode`) at its start: a placeholder summary padded to
/// [`RESERVED_BYTES`]. An error names the file; a disk too full for it is better refused before the run starts.
pub fn reserve(out: &Path, run_id: &str, mode: &str) -> Result<()> {
    let path = out.join(FILE);
    let placeholder = Summary::failed(run_id, mode, PLACEHOLDER.into());
    put(&path, &placeholder, RESERVED_BYTES).inspect_err(|_| {
        // A torn placeholder is not JSON: better no file than that.
        let _ = std::fs::remove_file(&path);
    })
}

/// Write `out/summary.json` in place over what [`reserve`] wrote, then cut it to size. Without a reservation the
/// file is simply written. An error names the file.
pub fn write(out: &Path, summary: &Summary) -> Result<()> {
    put(&out.join(FILE), summary, 0)
}

/// Write `summary` at the start of `path` (created if missing), over the whole of the old content (spaces after the
/// JSON), then set the file's length to the JSON's, or to `keep` bytes if that is more (padding with spaces). The
/// JSON is kept within the file's old length, or [`RESERVED_BYTES`] if that is more, by cutting its message.
fn put(path: &Path, summary: &Summary, keep: u64) -> Result<()> {
    let io = |e| OutputError::io(path, e);
    let mut file = std::fs::OpenOptions::new()
        .write(true)
        .create(true)
        .truncate(false)
        .open(path)
        .map_err(io)?;
    let old = file.metadata().map_err(io)?.len();
    let text = fitted(path, summary, old.max(RESERVED_BYTES) as usize)?;
    let len = (text.len() as u64).max(keep);
    let mut bytes = text.into_bytes();
    bytes.resize(len.max(old) as usize, b' ');
    file.rewind().map_err(io)?;
    file.write_all(&bytes).map_err(io)?;
    file.set_len(len).map_err(io)
}

/// `summary` as pretty JSON with a final line break, its message cut (marked `…`) so that it fits in `room` bytes.
fn fitted(path: &Path, summary: &Summary, room: usize) -> Result<String> {
    let json = |s: &Summary| {
        serde_json::to_string_pretty(s)
            .map(|t| t + "\n")
            .map_err(|e| OutputError::input(path, e.to_string()))
    };
    let text = json(summary)?;
    if text.len() <= room {
        return Ok(text);
    }
    let mut cut = summary.clone();
    cut.message.clear();
    // What the message may take in the JSON, `…` (3 bytes) included.
    let mut left = room.saturating_sub(json(&cut)?.len() + 3);
    for c in summary.message.chars() {
        // JSON escapes: a quote, a backslash and the short control escapes take 2 bytes, other controls 6.
        let escaped = match c {
            '"' | '\\' | '\n' | '\r' | '\t' | '\u{8}' | '\u{c}' => 2,
            c if u32::from(c) < 0x20 => 6,
            c => c.len_utf8(),
        };
        if escaped > left {
            break;
        }
        left -= escaped;
        cut.message.push(c);
    }
    cut.message.push('…');
    json(&cut)
}

#[cfg(test)]
mod tests {
    use super::*;
    use cosim_proto::run_status::RunStatus;

    fn summary(message: &str) -> Summary {
        Summary::failed("r1", "processes", message.into())
    }

    fn read(out: &Path) -> Summary {
        serde_json::from_str(&std::fs::read_to_string(out.join(FILE)).unwrap()).unwrap()
    }

    #[test]
    fn the_summary_is_written_over_the_reservation_and_cut_to_size() {
        let out = crate::output::test_dir("summary");
        reserve(&out, "r1", "processes").unwrap();
        assert_eq!(std::fs::metadata(out.join(FILE)).unwrap().len(), RESERVED_BYTES);
        // The placeholder is a summary that says what it is.
        let placeholder = read(&out);
        assert!(placeholder.is_placeholder(), "{placeholder:?}");
        assert_eq!(placeholder.run_id, "r1");

        let mut done = summary("reached t = 1 s in 10 steps");
        done.status = RunStatus::Ok;
        write(&out, &done).unwrap();
        let text = std::fs::read_to_string(out.join(FILE)).unwrap();
        assert_eq!(text, serde_json::to_string_pretty(&done).unwrap() + "\n");
        assert!(!read(&out).is_placeholder());
        assert_eq!(std::fs::read_dir(&out).unwrap().count(), 1, "no temporary file left");
        std::fs::remove_dir_all(&out).unwrap();
    }

    #[test]
    fn a_message_too_long_for_the_reservation_is_cut_to_fit() {
        let out = crate::output::test_dir("summary-long");
        reserve(&out, "r1", "processes").unwrap();
        let long = "é\"".repeat(RESERVED_BYTES as usize);
        write(&out, &summary(&long)).unwrap();
        let len = std::fs::metadata(out.join(FILE)).unwrap().len();
        assert!(len <= RESERVED_BYTES, "{len} bytes");
        let cut = read(&out).message;
        assert!(
            cut.ends_with('…') && long.starts_with(cut.trim_end_matches('…')),
            "{cut}"
        );
        assert!(cut.len() > 1000, "cut too much: {} bytes left", cut.len());
        std::fs::remove_dir_all(&out).unwrap();
    }

    #[test]
    fn a_write_that_fails_names_the_file() {
        // /dev/full answers every write with ENOSPC.
        let Ok(meta) = std::fs::metadata("/dev/full") else {
            panic!("/dev/full is needed by this test");
        };
        assert!(!meta.is_file());
        let e = put(Path::new("/dev/full"), &summary("x"), 0).unwrap_err().to_string();
        assert!(e.starts_with("/dev/full: ") && e.contains("os error 28"), "{e}");
    }
}
