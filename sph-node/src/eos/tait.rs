//! Tait equation of state (`DESIGN.md` §4.2): p = B [(ρ/ρ0)^7 − 1], B = ρ0 c0² / 7.

use serde::{Deserialize, Serialize};
/// Polytropic exponent γ of the Tait law for water.
pub const GAMMA: i32 = 7;

/// The Tait law for one rest density and sound speed.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Tait {
    /// Rest density ρ0 (kg/m³).
    pub rho0: f64,
    /// Speed of sound c0 (m/s).
    pub c0: f64,
    b: f64,
}

impl Tait {
    /// Tait law with B = ρ0 c0² / 7.
    pub fn new(rho0: f64, c0: f64) -> Self {
        Self {
            rho0,
            c0,
            b: rho0 * c0 * c0 / GAMMA as f64,
        }
    }

    /// B = ρ0 c0² / 7.
    pub fn b(&self) -> f64 {
        self.b
    }

    /// p(ρ) = B [(ρ/ρ0)^7 − 1].
    #[inline]
    pub fn pressure(&self, rho: f64) -> f64 {
        self.b * ((rho / self.rho0).powi(GAMMA) - 1.0)
    }

    /// The inverse: ρ(p) = ρ0 (1 + p/B)^(1/7); p is clamped above −B so the root exists.
    #[inline]
    pub fn density(&self, p: f64) -> f64 {
        let ratio = (1.0 + p / self.b).max(1e-12);
        self.rho0 * ratio.powf(1.0 / GAMMA as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_round_trip() {
        let eos = Tait::new(1000.0, 30.0);
        for p in [-1000.0, 0.0, 4905.0, 1.0e5] {
            assert!((eos.pressure(eos.density(p)) - p).abs() < 1e-6 * (1.0 + p.abs()));
        }
        assert_eq!(eos.pressure(1000.0), 0.0);
    }
}
