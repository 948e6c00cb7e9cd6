//! Neighbour search.

pub mod candidates;
pub mod cell_list;
pub mod grid;
pub mod sorted;
pub mod verlet;

pub use cell_list::{CellList, ListChunk, NeighborList, CHUNK};
pub use grid::Grid;
pub use sorted::SortedCells;
pub use verlet::VerletCandidates;
