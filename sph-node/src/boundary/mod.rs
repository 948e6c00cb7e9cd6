//! Rigid walls (`DESIGN.md` §4.7): fixed boundary particles and their pressure.

pub mod adami;
pub mod repulsion;
pub mod wall_guard;
pub mod walls;
