//! Neighbour search.

pub mod cell_list;
pub mod sorted;

pub use cell_list::{CellList, ListChunk, NeighborList, CHUNK};
pub use sorted::{Grid, SortedCells};
