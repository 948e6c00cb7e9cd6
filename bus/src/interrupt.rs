//! Interrupts (Ctrl-C's SIGINT, SIGTERM) turned into a flag that a run reads between two steps, so that it stops
//! there with its outputs written (summary, probes, plots, frames so far) instead of dying in the middle of a step.
//! A second signal ends the process at once (exit code 130), for a run that does not come to its next step; one
//! within [`SAME_REQUEST`] of the first is the same request, not a second (`timeout` and some supervisors send
//! SIGTERM to a process and again to its process group: the two arrive together, and the run ended at once with no
//! summary, found 2026-12-06).

use std::ops::ControlFlow;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};
use std::time::{Duration, Instant};

use signal_hook::consts::{SIGINT, SIGTERM};

/// How long a coupling step still in progress when a signal arrives is given to end on its own (the run then stops
/// between two steps, as for any signal): after that the step is given up, the node's answer no longer awaited
/// (processes) or its sub-cycle left (in this process), and the run ends `failed` with its outputs so far. Well
/// within the 10 s `cosim run` gives the broker to stop before it kills it.
pub const STOP_WAIT: Duration = Duration::from_secs(2);

/// Signals this close after the first are the same request to stop, not a second one.
pub const SAME_REQUEST: Duration = Duration::from_millis(100);

/// Set once SIGINT or SIGTERM arrived (after [`Interrupt::install`]).
#[derive(Clone, Debug)]
pub struct Interrupt {
    flag: Arc<AtomicBool>,
    /// When [`Interrupt::overdue`] first saw the signal.
    seen: Arc<OnceLock<Instant>>,
    /// How long after that it answers true ([`STOP_WAIT`]).
    wait: Duration,
}

impl Interrupt {
    /// Catch SIGINT and SIGTERM for the rest of the process's life: a thread of its own takes them as they come.
    pub fn install() -> std::io::Result<Self> {
        let flag = Arc::new(AtomicBool::new(false));
        let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM])?;
        let raised = Arc::clone(&flag);
        std::thread::Builder::new().name("signals".into()).spawn(move || {
            let mut first: Option<Instant> = None;
            for _ in signals.forever() {
                match first {
                    None => {
                        first = Some(Instant::now());
                        raised.store(true, Ordering::SeqCst);
                    }
                    Some(at) if at.elapsed() >= SAME_REQUEST => signal_hook::low_level::exit(130),
                    Some(_) => {}
                }
            }
        })?;
        Ok(Self::from_flag(flag))
    }

    /// An interrupt that `flag` raises (a test's, or one set by other means than a signal).
    pub fn from_flag(flag: Arc<AtomicBool>) -> Self {
        Self {
            flag,
            seen: Arc::default(),
            wait: STOP_WAIT,
        }
    }

    /// This interrupt with [`Interrupt::overdue`] answering `wait` after the signal instead of [`STOP_WAIT`].
    pub fn with_wait(self, wait: Duration) -> Self {
        Self { wait, ..self }
    }

    /// Whether a signal arrived.
    pub fn arrived(&self) -> bool {
        self.flag.load(Ordering::Relaxed)
    }

    /// How long ago this interrupt (or a clone) first saw the signal, counting from this call if none had; `None`
    /// before it arrived. A caller that waits asks often (between two sub-steps, or two polls of a channel).
    pub fn seen_for(&self) -> Option<Duration> {
        self.arrived().then(|| self.seen.get_or_init(Instant::now).elapsed())
    }

    /// Whether a computation in progress should be given up: the signal was seen [`STOP_WAIT`] ago or more.
    pub fn overdue(&self) -> bool {
        self.seen_for().is_some_and(|d| d >= self.wait)
    }

    /// What a run's progress callback answers (`contact_broker::coordinator::Control`): stop with [`REASON`]
    /// once a signal arrived, else go on.
    pub fn control(&self) -> ControlFlow<String> {
        match self.arrived() {
            true => ControlFlow::Break(REASON.to_string()),
            false => ControlFlow::Continue(()),
        }
    }
}

/// The reason a run stopped by a signal gives (summary.json's `message` ends with it).
pub const REASON: &str = "interrupted (SIGINT or SIGTERM)";

#[cfg(test)]
mod tests {
    use super::*;

    /// Overdue only once the signal arrived and its wait passed since it was first seen; clones share that moment.
    #[test]
    fn overdue_after_the_wait_from_when_the_signal_was_first_seen() {
        let flag = Arc::new(AtomicBool::new(false));
        let interrupt = Interrupt::from_flag(Arc::clone(&flag)).with_wait(Duration::from_millis(200));
        let clone = interrupt.clone();
        assert!(!interrupt.overdue() && !interrupt.arrived());
        flag.store(true, Ordering::Relaxed);
        let seen = Instant::now();
        assert!(interrupt.arrived() && !interrupt.overdue(), "not before its wait");
        while seen.elapsed() < Duration::from_millis(200) {
            std::thread::sleep(Duration::from_millis(20));
        }
        assert!(clone.overdue(), "the clone counts from the first sight");
        assert!(Interrupt::from_flag(flag).with_wait(Duration::ZERO).overdue());
        assert_eq!(Interrupt::from_flag(Arc::default()).wait, STOP_WAIT);
    }
}
