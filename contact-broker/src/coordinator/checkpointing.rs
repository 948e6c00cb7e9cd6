//! Checkpoints between two steps (`DIR/checkpoints/<step>/`, `crate::checkpoint`): when one is due, what the
//! coordinator saves in it ([`BrokerState`]), and how a run continues from one.

use std::time::Instant;

use anyhow::Context;

use cosim_proto::scene::LoadedScene;

use super::contact_pass::ContactPass;
use super::inputs::{Nodes, RunInfo};
use super::sampling::Outputs;
use super::step_time::{Clock, Step, LANDING};
use crate::checkpoint::{self, BrokerState};
use crate::interface::Corrections;
use crate::summary::Summary;

/// When the next checkpoint is due: at the first step at or after every multiple of `interval` of simulated time,
/// and at the last step (so that a finished run can be continued further). No checkpoints without an interval.
pub(super) struct Schedule {
    interval: Option<f64>,
    /// Index k of the next checkpoint time k · `interval`.
    next: u64,
}

impl Schedule {
    /// Checkpoints every `interval` seconds of simulated time, from the start.
    pub fn new(interval: Option<f64>) -> Self {
        Self { interval, next: 1 }
    }

    /// Whether a checkpoint is due after `step`, which ended at `clock.t`; if so, the next one is set.
    fn due(&mut self, clock: &Clock, step: &Step) -> bool {
        let Some(interval) = self.interval else {
            return false;
        };
        if clock.t >= self.next as f64 * interval - LANDING * step.cap || clock.t >= clock.end() {
            self.next = checkpoint_after(clock.t, interval, LANDING * step.cap);
            true
        } else {
            false
        }
    }
}

/// Index k of the first checkpoint time k · `interval` after `t` (times within `slack` before `t` count as reached).
fn checkpoint_after(t: f64, interval: f64, slack: f64) -> u64 {
    ((t + slack) / interval + 1e-9).floor() as u64 + 1
}

/// The state of the run after `step`, as the nodes left it.
pub(super) struct RunState<'a, 's> {
    pub clock: &'a Clock,
    pub contact: &'a ContactPass,
    pub outputs: &'a Outputs<'s>,
    pub summary: &'a Summary,
}

/// Write a checkpoint after `step` if one is due. Between two steps: every node answered the step, its
/// corrections are still to be sent.
pub(super) fn save_if_due(
    schedule: &mut Schedule,
    step: &Step,
    run: RunState<'_, '_>,
    scene: &LoadedScene,
    nodes: &mut Nodes<'_>,
    info: &RunInfo,
) -> anyhow::Result<()> {
    if !schedule.due(run.clock, step) {
        return Ok(());
    }
    let (clock, contact) = (run.clock, run.contact);
    let state = BrokerState {
        step: clock.step,
        t: clock.t,
        next_output: clock.next_output,
        next_checkpoint: schedule.next,
        dt_fluid: clock.dt_fluid,
        dt_contact: clock.dt_contact,
        dt_structure: clock.dt_structure,
        pending_fem: contact.pending.fem.clone(),
        pending_sph: contact.pending.sph.clone(),
        roi: contact.roi,
        load: contact.load.clone(),
        load_log: contact.since.clone(),
        owed: contact.owed().to_vec(),
        exchanged: contact.exchanged,
        fluid_origin: run.outputs.probes.fluid_origin().map(<[_]>::to_vec),
        rows: run.outputs.csv.rows().to_vec(),
        summary: run.summary.clone(),
    };
    save(scene, nodes, info, &state)
}

/// Gather every node's state and write the checkpoint folder. A node that cannot save its state fails the run:
/// asked for checkpoints, the user must not find out at the restart that there are none.
fn save(scene: &LoadedScene, nodes: &mut Nodes<'_>, info: &RunInfo, state: &BrokerState) -> anyhow::Result<()> {
    let started = Instant::now();
    let context = || {
        format!(
            "checkpoint at step {} (t = {} s)",
            state.step,
            cosim_proto::Num(state.t)
        )
    };
    let mut saved = Vec::new();
    if let Some(link) = nodes.fem.as_deref_mut() {
        saved.push(("fem", link.checkpoint(state.step).with_context(context)?));
    }
    if let Some(link) = nodes.sph.as_deref_mut() {
        saved.push(("sph", link.checkpoint(state.step).with_context(context)?));
    }
    let written = checkpoint::write(&info.out, &info.run_id, scene, state, &saved, started).with_context(context)?;
    tracing::info!(
        "checkpoint {}: {} bytes in {:.3} s",
        written.dir.display(),
        written.bytes,
        written.seconds
    );
    Ok(())
}

/// Continue where the checkpoint `saved` left off: the nodes restored their own states when they started; the
/// clock, the contact, the probe rows and the summary's counts are put back here. The checkpoint times follow
/// `schedule`'s interval, which may differ from the run that saved it.
pub(super) fn resume(
    saved: &BrokerState,
    schedule: &mut Schedule,
    clock: &mut Clock,
    contact: &mut ContactPass,
    outputs: &mut Outputs<'_>,
    summary: &mut Summary,
) -> anyhow::Result<()> {
    saved.check_nodes(summary.fem_nodes, summary.particles)?;
    (clock.t, clock.step, clock.next_output) = (saved.t, saved.step, saved.next_output);
    (clock.dt_fluid, clock.dt_contact, clock.dt_structure) = (saved.dt_fluid, saved.dt_contact, saved.dt_structure);
    // From the time, not the saved index: the restart may ask for another interval.
    schedule.next = schedule
        .interval
        .map_or(saved.next_checkpoint, |i| checkpoint_after(clock.t, i, 0.0));
    contact.pending = Corrections {
        fem: saved.pending_fem.clone(),
        sph: saved.pending_sph.clone(),
    };
    (contact.roi, contact.load, contact.exchanged) = (saved.roi, saved.load.clone(), saved.exchanged);
    contact.since = saved.load_log.clone();
    contact.restore_owed(&saved.owed)?;
    outputs.resume(saved)?;
    summary.continue_from(&saved.summary);
    Ok(())
}
