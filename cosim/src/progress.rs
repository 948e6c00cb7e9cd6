//! The terminal progress bar: simulated time, steps per second and the time left.

use std::time::Instant;

use contact_broker::coordinator::Progress;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Resolution of the bar.
const TICKS: u64 = 10_000;

/// A progress bar drawn on stderr when it is a terminal (hidden otherwise, or when quiet).
pub struct Bar {
    bar: ProgressBar,
    started: Instant,
}

impl Bar {
    /// A new bar; hidden when `quiet`.
    pub fn new(quiet: bool) -> Self {
        let bar = ProgressBar::with_draw_target(
            Some(TICKS),
            if quiet {
                ProgressDrawTarget::hidden()
            } else {
                ProgressDrawTarget::stderr()
            },
        );
        bar.set_style(
            ProgressStyle::with_template("{spinner} [{elapsed_precise}] {wide_bar} {percent:>3}% ETA {eta} {msg}")
                .expect("valid template"),
        );
        Self {
            bar,
            started: Instant::now(),
        }
    }

    /// Show where the run is.
    pub fn update(&self, p: Progress) {
        let rate = p.step as f64 / self.started.elapsed().as_secs_f64().max(1e-9);
        self.bar
            .set_position(((p.t / p.end_time).clamp(0.0, 1.0) * TICKS as f64) as u64);
        self.bar.set_message(format!(
            "t = {:.4} / {} s, step {}, {:.0} steps/s",
            p.t, p.end_time, p.step, rate
        ));
    }

    /// Remove the bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
