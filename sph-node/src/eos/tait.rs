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

    /// The elastic energy per unit mass stored by compressing to ρ from ρ0 (J/kg): e(ρ) = ∫_ρ0^ρ p(ρ')/ρ'² dρ'
    /// = (B/ρ0) [((ρ/ρ0)^6 − 1)/6 + ρ0/ρ − 1], the work the pressure does on a particle's volume (de = −p dV per
    /// mass, V = 1/ρ). Zero at ρ0 and positive either side (c0² (ρ/ρ0 − 1)²/2 near it); with the kinetic and
    /// gravitational energy it is what the WCSPH equations conserve between their dissipative terms.
    #[inline]
    pub fn specific_energy(&self, rho: f64) -> f64 {
        let gm1 = (GAMMA - 1) as f64;
        let ratio = rho / self.rho0;
        self.b / self.rho0 * ((ratio.powi(GAMMA - 1) - 1.0) / gm1 + 1.0 / ratio - 1.0)
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

    #[test]
    fn the_specific_energy_is_the_work_of_the_pressure() {
        let eos = Tait::new(1000.0, 30.0);
        assert_eq!(eos.specific_energy(1000.0), 0.0);
        for rho in [990.0, 999.9, 1000.1, 1003.0, 1020.0] {
            // de/dρ = p/ρ², by central differences (relative step 1e-6).
            let d = 1e-6 * rho;
            let slope = (eos.specific_energy(rho + d) - eos.specific_energy(rho - d)) / (2.0 * d);
            let want = eos.pressure(rho) / (rho * rho);
            assert!(
                (slope - want).abs() <= 1e-6 * want.abs(),
                "ρ = {rho}: {slope} against {want}"
            );
            // Near ρ0 the acoustic energy c0² (ρ/ρ0 − 1)²/2, to first order in the strain.
            let strain: f64 = rho / 1000.0 - 1.0;
            let acoustic = 0.5 * 30.0 * 30.0 * strain * strain;
            let e = eos.specific_energy(rho);
            assert!(
                e > 0.0 && (e / acoustic - 1.0).abs() < 4.0 * strain.abs(),
                "ρ = {rho}: {e} against {acoustic}"
            );
        }
    }
}
