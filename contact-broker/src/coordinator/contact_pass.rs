//! The contact pass between two steps (`DESIGN.md` §3 step 4), run when a structure and a fluid take part, and
//! what it hands on to the next step: the corrections to send, the region of interest to ask the fluid for, and the
//! interface load drawn in the frames.

use std::time::Instant;

use anyhow::Context;

use cosim_proto::messages::StepCommand;
use cosim_proto::scene::Scene;

use super::exchange::{commands, Round};
use super::inputs::Nodes;
use super::step_time::Step;
use crate::interface::{Corrections, Interface, PassStats};
use crate::probes::LoadLog;
use crate::summary::{ContactStats, Summary};
use crate::wall_contact::WallContact;

/// The contact between the structure and the fluid, and what one pass leaves for the next step.
pub(super) struct ContactPass {
    interface: Option<Interface>,
    /// Corrections of the last pass, still to be sent.
    pub pending: Corrections,
    /// Region of interest of the next fluid command.
    pub roi: Option<[f64; 4]>,
    /// Interface load of the last output step.
    pub load: Option<Vec<[f64; 2]>>,
    /// The contact impulse per solid since the last sample (`interface_load` probes).
    pub since: LoadLog,
    /// The solid of each FE node.
    node_solid: Vec<u32>,
    /// Fluid particles exchanged over the run.
    pub exchanged: u64,
    /// What the last pass did.
    pub last: PassStats,
    /// The walls against the structure's interface nodes (`wall_contact.rs`); `None` without walls or nodes to stop.
    walls: Option<WallContact>,
    /// The walls have stopped a node in this process's run (logged once).
    walls_stopped: bool,
}

impl ContactPass {
    /// The contact of `scene` between the registered nodes; none unless both a structure and a fluid take part.
    pub fn new(scene: &Scene, nodes: &Nodes<'_>) -> anyhow::Result<Self> {
        let interface = match (&nodes.fem, &nodes.sph) {
            (Some(f), Some(p)) => Some(Interface::new(scene, f.setup(), p.setup())?),
            _ => None,
        };
        let mesh = interface
            .as_ref()
            .map(|i| (i, nodes.fem.as_ref().expect("interface has a structure").setup()));
        let walls = mesh.and_then(|(i, mesh)| WallContact::new(scene, mesh, i.node_ids()));
        let roi = mesh.map(|(i, mesh)| {
            let x: Vec<[f64; 2]> = i.node_ids().iter().map(|&id| mesh.nodes[id as usize]).collect();
            i.roi(&x)
        });
        Ok(Self {
            interface,
            pending: Corrections::default(),
            roi,
            load: None,
            since: LoadLog::default(),
            node_solid: nodes
                .fem
                .as_ref()
                .map_or_else(Vec::new, |f| f.setup().node_solid.clone()),
            exchanged: 0,
            last: PassStats::default(),
            walls,
            walls_stopped: false,
        })
    }

    /// The contacts the last pass recorded ([`Interface::contacts`]); `None` without an interface or a record.
    pub fn contacts(&self) -> Option<&[cosim_proto::control::ContactRecord]> {
        self.interface.as_ref().and_then(|i| i.contacts())
    }

    /// How the structure's contact impulse is relaxed ([`Interface::relaxation`]); `None` without an interface or
    /// where it is given at once.
    pub fn relaxation(&self) -> Option<&crate::relaxation::RelaxationChoice> {
        self.interface.as_ref().and_then(|i| i.relaxation())
    }

    /// The contact impulse owed to the structure's interface nodes ([`Interface::owed`]); empty without one.
    pub fn owed(&self) -> &[[f64; 2]] {
        self.interface.as_ref().map_or(&[], |i| i.owed())
    }

    /// Put back the owed impulse a checkpoint saved; refused unless empty or one per interface node.
    pub fn restore_owed(&mut self, owed: &[[f64; 2]]) -> anyhow::Result<()> {
        match self.interface.as_mut() {
            Some(i) => i.restore_owed(owed).context("checkpoint broker.bin owed"),
            None if owed.is_empty() => Ok(()),
            None => anyhow::bail!(
                "checkpoint broker.bin owed: {} impulses, but the run has no interface",
                owed.len()
            ),
        }
    }

    /// The commands of the next step, (fem, sph), carrying the pending corrections and the region of interest.
    pub fn commands(&mut self, dt: f64, want_snapshot: bool) -> (StepCommand, StepCommand) {
        let coupled = self.interface.is_some();
        commands(dt, want_snapshot, coupled, self.roi, &mut self.pending)
    }

    /// Contact on the states just reported after `step` (ending at `t`); the corrections go out with the next
    /// command. Nothing to do unless both nodes answered.
    pub fn pass(
        &mut self,
        round: &Round,
        step: &Step,
        number: u64,
        t: f64,
        summary: &mut Summary,
    ) -> anyhow::Result<()> {
        let (Some(interface), Some(fem), Some(sph)) = (self.interface.as_mut(), &round.fem, &round.sph) else {
            return Ok(());
        };
        let started = Instant::now();
        let (mut corrections, stats) = interface.pass(fem, sph, step.dt).with_context(|| {
            format!(
                "contact pass of coupling step {number} at t = {} s",
                cosim_proto::Num(t)
            )
        })?;
        if let Some(walls) = self.walls.as_mut() {
            let stopped = walls.correct(fem, &mut corrections.fem);
            if stopped > 0 && !self.walls_stopped {
                self.walls_stopped = true;
                tracing::info!(
                    "t = {} s: the walls stop the structure ({stopped} node(s) put back on a wall's surface; \
                     wall_contact.rs)",
                    cosim_proto::Num(t)
                );
            }
        }
        self.pending = corrections;
        self.last = stats.clone();
        self.roi = Some(interface.roi(&fem.x));
        self.exchanged += stats.exchanged as u64;
        record(&mut summary.contact_stats, &stats, self.exchanged, number);
        self.since.add(interface.impulses(), &self.node_solid, step.dt);
        if step.lands {
            self.load = Some(interface.load());
        }
        summary.timings.broker += started.elapsed().as_secs_f64();
        Ok(())
    }
}

/// Fold one pass into the run's contact statistics.
fn record(total: &mut ContactStats, pass: &PassStats, exchanged: u64, steps: u64) {
    total.contacts += pass.contacts as u64;
    total.max_penetration = total.max_penetration.max(pass.max_penetration);
    total.linear_momentum_change = total.linear_momentum_change.max(pass.linear_momentum_change);
    total.angular_momentum_change = total.angular_momentum_change.max(pass.angular_momentum_change);
    total.exchanged_per_step = exchanged as f64 / steps.max(1) as f64;
    total.exchanged_max = total.exchanged_max.max(pass.exchanged as u64);
}
