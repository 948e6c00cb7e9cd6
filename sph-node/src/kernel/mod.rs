//! Smoothing kernels.

pub mod cubic_spline;

pub use cubic_spline::CubicSpline;
