//! The scratch memory of the particle–element pass (`DESIGN.md` §2: state apart from scratch).

use super::detection::{Master, Topology};
use super::memo::Memo;
use super::pairs::{ContactPair, PairLog};
use super::projection::Planes;
use super::rigid::Gaps;
use super::segment_grid::SegmentGrid;
use super::setup::{Mark, StaticGeometry};
use super::touching::Contact;

/// Scratch arrays of [`particle_element_with`](super::particle_element_with): keep one per caller and pass it to
/// every call so the arrays are allocated once. Holds no state between calls: results never depend on what it held
/// before (the last pass's pairs are kept for reading only). Not serialisable, by design.
#[derive(Clone, Debug, Default)]
pub struct ParticleElementWorkspace {
    /// The segments binned in cells (set-up).
    pub(super) grid: SegmentGrid,
    /// Node → segment tables (set-up).
    pub(super) topo: Topology,
    /// 1/m per node, 0 for a fixed one (set-up).
    pub(super) inv_m: Vec<f64>,
    /// Segment frames and acting nodes of a pass with static nodes (set-up).
    pub(super) statics: StaticGeometry,
    /// Per particle: corrected, and what the position phase learnt.
    pub(super) marks: Vec<Mark>,
    /// The masters near the particle being visited (position phase, touching set).
    pub(super) masters: Vec<Master>,
    /// The immovable ones of them (position phase).
    pub(super) rigid: Vec<Master>,
    /// The gaps of the immovable masters the exact projection computes (position phase).
    pub(super) gaps: Gaps,
    /// The gaps the position phase kept per particle for its later visits.
    pub(super) memo: Memo,
    /// The touching set: the velocity phase's contacts.
    pub(super) contacts: Vec<Contact>,
    /// The immovable contacts of the particle being visited (velocity phase).
    pub(super) planes: Planes,
    /// Visit every particle in every sweep even where the nodes are static (tests compare the two).
    pub(super) exhaustive: bool,
    /// The pairs the last pass acted on (kept after the pass: [`ParticleElementWorkspace::pairs`]).
    pub(super) pairs: PairLog,
}

impl ParticleElementWorkspace {
    /// Each (particle, master) pair the last pass acted on, ordered by particle then master, with its gap at
    /// detection and the λ and J applied to it ([`ContactPair`]). Empty before the first pass.
    pub fn pairs(&self) -> &[ContactPair] {
        self.pairs.pairs()
    }
}
