//! Neighbour search.

pub mod cell_list;

pub use cell_list::{CellList, NeighborList};
