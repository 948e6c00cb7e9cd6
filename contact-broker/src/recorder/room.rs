//! The room a recording leaves for the run's own outputs. The trace (`--record`) is not in the disk estimate that
//! `cosim run` checks before it starts: how many particles each step's messages carry is set by the flow. So the
//! recorder watches its disk as it writes: every [`CHECK_EVERY`] bytes of trace it compares the free space with
//! what the run's frames, probe table and checkpoints still need (`cosim_proto::scene::disk`, scaled to the time
//! left), says once when the trace's pace will not fit to the end, and stops recording before it would take the
//! outputs' room. A run whose recording stopped ends as it would have without it, with its outputs whole, and the
//! trace readable up to its last record.

use std::path::{Path, PathBuf};

use cosim_proto::scene::sizing::bytes_text;
use cosim_proto::Num;

/// Bytes of trace between two looks at the free space (a `statvfs`, a few µs).
pub const CHECK_EVERY: u64 = 4 << 20;

/// The free bytes of the disk that holds a folder (`cosim_bus::disk::free`; a test's own disk otherwise).
pub type FreeSpace = Box<dyn Fn(&Path) -> Option<u64> + Send>;

/// What the recorder does after a write.
#[derive(Debug, PartialEq)]
pub enum Verdict {
    /// Go on.
    Go,
    /// Go on, and say this once: at its pace the trace will not fit to the end.
    Warn(String),
    /// Stop recording, and say why: the rest of the disk is the outputs'.
    Stop(String),
}

/// The outputs' room on the trace's disk, and the trace's pace.
pub struct Room {
    dir: PathBuf,
    /// Bytes the outputs need from `from` to `end` (the run's estimate when it started).
    outputs: f64,
    from: f64,
    end: f64,
    free: FreeSpace,
    /// The simulated time of the last command recorded.
    t: f64,
    /// Trace bytes written when the first command was recorded (the scene, restores and registrations before it).
    start_bytes: Option<u64>,
    next_check: u64,
    largest_record: u64,
    warned: bool,
}

impl Room {
    /// Keep `outputs` bytes (what the run writes from simulated time `from` to `end`) free on the disk of `dir`.
    pub fn new(dir: &Path, outputs: f64, from: f64, end: f64) -> Self {
        Self {
            dir: dir.to_path_buf(),
            outputs,
            from,
            end,
            free: Box::new(cosim_bus::disk::free),
            t: from,
            start_bytes: None,
            next_check: 0,
            largest_record: 0,
            warned: false,
        }
    }

    /// The same, with the free space read by `free`.
    #[cfg(test)]
    pub fn with_free(mut self, free: FreeSpace) -> Self {
        self.free = free;
        self
    }

    /// A command of the step from `t` was recorded, after `bytes` bytes of trace.
    pub fn at(&mut self, t: f64, bytes: u64) {
        self.t = self.t.max(t);
        self.start_bytes.get_or_insert(bytes);
    }

    /// The outputs still to write, from the last command's time on.
    fn outputs_left(&self) -> f64 {
        let span = self.end - self.from;
        let left = match span > 0.0 {
            true => ((self.end - self.t) / span).clamp(0.0, 1.0),
            false => 0.0,
        };
        self.outputs * left
    }

    /// A record of `record` bytes was written, `bytes` in all so far.
    pub fn after_write(&mut self, record: u64, bytes: u64) -> Verdict {
        self.largest_record = self.largest_record.max(record);
        if bytes < self.next_check {
            return Verdict::Go;
        }
        self.next_check = bytes + CHECK_EVERY;
        let Some(free) = (self.free)(&self.dir) else {
            return Verdict::Go;
        };
        let (free, outputs) = (free as f64, self.outputs_left());
        // What the trace may still write before the next look: the bytes between two looks and one more record.
        let margin = (CHECK_EVERY + self.largest_record) as f64;
        if free < outputs + margin {
            return Verdict::Stop(format!(
                "the disk of {} has {} free, and the run's frames, probe table and checkpoints from t = {} s on need \
                 about {}: the recording stops here, at {} of trace, so that they fit (what was written stays \
                 readable; the run goes on)",
                self.dir.display(),
                bytes_text(free),
                Num(sig4(self.t)),
                bytes_text(outputs),
                bytes_text(bytes as f64),
            ));
        }
        let Some(start) = self.start_bytes else {
            return Verdict::Go;
        };
        let elapsed = self.t - self.from;
        if self.warned || elapsed <= 0.0 || self.t >= self.end {
            return Verdict::Go;
        }
        // The trace's pace so far, to the end.
        let pace = bytes.saturating_sub(start) as f64 / elapsed;
        let more = pace * (self.end - self.t);
        if more + outputs + margin <= free {
            return Verdict::Go;
        }
        self.warned = true;
        let stop_at = self.t + (free - outputs - margin).max(0.0) / pace;
        Verdict::Warn(format!(
            "the trace grows by about {} a second of simulated time: to t = {} s it needs about {} more, and the disk \
             of {} has {} free beside the {} the run's other outputs still need; the recording will stop at about \
             t = {} s (the run goes on)",
            bytes_text(pace),
            Num(sig4(self.end)),
            bytes_text(more),
            self.dir.display(),
            bytes_text(free - outputs),
            bytes_text(outputs),
            Num(sig4(stop_at.min(self.end))),
        ))
    }
}

/// `x` to four significant digits, for a time in a message.
fn sig4(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let scale = 10f64.powi(3 - x.abs().log10().floor() as i32);
    (x * scale).round() / scale
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A disk of `capacity` bytes that holds nothing but what `used` says.
    fn disk(capacity: u64, used: std::sync::Arc<std::sync::atomic::AtomicU64>) -> FreeSpace {
        Box::new(move |_| Some(capacity.saturating_sub(used.load(std::sync::atomic::Ordering::Relaxed))))
    }

    /// A trace of 100 KiB records a step on a disk of 64 MiB, with 40 MiB of outputs to come over 1 s of simulated
    /// time, 1,000 steps: at its pace (100 MiB a second) it cannot fit. It is said once, when the pace is known, and
    /// the recording stops while the outputs still fit: what is free then is at least the outputs' remaining share.
    #[test]
    fn the_recording_stops_before_it_takes_the_outputs_room() {
        use std::sync::atomic::{AtomicU64, Ordering};
        let used = std::sync::Arc::new(AtomicU64::new(0));
        let (capacity, outputs) = (64u64 << 20, 40.0 * 1048576.0);
        let mut room = Room::new(Path::new("/x"), outputs, 0.0, 1.0).with_free(disk(capacity, used.clone()));
        let record = 100u64 << 10;
        let (mut warned, mut stopped) = (Vec::new(), None);
        for step in 0..1000u64 {
            let t = step as f64 * 1e-3;
            room.at(t, used.load(Ordering::Relaxed));
            let bytes = used.fetch_add(record, Ordering::Relaxed) + record;
            match room.after_write(record, bytes) {
                Verdict::Go => {}
                Verdict::Warn(w) => warned.push((t, w)),
                Verdict::Stop(s) => {
                    stopped = Some((t, bytes, s));
                    break;
                }
            }
        }
        assert_eq!(warned.len(), 1, "{warned:?}");
        let (t_warn, warning) = &warned[0];
        assert!(*t_warn < 0.05, "said late, at {t_warn}");
        assert!(warning.contains("the recording will stop at about"), "{warning}");
        let (t, bytes, why) = stopped.expect("the recording stops");
        // What is left is the outputs' share from t on, to the margin of one look (4 MiB and a record).
        let left = (capacity - bytes) as f64;
        let need = outputs * (1.0 - t);
        assert!(left >= need, "{left} free against {need} needed at t = {t}");
        assert!(
            left <= need + 2.0 * (CHECK_EVERY + record) as f64,
            "stopped early: {left} free against {need}"
        );
        // The warning's time is where it stopped, to the pace's step (the outputs shrink as t goes on).
        assert!(why.contains("the recording stops here"), "{why}");
        assert!(why.contains("/x"), "names the folder: {why}");
    }

    /// A trace that fits leaves no warning and never stops.
    #[test]
    fn a_trace_that_fits_is_not_stopped() {
        use std::sync::atomic::{AtomicU64, Ordering};
        let used = std::sync::Arc::new(AtomicU64::new(0));
        let mut room = Room::new(Path::new("/x"), 1e6, 0.0, 1.0).with_free(disk(1 << 30, used.clone()));
        for step in 0..1000u64 {
            room.at(step as f64 * 1e-3, used.load(Ordering::Relaxed));
            let bytes = used.fetch_add(50_000, Ordering::Relaxed) + 50_000;
            assert_eq!(room.after_write(50_000, bytes), Verdict::Go, "step {step}");
        }
    }

    /// A disk whose free space cannot be read stops nothing.
    #[test]
    fn an_unreadable_disk_stops_nothing() {
        let mut room = Room::new(Path::new("/x"), 1e12, 0.0, 1.0).with_free(Box::new(|_| None));
        room.at(0.5, 0);
        assert_eq!(room.after_write(1 << 30, 1 << 30), Verdict::Go);
    }
}
