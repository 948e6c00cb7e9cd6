//! Fluid–structure contact, pure (no messaging): the particle–element algorithm of Long, Hu, Yang & Wan (2016),
//! after Johnson & Stryk (2001), and the particle–particle baseline it is compared with (`DESIGN.md` §4.5, §4.6),
//! each a [`ContactAlgorithm`] that owns its scratch memory; `()` is the algorithm for no contact.
//!
//! # Data
//! Slaves are fluid particles ([`Particles`]); masters are the structure's boundary segments ([`Segment`], node
//! index pairs into [`Nodes`]). The structure lies on the *left* of each segment a → b (a counter-clockwise outer
//! boundary, or a clockwise tank wall), so the outward normal n = (Δy, −Δx)/L points into the fluid. A fixed node
//! has infinite mass (1/m = 0): it is never moved, and what it receives is reported as a reaction.
//! Everything is per unit thickness (2D); masses in kg/m, impulses in N·s/m.
//!
//! # Particle–element ([`particle_element`], [`ParticleElement`], `DESIGN.md` §4.5)
//! For each particle s near a segment: ξ = (x_s − x1)·t/L, N1 = 1 − ξ, N2 = ξ, x_c = N1 x1 + N2 x2,
//! g = (x_s − x_c)·n − r_c, active if 0 ≤ ξ ≤ 1, g < 0 and (x_s − x_c)·n > −d_max. With the effective inverse mass
//! w = 1/m_s + N1²/m1 + N2²/m2, positions are corrected by λ = −g/w (x_s += λ/m_s n, x_a −= λ N_a/m_a n) and then,
//! for approaching contacts (v_rel = (v_s − N1 v1 − N2 v2)·n < 0), velocities by the impulse J = −v_rel/w
//! (v_s += J/m_s n, v_a −= J N_a/m_a n); tangential velocity is untouched (free slip). At a concave corner both
//! segments act; at a convex corner the wedge outside both segments' ξ ranges is a node contact with
//! n = (x_s − x_node)/|x_s − x_node| (the free ends of an open chain are rounded the same way).
//!
//! Order of work (deterministic, no hashing, no threads): a position phase of Gauss–Seidel sweeps over the
//! particles in index order (each particle's masters in segment order), then a velocity phase of sweeps over the
//! contacts that touch after the position phase, with positions frozen. Sweeps stop early once the largest
//! correction of a sweep is below the tolerance. Contacts with immovable masters (all nodes fixed) are solved
//! exactly per particle instead of swept (`particle_element/projection.rs`), so against a rigid structure no particle is left inside
//! the contact thickness and no contact approaches, whatever the corner angles.
//!
//! # Conservation
//! Each impulse J n on the particle is balanced by −J N_a n on the nodes (N1 + N2 = 1), so linear momentum is
//! unchanged; its moment is J (x_s − x_c) × n = 0 because x_c is the projection of x_s (x_s − x_c ∥ n), and a node
//! contact's n is along x_s − x_node. The velocity phase works at the corrected positions, so the total angular
//! momentum Σ m x × v at those positions is unchanged to round-off. The position phase conserves the mass-weighted
//! analogues: Σ m x (the centre of mass) and, per contact, Σ m x × Δx. The motion of the positions themselves
//! changes Σ m x × v by λ n × v_rel per contact (sliding particles are moved sideways of their momentum): this is
//! inherent in any position projection with free slip and is not a round-off matter. Impulses received by fixed
//! nodes are reported ([`ContactReport::node_impulse`]) so balances close including the supports.
//!
//! # Particle–particle ([`particle_particle`], [`ParticleParticle`], `DESIGN.md` §4.6)
//! Boundary nodes and extra points along each segment (spacing ≤ Δx) repel particles with Monaghan's (1994)
//! Lennard-Jones force a = D[(r0/r)^p1 − (r0/r)^p2] r/r² for r < r0; each reaction is spread on the segment's
//! nodes with N1, N2 so linear and angular momentum are conserved.
//!
//! # Cost
//! Segments are binned in a uniform cell list (`grid.rs`), so one call costs O(particles + segments) per sweep.
//! Each algorithm keeps its scratch arrays between calls ([`ParticleElementWorkspace`],
//! [`ParticleParticleWorkspace`]), so they are allocated once.
//!
//! # Files
//! `algorithm.rs` the trait; `bodies.rs` the particles, nodes and segments and their check; `error.rs` bad input;
//! `particle_element/` the particle–element pass, one file per step (see its docs); `particle_particle.rs` the
//! baseline; `geometry.rs` and `grid.rs` the 2D vector helpers and the cell list both use. `mod.rs` only lists them:
//! the files import one another without loops (algorithms → bodies, error, geometry, grid).

mod algorithm;
mod bodies;
mod error;
mod face;
mod geometry;
mod grid;
mod pair;
mod particle_element;
mod particle_particle;

pub use algorithm::{ContactAlgorithm, PassReport, Stiffness};
pub use bodies::{Nodes, Particles, Segment};
pub use error::ContactError;
pub use face::nearest_face;
pub use particle_element::{
    particle_element, particle_element_with, ContactPair, ContactParams, ContactReport, PairMaster, ParticleElement,
    ParticleElementWorkspace,
};
pub use particle_particle::{
    particle_particle, particle_particle_with, ParticleParticle, ParticleParticleParams, ParticleParticleReport,
    ParticleParticleWorkspace,
};
