//! Equations of state.

pub mod tait;

pub use tait::Tait;
