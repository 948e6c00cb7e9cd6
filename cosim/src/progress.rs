//! The progress of a run on stderr: a bar in a terminal (simulated time, steps per second and the time left), and
//! where stderr is a file or a pipe (`cosim run … 2> run.log`, a batch job) one plain line every
//! [`PLAIN_INTERVAL`], so that a long run's log says how far it has come.

use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::{Duration, Instant};

use contact_broker::coordinator::Progress;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Resolution of the bar.
const TICKS: u64 = 10_000;

/// Wall time between two plain progress lines.
pub const PLAIN_INTERVAL: Duration = Duration::from_secs(30);

/// A progress bar drawn on stderr when it is a terminal, plain lines when it is not, nothing when quiet.
pub struct Bar {
    bar: ProgressBar,
    started: Instant,
    /// When the last plain line was written; `None` where the lines are not written (a terminal, or quiet).
    plain: Option<Mutex<Instant>>,
}

impl Bar {
    /// A new bar; hidden when `quiet`.
    pub fn new(quiet: bool) -> Self {
        let terminal = std::io::stderr().is_terminal();
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
        let started = Instant::now();
        Self {
            bar,
            started,
            plain: (!quiet && !terminal).then(|| Mutex::new(started)),
        }
    }

    /// Show where the run is.
    pub fn update(&self, p: Progress) {
        let elapsed = self.started.elapsed();
        let rate = p.step as f64 / elapsed.as_secs_f64().max(1e-9);
        self.bar
            .set_position(((p.t / p.end_time).clamp(0.0, 1.0) * TICKS as f64) as u64);
        self.bar.set_message(format!(
            "t = {:.4} / {} s, step {}, {:.0} steps/s",
            p.t, p.end_time, p.step, rate
        ));
        if let Some(last) = &self.plain {
            let mut last = last.lock().unwrap_or_else(|e| e.into_inner());
            if last.elapsed() >= PLAIN_INTERVAL {
                *last = Instant::now();
                eprintln!("{}", plain_line(&p, elapsed));
            }
        }
    }

    /// Remove the bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// One progress line for a log: simulated time against the end, the share done, the steps and their rate, the wall
/// time so far and the time left at the pace so far.
pub fn plain_line(p: &Progress, elapsed: Duration) -> String {
    let done = (p.t / p.end_time).clamp(0.0, 1.0);
    let wall = elapsed.as_secs_f64();
    let left = if done > 0.0 {
        hms(wall * (1.0 - done) / done)
    } else {
        "?".to_string()
    };
    format!(
        "cosim: t = {} / {} s ({:.1} %), step {}, {:.0} steps/s, {} so far, about {left} left",
        cosim_proto::Num(cosim_proto::readable::significant(p.t, 6)),
        cosim_proto::Num(p.end_time),
        100.0 * done,
        p.step,
        p.step as f64 / wall.max(1e-9),
        hms(wall),
    )
}

/// Seconds as `1h02m03s`, `2m03s` or `3s`.
pub fn hms(seconds: f64) -> String {
    let s = seconds.max(0.0).round() as u64;
    match (s / 3600, s / 60 % 60, s % 60) {
        (0, 0, s) => format!("{s}s"),
        (0, m, s) => format!("{m}m{s:02}s"),
        (h, m, s) => format!("{h}h{m:02}m{s:02}s"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(step: u64, t: f64, end_time: f64) -> Progress {
        Progress {
            step,
            t,
            end_time,
            contacts: 0,
            max_penetration: 0.0,
            exchanged: 0,
            energy_made: None,
        }
    }

    #[test]
    fn a_plain_line_says_how_far_the_run_is_and_how_long_is_left() {
        assert_eq!(
            plain_line(&at(1150, 0.1, 0.4), Duration::from_secs(95)),
            "cosim: t = 0.1 / 0.4 s (25.0 %), step 1150, 12 steps/s, 1m35s so far, about 4m45s left"
        );
        assert_eq!(
            plain_line(&at(0, 0.0, 1.25), Duration::from_secs(0)),
            "cosim: t = 0 / 1.25 s (0.0 %), step 0, 0 steps/s, 0s so far, about ? left"
        );
        assert_eq!(hms(3723.4), "1h02m03s");
    }
}
