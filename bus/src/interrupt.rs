//! Interrupts (Ctrl-C's SIGINT, SIGTERM) turned into a flag that a run reads between two steps, so that it stops
//! there with its outputs written (summary, probes, plots, frames so far) instead of dying in the middle of a step.
//! A second signal ends the process at once (exit code 130), for a run that does not come to its next step.

use std::ops::ControlFlow;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use signal_hook::consts::{SIGINT, SIGTERM};

/// Set once SIGINT or SIGTERM arrived (after [`Interrupt::install`]).
#[derive(Clone, Debug)]
pub struct Interrupt(Arc<AtomicBool>);

impl Interrupt {
    /// Catch SIGINT and SIGTERM for the rest of the process's life.
    pub fn install() -> std::io::Result<Self> {
        let flag = Arc::new(AtomicBool::new(false));
        for signal in [SIGINT, SIGTERM] {
            // The order matters: the shutdown hook sees the flag as it was before this signal set it.
            signal_hook::flag::register_conditional_shutdown(signal, 130, Arc::clone(&flag))?;
            signal_hook::flag::register(signal, Arc::clone(&flag))?;
        }
        Ok(Self(flag))
    }

    /// Whether a signal arrived.
    pub fn arrived(&self) -> bool {
        self.0.load(Ordering::Relaxed)
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
