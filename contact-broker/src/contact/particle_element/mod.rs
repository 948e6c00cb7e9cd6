//! Particle–element contact (Long et al. 2016 after Johnson & Stryk 2001; `DESIGN.md` §4.5): positions and normal
//! velocities of slave particles and master nodes are corrected so that no particle stays within the contact
//! thickness of the structure and no contact approaches, conserving linear and angular momentum (the formulas and
//! the conservation argument are in the [`contact`](super) module docs).
//!
//! One pass ([`particle_element_with`]) is a sequence of named steps, one file each:
//! 1. `setup.rs`: inverse masses, the segment grid, tolerances, the detection context (`detection.rs`: which master
//!    a particle touches, and the contact geometry ξ, N1, N2, n, g);
//! 2. `position.rs`: the position phase, Gauss–Seidel sweeps of λ = −g/w;
//! 3. `projection.rs`: within both phases, the exact projection on immovable masters (`rigid.rs`: one exact step);
//! 4. `touching.rs`: the touching set, contacts frozen at the corrected positions;
//! 5. `velocity.rs`: the velocity phase, Gauss–Seidel sweeps of J = −v_rel/w on approaching contacts.
//!
//! [`ParticleElement`] is the [`ContactAlgorithm`] that runs it with its own [`ParticleElementWorkspace`].

mod detection;
mod memo;
mod pairs;
mod params;
mod position;
mod projection;
mod report;
mod rigid;
mod segment_grid;
mod setup;
mod touching;
mod velocity;
mod workspace;

#[cfg(test)]
mod tests;

pub use pairs::{ContactPair, PairMaster};
pub use params::ContactParams;
pub use report::ContactReport;
pub use workspace::ParticleElementWorkspace;

use crate::contact::algorithm::{ContactAlgorithm, PassReport, Stiffness};
use crate::contact::bodies::{validate, Nodes, Particles, Segment};
use crate::contact::error::ContactError;
use pairs::Out;
use setup::{Mark, Setup};

/// Corrects particles and nodes in place (see the [module docs](super) for the algorithm) with a fresh workspace.
pub fn particle_element(
    particles: Particles<'_>,
    nodes: Nodes<'_>,
    segments: &[Segment],
    params: &ContactParams,
) -> Result<ContactReport, ContactError> {
    particle_element_with(
        &mut ParticleElementWorkspace::default(),
        particles,
        nodes,
        segments,
        params,
    )
}

/// [`particle_element`] reusing the scratch arrays of `ws`.
pub fn particle_element_with(
    ws: &mut ParticleElementWorkspace,
    mut particles: Particles<'_>,
    mut nodes: Nodes<'_>,
    segments: &[Segment],
    params: &ContactParams,
) -> Result<ContactReport, ContactError> {
    params.validate()?;
    validate(&particles, &nodes, segments)?;
    let nn = nodes.x.len();
    let mut report = ContactReport {
        node_impulse: vec![[0.0; 2]; nn],
        node_position_impulse: vec![[0.0; 2]; nn],
        ..ContactReport::default()
    };
    if particles.x.is_empty() || segments.is_empty() {
        ws.pairs.clear();
        return Ok(report);
    }
    let ParticleElementWorkspace {
        grid,
        topo,
        inv_m,
        statics,
        marks,
        masters,
        rigid,
        gaps,
        memo,
        contacts,
        planes,
        exhaustive,
        pairs,
    } = ws;
    pairs.clear();
    marks.clear();
    marks.resize(particles.x.len(), Mark::default());
    memo.clear();

    let mut setup = Setup::new(grid, topo, inv_m, statics, &nodes, segments, params, *exhaustive);
    position::phase(
        &mut setup,
        &mut particles,
        &mut nodes,
        masters,
        rigid,
        gaps,
        memo,
        marks,
        Out {
            report: &mut report,
            pairs,
        },
    );
    touching::collect(
        &setup,
        particles.x,
        nodes.x,
        marks,
        memo,
        masters,
        contacts,
        &mut report,
    );
    velocity::phase(
        &setup,
        &mut particles,
        &mut nodes,
        contacts,
        planes,
        marks,
        Out {
            report: &mut report,
            pairs,
        },
    );
    pairs.finish();

    report.particles_corrected = marks.iter().filter(|m| m.corrected).count();
    Ok(report)
}

/// The particle–element algorithm with its parameters and its scratch memory.
#[derive(Clone, Debug, Default)]
pub struct ParticleElement {
    /// The parameters of every pass.
    pub params: ContactParams,
    workspace: ParticleElementWorkspace,
}

impl ParticleElement {
    /// The algorithm with `params` and an empty workspace.
    pub fn new(params: ContactParams) -> Self {
        ParticleElement {
            params,
            workspace: ParticleElementWorkspace::default(),
        }
    }

    /// The pairs the last pass acted on ([`ParticleElementWorkspace::pairs`]).
    pub fn pairs(&self) -> &[ContactPair] {
        self.workspace.pairs()
    }
}

impl ContactAlgorithm for ParticleElement {
    /// [`particle_element_with`]; `dt` is not needed (positions and velocities are corrected directly).
    fn correct(
        &mut self,
        particles: Particles<'_>,
        nodes: Nodes<'_>,
        segments: &[Segment],
        _dt: f64,
    ) -> Result<PassReport, ContactError> {
        let report = particle_element_with(&mut self.workspace, particles, nodes, segments, &self.params)?;
        Ok(PassReport {
            contacts: report.contacts,
            max_penetration: report.max_penetration,
            node_impulse: report.node_impulse,
            stiffness: Stiffness::default(),
        })
    }

    fn pairs(&self) -> Option<&[ContactPair]> {
        Some(self.workspace.pairs())
    }
}
