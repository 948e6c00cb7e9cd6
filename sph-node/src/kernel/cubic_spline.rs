//! 2D cubic spline kernel (Monaghan & Lattanzio 1985), `DESIGN.md` §4.2.
//!
//! W(q) = α_d (1 − 1.5 q² + 0.75 q³) for 0 ≤ q < 1, α_d · 0.25 (2 − q)³ for 1 ≤ q < 2, 0 beyond;
//! q = r/h, α_d = 10 / (7 π h²). The support radius is 2h.

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// The cubic spline kernel for one smoothing length h.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
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

    /// 1/h: q = r · (1/h) is a multiplication where r/h is a division (issue 20; inlined into a loop, the
    /// reciprocal is taken once, outside it).
    #[inline(always)]
    fn inv_h(&self) -> f64 {
        1.0 / self.h
    }

    /// Support radius 2h.
    pub fn support(&self) -> f64 {
        2.0 * self.h
    }

    /// W(r).
    #[inline]
    pub fn w(&self, r: f64) -> f64 {
        let q = r * self.inv_h();
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
        let q = r * self.inv_h();
        let dw_dq = if q < 1.0 {
            self.alpha * (-3.0 * q + 2.25 * q * q)
        } else if q < 2.0 {
            let t = 2.0 - q;
            -0.75 * self.alpha * t * t
        } else {
            0.0
        };
        dw_dq * self.inv_h()
    }

    /// (W(r), dW/dr(r)/r) in one evaluation, bit for bit as [`CubicSpline::w`] and [`CubicSpline::dw_dr`]`(r) / r`
    /// (the factor is 0 at r = 0, where [`CubicSpline::grad`] is zero): ∇_i W_ij = factor · r_ij.
    #[inline]
    pub fn w_and_grad_factor(&self, r: f64) -> (f64, f64) {
        let q = r * self.inv_h();
        let (w, dw_dq) = if q < 1.0 {
            (
                self.alpha * (1.0 - 1.5 * q * q + 0.75 * q * q * q),
                self.alpha * (-3.0 * q + 2.25 * q * q),
            )
        } else if q < 2.0 {
            let t = 2.0 - q;
            (self.alpha * 0.25 * t * t * t, -0.75 * self.alpha * t * t)
        } else {
            (0.0, 0.0)
        };
        let factor = if r > 0.0 { dw_dq * self.inv_h() / r } else { 0.0 };
        (w, factor)
    }

    /// For squared distances `d2` (each below the support squared): the ∇W factor
    /// ([`CubicSpline::w_and_grad_factor`]) at r = √d2 (as [`crate::particles::separation`] gives r), bit for bit
    /// as the scalar function. Branch-free, so that the compiler can evaluate several pairs at once.
    pub fn grad_factors(&self, d2: &[f64], grad: &mut [f64]) {
        let inv_h = self.inv_h();
        let alpha = self.alpha;
        for (&d2, g) in d2.iter().zip(grad) {
            let r = d2.sqrt();
            let q = r * inv_h;
            let t = 2.0 - q;
            let dq_near = alpha * (-3.0 * q + 2.25 * q * q);
            let dq_far = -0.75 * alpha * t * t;
            let dq = if q < 1.0 {
                dq_near
            } else if q < 2.0 {
                dq_far
            } else {
                0.0
            };
            let f = dq * inv_h / r;
            *g = if r > 0.0 { f } else { 0.0 };
        }
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

    #[test]
    fn fused_evaluation_is_bitwise_equal() {
        let k = CubicSpline::new(0.0013);
        for i in 0..=3000 {
            let r = i as f64 * 0.0026 / 2900.0;
            let (w, f) = k.w_and_grad_factor(r);
            assert_eq!(w.to_bits(), k.w(r).to_bits(), "W at r = {r}");
            let g = k.grad([r, 0.0], r);
            assert_eq!((f * r).to_bits(), g[0].to_bits(), "grad at r = {r}");
            if r > 0.0 {
                assert_eq!(f.to_bits(), (k.dw_dr(r) / r).to_bits(), "factor at r = {r}");
            }
            let d2 = [r * r];
            let mut g = [0.0];
            k.grad_factors(&d2, &mut g);
            let rr = d2[0].sqrt();
            assert_eq!(
                g[0].to_bits(),
                k.w_and_grad_factor(rr).1.to_bits(),
                "factor at r = {rr}"
            );
        }
    }
}
