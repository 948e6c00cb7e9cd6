//! Short-range wall repulsion: a fluid particle closer than [`RANGE`]·Δx to the face of a `[[wall]]` box is
//! pushed back along the face normal, a repulsive boundary force in the family of Monaghan 1994 (J. Comput. Phys.
//! 110:399, §7) and Monaghan & Kajtar 2009 (Comput. Phys. Commun. 180:1811), acting on the distance to the face
//! instead of the distances to boundary particles *(choice)*.
//!
//! Why the Adami walls (§4.7) need it. The wall particles' pressure (Adami et al. 2012, Eq. (27)) mirrors the
//! fluid's, so a wall acts like more fluid: the pressure force between a fluid particle and its neighbours depends
//! only on how they are arranged around it, not on where the face is, and the cubic spline's gradient falls to zero
//! at short range. A fluid layer that the flow presses against a wall settles wherever its neighbourhood balances:
//! measured, with the WCSPH wall guard counting, whole bottom layers rested *on* the face (half a spacing from the
//! first wall layer) with a net acceleration into the wall of 5–20 m/s² (settled dam break) and 50–130 m/s²
//! (the plate scene's corners), and were put back by the guard every step.
//!
//! The force: a = k (d0 − d) n for d < d0, d the distance from the particle to the box (its face or edge), n the
//! unit vector from the box's nearest point to the particle, d0 = [`RANGE`]·Δx, k = (c0/Δx)²: the fluid's own
//! acoustic stiffness over one spacing (a layer Δx thick compressed by d0 − d carries the pressure
//! ρ0 c0² (d0 − d)/Δx, which pushes on a particle of volume Δx² with ρ0 c0² (d0 − d)/Δx² per unit mass). It
//! is a linear spring, conservative; its frequency c0/Δx is below the acoustic limit of the step (§4.2:
//! Δt ≤ 0.25 h/c0 gives ω Δt ≤ 0.33 for h = 1.3 Δx), and at the face (d = 0) it reaches c0²/(4 Δx), far more
//! than any of the pressure imbalances above (2·10⁴ m/s² for the elastic gate at Δx = 5 mm, 4·10⁴ m/s² for the
//! plate scene). A particle arriving at speed v stops within v Δx/c0 of d0 (0.04 Δx at v = c0/25).
//!
//! Water at rest does not reach the zone: in the still tank the particles stay more than 0.3 Δx from the faces
//! (`sph-node/tests/still_water_long.rs` requires Δx/4), so the hydrostatic state is unchanged, bit for bit.

use rayon::prelude::*;

use crate::boundary::wall_guard::WallBoxes;

/// Range d0 of the repulsion, in units of Δx: a quarter spacing from the face (the first wall layer is Δx/2
/// behind it, so the zone begins 3Δx/4 from the nearest wall particle).
pub const RANGE: f64 = 0.25;

/// Constants of the repulsion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Repulsion {
    /// Range d0 (m).
    pub range: f64,
    /// Stiffness k (1/s²).
    pub stiffness: f64,
}

impl Repulsion {
    /// For spacing `dx` and speed of sound `c0`: d0 = [`RANGE`]·Δx, k = (c0/Δx)².
    pub fn new(dx: f64, c0: f64) -> Self {
        let w = c0 / dx;
        Self {
            range: RANGE * dx,
            stiffness: w * w,
        }
    }

    /// The repulsion on a particle at `x` from every box of `walls` within range (zero if none).
    #[inline]
    pub fn acceleration(&self, walls: &WallBoxes, x: [f64; 2]) -> [f64; 2] {
        let mut a = [0.0, 0.0];
        // Beyond this squared distance `hypot` is certainly ≥ d0 (r² is within 4 ulp of |r|², hypot within 1 ulp of
        // |r|): most particles are far from most boxes, and `hypot` is a slow library call (issue 20; the same
        // bits, it decides only what `d >= range` below would).
        let far2 = self.range * self.range * (1.0 + 1e-9);
        for (lo, hi) in walls.boxes() {
            // Nearest point of the box and the distance to it.
            let c = [x[0].clamp(lo[0], hi[0]), x[1].clamp(lo[1], hi[1])];
            let r = [x[0] - c[0], x[1] - c[1]];
            if r[0] * r[0] + r[1] * r[1] >= far2 {
                continue;
            }
            let d = r[0].hypot(r[1]);
            if d >= self.range || d <= 0.0 {
                // Out of range; or inside the box, which the wall guard deals with.
                continue;
            }
            // a = k (d0 − d) n, n = r/d (see the module documentation)
            let f = self.stiffness * (self.range - d) / d;
            a[0] += f * r[0];
            a[1] += f * r[1];
        }
        a
    }

    /// Adds the repulsion to the accelerations `accel` of the particles at `x`.
    pub fn add_into(&self, walls: &WallBoxes, x: &[[f64; 2]], accel: &mut [[f64; 2]]) {
        accel
            .par_iter_mut()
            .zip(x.par_iter())
            .with_min_len(1024)
            .for_each(|(a, &x)| {
                let r = self.acceleration(walls, x);
                a[0] += r[0];
                a[1] += r[1];
            });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cosim_proto::scene::BoxSpec;

    fn tank() -> WallBoxes {
        let b = |min, max| BoxSpec { min, max };
        WallBoxes::new(
            &[b([-0.03, -0.03], [0.5, 0.0]), b([-0.03, 0.0], [0.0, 0.3])],
            0.01,
            0.013,
            [0.1, 0.1],
        )
    }

    #[test]
    fn nothing_beyond_a_quarter_spacing() {
        let rep = Repulsion::new(0.01, 20.0);
        for x in [[0.1, 0.0025], [0.0025, 0.1], [0.2, 0.1], [0.003, 0.003]] {
            assert_eq!(rep.acceleration(&tank(), x), [0.0, 0.0], "{x:?}");
        }
    }

    #[test]
    fn linear_along_the_face_normal() {
        // k = (20 / 0.01)² = 4e6 s⁻²; at d = 1 mm from the floor: 4e6 · (2.5 − 1) mm = 6000 m/s² upwards.
        let rep = Repulsion::new(0.01, 20.0);
        let a = rep.acceleration(&tank(), [0.2, 0.001]);
        assert!(a[0] == 0.0 && (a[1] - 6000.0).abs() < 1e-9, "{a:?}");
        // In the corner both walls push: 1 mm from each face.
        let a = rep.acceleration(&tank(), [0.001, 0.001]);
        assert!((a[0] - 6000.0).abs() < 1e-9 && (a[1] - 6000.0).abs() < 1e-9, "{a:?}");
    }

    #[test]
    fn round_a_convex_edge() {
        // The end of a floor that stops at x = 0.5: a particle beyond it is pushed away from the edge.
        let rep = Repulsion::new(0.01, 20.0);
        let a = rep.acceleration(&tank(), [0.5012, 0.0016]);
        let d: f64 = 0.002;
        let f = 4e6 * (0.0025 - d) / d;
        assert!(
            (a[0] - f * 0.0012).abs() < 1e-9 && (a[1] - f * 0.0016).abs() < 1e-9,
            "{a:?}"
        );
    }
}
