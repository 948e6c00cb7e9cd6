//! What a contact algorithm reports of its last pass, pair by pair ([`super::ContactAlgorithm::pairs`]): the types
//! are the algorithms' common language, so they sit beside the trait; the particle–element pass fills them
//! (`particle_element/pairs.rs`).

/// The master of a [`ContactPair`]: a boundary segment (index into the pass's segments), or a boundary node acting
/// on its own (convex corner, end of an open chain).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum PairMaster {
    /// Segment index.
    Segment(u32),
    /// Node index.
    Node(u32),
}

/// One (particle, master) pair the last pass acted on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactPair {
    /// The particle (index into the pass's particles).
    pub particle: usize,
    /// The master.
    pub master: PairMaster,
    /// Gap g when the pass first acted on the pair [m] (negative: penetrating): at the particle's position when
    /// detected in the position phase, or in the touching set for a pair only the velocity phase acted on.
    pub gap: f64,
    /// Position multiplier λ applied to the pair, all sweeps [kg m]: the particle moved by λ/m_s along the
    /// contact normal (λ = −g/w, `DESIGN.md` §4.5; against an immovable master m_s μ, `projection.rs`).
    pub lambda: f64,
    /// Velocity impulse J applied to the pair, all sweeps [kg m/s] (J = −v_rel/w, `DESIGN.md` §4.5; against an
    /// immovable master m_s μ).
    pub impulse: f64,
}
