//! The run's progress, reported after each coupling step to whoever runs it (the progress bar of `cosim run`, the
//! broker's progress events and live status), and their answer: go on, or stop.

use super::contact_pass::ContactPass;
use super::step_time::Clock;
use crate::summary::Summary;

/// Progress of a run, reported after each coupling step.
#[derive(Clone, Copy, Debug, Default)]
pub struct Progress {
    /// Coupling steps taken.
    pub step: u64,
    /// Simulated time [s].
    pub t: f64,
    /// End time [s].
    pub end_time: f64,
    /// Contacts the last contact pass resolved.
    pub contacts: u64,
    /// Deepest penetration of the contact thickness so far [m].
    pub max_penetration: f64,
    /// Fluid particles exchanged in the last step (the region of interest).
    pub exchanged: u64,
    /// The most energy the fluid and the structure together gained so far, as a fraction of the energy the water
    /// can release (`summary.json` `energy_growth`, taken at the output times); `None` without a fluid under gravity.
    pub energy_made: Option<f64>,
}

/// What the run's progress callback answers after each step: go on, or stop the run now for the reason given (the
/// run then ends `failed` with that reason, its outputs so far written, like any other failure).
pub type Control = std::ops::ControlFlow<String>;

/// Report the step just taken; an error when the callback stops the run.
pub(super) fn report(
    progress: &mut dyn FnMut(Progress) -> Control,
    clock: &Clock,
    contact: &ContactPass,
    summary: &Summary,
) -> anyhow::Result<()> {
    let (step, t) = (clock.step, clock.t);
    let control = progress(Progress {
        step,
        t,
        end_time: clock.end(),
        contacts: contact.last.contacts as u64,
        max_penetration: summary.contact_stats.max_penetration,
        exchanged: contact.last.exchanged as u64,
        energy_made: summary.energy_growth.as_ref().map(|g| g.largest),
    });
    if let Control::Break(why) = control {
        anyhow::bail!(
            "stopped after coupling step {step} (t = {} s): {why}",
            cosim_proto::Num(cosim_proto::readable::significant(t, 12))
        );
    }
    Ok(())
}
