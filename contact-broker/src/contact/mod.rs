//! Fluid–structure contact, pure (no messaging): the particle–element algorithm of Long, Hu, Yang & Wan (2016),
//! after Johnson & Stryk (2001), and the particle–particle baseline it is compared with (`DESIGN.md` §4.5, §4.6).
//!
//! # Data
//! Slaves are fluid particles ([`Particles`]); masters are the structure's boundary segments ([`Segment`], node
//! index pairs into [`Nodes`]). The structure lies on the *left* of each segment a → b (a counter-clockwise outer
//! boundary, or a clockwise tank wall), so the outward normal n = (Δy, −Δx)/L points into the fluid. A fixed node
//! has infinite mass (1/m = 0): it is never moved, and what it receives is reported as a reaction.
//! Everything is per unit thickness (2D); masses in kg/m, impulses in N·s/m.
//!
//! # Particle–element ([`particle_element`], `DESIGN.md` §4.5)
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
//! exactly per particle instead of swept (see `rigid.rs`), so against a rigid structure no particle is left inside
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
//! # Particle–particle ([`particle_particle`], `DESIGN.md` §4.6)
//! Boundary nodes and extra points along each segment (spacing ≤ Δx) repel particles with Monaghan's (1994)
//! Lennard-Jones force a = D[(r0/r)^p1 − (r0/r)^p2] r/r² for r < r0; each reaction is spread on the segment's
//! nodes with N1, N2 so linear and angular momentum are conserved.
//!
//! # Cost
//! Segments are binned in a uniform cell list (`grid.rs`), so one call costs O(particles + segments) per sweep.
//! Reuse a [`ContactWorkspace`] across calls to avoid reallocating the scratch arrays.

mod detection;
mod geometry;
mod grid;
mod particle_element;
mod particle_particle;
mod rigid;
mod workspace;

pub use particle_element::{particle_element, particle_element_with, ContactParams, ContactReport};
pub use particle_particle::{
    particle_particle, particle_particle_with, ParticleParticleParams, ParticleParticleReport,
};
pub use workspace::ContactWorkspace;

/// Slave particles: the fluid particles in the region of interest. `x` and `v` are corrected in place.
#[derive(Debug)]
pub struct Particles<'a> {
    /// Positions [m].
    pub x: &'a mut [[f64; 2]],
    /// Velocities [m/s].
    pub v: &'a mut [[f64; 2]],
    /// Masses [kg/m], positive.
    pub m: &'a [f64],
}

/// Structure nodes (masters). `x` and `v` of free nodes are corrected in place; fixed nodes are never written.
#[derive(Debug)]
pub struct Nodes<'a> {
    /// Positions [m].
    pub x: &'a mut [[f64; 2]],
    /// Velocities [m/s].
    pub v: &'a mut [[f64; 2]],
    /// Lumped masses [kg/m], positive for free nodes (ignored for fixed ones).
    pub m: &'a [f64],
    /// Fixed (clamped or prescribed) nodes: infinite mass, 1/m = 0.
    pub fixed: &'a [bool],
}

/// A boundary segment from node `a` to node `b` (indices into [`Nodes`]). The structure lies on its left, so its
/// outward normal n = (Δy, −Δx)/L points into the fluid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Segment {
    /// Start node.
    pub a: usize,
    /// End node.
    pub b: usize,
}

/// Bad input to a contact routine. Nothing is modified when one is returned.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ContactError {
    /// Two arrays that must match in length do not.
    #[error("{what} has {got} entries, expected {expected}")]
    Length {
        /// Which array.
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Actual length.
        got: usize,
    },
    /// A segment names a node that does not exist, or the same node twice.
    #[error(
        "segment {segment} ({a} -> {b}) is invalid: there are {nodes} nodes and a segment needs two distinct ones"
    )]
    Segment {
        /// Segment index.
        segment: usize,
        /// Its start node.
        a: usize,
        /// Its end node.
        b: usize,
        /// Number of nodes.
        nodes: usize,
    },
    /// A non-finite coordinate or velocity, or a mass that is not positive and finite.
    #[error("{what} {index}: {field} is {value}, it must be finite{positive}")]
    Value {
        /// `particle` or `node`.
        what: &'static str,
        /// Its index.
        index: usize,
        /// `x`, `v` or `m`.
        field: &'static str,
        /// The offending value.
        value: f64,
        /// `" and positive"` for masses.
        positive: &'static str,
    },
    /// A contact parameter out of range.
    #[error("contact parameter `{name}` is {value}: it must be {expected}")]
    Param {
        /// Parameter name.
        name: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        expected: &'static str,
    },
}

/// Checks array lengths, segment indices and that every value is usable.
pub(crate) fn validate(p: &Particles, n: &Nodes, segments: &[Segment]) -> Result<(), ContactError> {
    let len = |what, expected, got| {
        if expected == got {
            Ok(())
        } else {
            Err(ContactError::Length { what, expected, got })
        }
    };
    let np = p.x.len();
    len("particle velocities", np, p.v.len())?;
    len("particle masses", np, p.m.len())?;
    let nn = n.x.len();
    len("node velocities", nn, n.v.len())?;
    len("node masses", nn, n.m.len())?;
    len("node fixed flags", nn, n.fixed.len())?;
    for (j, s) in segments.iter().enumerate() {
        if s.a >= nn || s.b >= nn || s.a == s.b {
            return Err(ContactError::Segment {
                segment: j,
                a: s.a,
                b: s.b,
                nodes: nn,
            });
        }
    }
    let check = |what, xs: &[[f64; 2]], vs: &[[f64; 2]], ms: &[f64], mass_needed: &dyn Fn(usize) -> bool| {
        for i in 0..xs.len() {
            for (field, val) in [("x", xs[i]), ("v", vs[i])] {
                if let Some(&bad) = val.iter().find(|c| !c.is_finite()) {
                    return Err(ContactError::Value {
                        what,
                        index: i,
                        field,
                        value: bad,
                        positive: "",
                    });
                }
            }
            if mass_needed(i) && !(ms[i] > 0.0 && ms[i].is_finite()) {
                let positive = " and positive";
                return Err(ContactError::Value {
                    what,
                    index: i,
                    field: "m",
                    value: ms[i],
                    positive,
                });
            }
        }
        Ok(())
    };
    check("particle", p.x, p.v, p.m, &|_| true)?;
    check("node", n.x, n.v, n.m, &|k| !n.fixed[k])
}

/// Checks that a parameter is finite and satisfies `ok`.
pub(crate) fn param(name: &'static str, value: f64, ok: bool, expected: &'static str) -> Result<(), ContactError> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(ContactError::Param { name, value, expected })
    }
}
