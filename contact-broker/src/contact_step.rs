//! The longest coupling step at which the explicit contact force keeps the energy (docs/CORRECTIONS.md
//! "`particle_particle` heats the structure: the coupling step bounded by the contact's stiffness").
//!
//! `particle_particle` applies Monaghan's (1994) repulsive force once per coupling step, from the positions the step
//! ended at, to the particle and to the segment's nodes: for each pair that is symplectic Euler on a spring of
//! frequency Ω, stable only for Ω Δt < 2 and accurate in energy only well below. The force is stiff (Ω_c =
//! √(D (p1 − p2))/r0 at its range, steeper inside it) and a structure node is lighter than the particles that press
//! on it, so the node's side is the faster one: on the shipped gate with WCSPH, Ω Δt over the nodes was 1.3 at the
//! median coupling step and 2.3 at most, and the structure gained energy linearly in time (+8.9 J/m by 0.4 s, 0.93
//! of the column's potential energy; +0.4 J/m at 0.2 s at a third of the step).
//!
//! So the contact bounds the next coupling step by [`COURANT`] / Ω_max. Ω_max² is the larger of the pass's Gershgorin
//! bounds on M⁻¹K over the particles and over the free nodes ([`Stiffness`]), each pair's stiffness taken where the
//! pair will turn, at the energy of its closing motion (`ParticleParticleParams::turning_point`): taken where the
//! pair is, the bound comes a step late on a fast approach into the force's steep part (a particle at 3 m/s onto a
//! free node as heavy as itself left with 4.2 times its energy; anticipated, within 1 %). A node's side counts with
//! the share ω of its impulse it receives at once ([`crate::relaxation`]): it answers as a node 1/ω as heavy. The
//! clock keeps the shortest bound of the run ([`crate::coordinator`]): a step that follows the contact's stiffness
//! up and down pumps energy into it (the shipped gate with the bound of each pass alone: an element inverted at
//! 0.16 s; kept: +0.43 J/m in the structure by 0.2 s).
//!
//! With WCSPH only: within one of its (acoustic) steps a particle moves as a free mass, which is what the bound
//! assumes. An ISPH particle is held by the pressure solve within its step, and its contact reaction is relaxed
//! instead (`relaxation.rs`); the free particle's bound would take from ISPH the long step it exists for.

use cosim_proto::scene::{ContactAlgorithm, FluidSolver, Scene};

use crate::contact::Stiffness;

/// Ω_max Δt of the longest coupling step a stiff contact allows.
pub const COURANT: f64 = 0.7;

/// Whether `scene`'s coupling steps are bounded by the contact force's stiffness: `particle_particle` with a WCSPH
/// fluid (the other algorithms exert no force: [`Stiffness`] zero).
pub fn applies(scene: &Scene) -> bool {
    scene.contact.algorithm == ContactAlgorithm::ParticleParticle
        && scene.fluid.as_ref().is_some_and(|f| f.solver == FluidSolver::Wcsph)
}

/// The longest next coupling step for a pass of stiffness `stiffness` whose nodes receive the share `omega` of their
/// impulse at once; `None` where the pass exerted no force.
pub fn stable_step(stiffness: Stiffness, omega: f64) -> Option<f64> {
    let omega2 = stiffness.particles.max(omega * stiffness.nodes);
    (omega2 > 0.0 && omega2.is_finite()).then(|| COURANT / omega2.sqrt())
}

#[cfg(test)]
mod tests;
