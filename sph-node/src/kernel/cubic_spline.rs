//! 2D cubic spline kernel (Monaghan & Lattanzio 1985), `DESIGN.md` §4.2.
//!
//! W(q) = α_d (1 − 1.5 q² + 0.75 q³) for 0 ≤ q < 1, α_d · 0.25 (2 − q)³ for 1 ≤ q < 2, 0 beyond;
//! q = r/h, α_d = 10 / (7 π h²). The support radius is 2h.

use std::f64::consts::PI;

/// The cubic spline kernel for one smoothing length h.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CubicSpline {
    h: f64,
    alpha: f64,
}

impl CubicSpline {
    /// Kernel with smoothing length `h`.
    pub fn new(h: f64) -> Self {
        Self {
            h,
            alpha: 10.0 / (7.0 * PI * h * h),
        }
    }

    /// Smoothing length h.
    pub fn h(&self) -> f64 {
        self.h
    }

    /// Support radius 2h.
    pub fn support(&self) -> f64 {
        2.0 * self.h
    }

    /// W(r).
    #[inline]
    pub fn w(&self, r: f64) -> f64 {
        let q = r / self.h;
        if q < 1.0 {
            self.alpha * (1.0 - 1.5 * q * q + 0.75 * q * q * q)
        } else if q < 2.0 {
            let t = 2.0 - q;
            self.alpha * 0.25 * t * t * t
        } else {
            0.0
        }
    }

    /// dW/dr (≤ 0).
    #[inline]
    pub fn dw_dr(&self, r: f64) -> f64 {
        let q = r / self.h;
        let dw_dq = if q < 1.0 {
            self.alpha * (-3.0 * q + 2.25 * q * q)
        } else if q < 2.0 {
            let t = 2.0 - q;
            -0.75 * self.alpha * t * t
        } else {
            0.0
        };
        dw_dq / self.h
    }

    /// ∇_i W_ij for r_ij = x_i − x_j at distance `r` = |r_ij|; zero at r = 0.
    #[inline]
    pub fn grad(&self, r_ij: [f64; 2], r: f64) -> [f64; 2] {
        if r <= 0.0 {
            return [0.0, 0.0];
        }
        let f = self.dw_dr(r) / r;
        [f * r_ij[0], f * r_ij[1]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn continuous_at_q_equal_one() {
        let k = CubicSpline::new(1.0);
        let below = k.w(1.0 - 1e-12);
        let above = k.w(1.0 + 1e-12);
        assert!((below - above).abs() < 1e-10);
        assert_eq!(k.w(2.0), 0.0);
    }
}
