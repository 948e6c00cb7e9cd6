//! Reusable scratch memory of the contact routines (`DESIGN.md` §2: state apart from scratch).

use super::detection::{Master, Topology};
use super::grid::CellGrid;
use super::particle_element::{Contact, Visit};
use super::particle_particle::BoundaryPoint;
use super::rigid::HalfPlane;

/// Scratch arrays of [`particle_element_with`](super::particle_element_with) and
/// [`particle_particle_with`](super::particle_particle_with): keep one per caller and pass it to every call so the
/// arrays are allocated once. Holds no state between calls: results never depend on what it held before.
#[derive(Clone, Debug, Default)]
pub struct ContactWorkspace {
    pub(crate) grid: CellGrid,
    pub(crate) topo: Topology,
    pub(crate) inv_m: Vec<f64>,
    pub(crate) masters: Vec<Master>,
    pub(crate) rigid: Vec<Master>,
    pub(crate) touched: Vec<bool>,
    pub(crate) contacts: Vec<Contact>,
    pub(crate) planes: Vec<HalfPlane>,
    pub(crate) plane_contacts: Vec<usize>,
    pub(crate) points: Vec<BoundaryPoint>,
    pub(crate) visits: Vec<Visit>,
    /// Visit every particle in every sweep even where the nodes are static (tests compare the two).
    pub(crate) exhaustive: bool,
}
