//! The scratch memory of the particle–element pass (`DESIGN.md` §2: state apart from scratch).

use super::detection::{Master, Topology};
use super::projection::Planes;
use super::setup::Mark;
use super::touching::Contact;
use crate::contact::grid::CellGrid;

/// Scratch arrays of [`particle_element_with`](super::particle_element_with): keep one per caller and pass it to
/// every call so the arrays are allocated once. Holds no state between calls: results never depend on what it held
/// before. Not serialisable, by design.
#[derive(Clone, Debug, Default)]
pub struct ParticleElementWorkspace {
    /// Set-up: the segments binned in cells, the node → segment tables, 1/m per node.
    pub(super) grid: CellGrid,
    pub(super) topo: Topology,
    pub(super) inv_m: Vec<f64>,
    /// Per particle: corrected, and what the position phase learnt.
    pub(super) marks: Vec<Mark>,
    /// The masters near the particle being visited, and (position phase) the immovable ones of them.
    pub(super) masters: Vec<Master>,
    pub(super) rigid: Vec<Master>,
    /// The touching set, and (velocity phase) one particle's immovable contacts.
    pub(super) contacts: Vec<Contact>,
    pub(super) planes: Planes,
    /// Visit every particle in every sweep even where the nodes are static (tests compare the two).
    pub(super) exhaustive: bool,
}
