//! What one particle–element pass did: counts, penetrations and the impulses the nodes received.

use super::detection::Master;

/// What one call of [`particle_element`](super::particle_element) did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ContactReport {
    /// Particle–master pairs found penetrating (g < 0) in the first sweep.
    pub contacts: usize,
    /// Of these, node contacts (convex corners, ends of open chains).
    pub node_contacts: usize,
    /// Pairs touching after the position phase (gap within the touch tolerance, see
    /// [`ContactParams::tolerance`](super::ContactParams::tolerance)): the velocity phase's contacts.
    pub touching: usize,
    /// Largest penetration −g found in the first sweep [m] (0 without contact).
    pub max_penetration: f64,
    /// Largest penetration left after the position phase [m] (0 against a rigid structure, up to round-off).
    pub residual_penetration: f64,
    /// Particles whose position or velocity was changed.
    pub particles_corrected: usize,
    /// Position sweeps run.
    pub position_sweeps: u32,
    /// Velocity sweeps run (0 when nothing touched).
    pub velocity_sweeps: u32,
    /// Velocity impulse received by each node [N·s/m]: m Δv for a free node, the reaction passed to the support for
    /// a fixed one. Interface load = impulse / Δt ([`ContactReport::interface_load`]).
    pub node_impulse: Vec<[f64; 2]>,
    /// Mass-weighted position change received by each node [kg·m/m]: m Δx for a free node, the reaction of the
    /// position correction for a fixed one. Together with the particles' m Δx it sums to zero.
    pub node_position_impulse: Vec<[f64; 2]>,
}

impl ContactReport {
    /// Interface load on each node [N/m]: nodal impulse / Δt (`DESIGN.md` §4.5).
    pub fn interface_load(&self, dt: f64) -> Vec<[f64; 2]> {
        self.node_impulse.iter().map(|i| [i[0] / dt, i[1] / dt]).collect()
    }
}

impl ContactReport {
    /// Counts a penetrating contact of the first sweep with master `m` at gap `g` < 0.
    pub(super) fn note_contact(&mut self, m: Master, g: f64) {
        self.contacts += 1;
        if matches!(m, Master::Node(_)) {
            self.node_contacts += 1;
        }
        self.max_penetration = self.max_penetration.max(-g);
    }
}
