//! Water-level gauges (`DESIGN.md` §5 `water_level` probes): the height of the free surface above a gauge's foot,
//! along the vertical line through it, as a wave gauge in a tank reads it (Lobovsky et al. 2014, gauges H1–H4).
//!
//! The surface is where the SPH fluid fraction φ(y) = Σ_j V_j W(|(x_g, y) − x_j|, h) (fluid V_j = m_j/ρ_j, walls the
//! lattice cell Δx²) passes ½: a half-plane of particles fills half a kernel support at its edge, so a lattice whose
//! top row sits Δx/2 below H reads H. The gauge reads the highest such surface, coming down from above the water, as
//! a gauge looking down on it does: an overturning crest over an air pocket is water at the gauge (at Lobovsky's
//! H4 the returning plunging wave reads 0.75 H in the data, where the layer under the pocket is 0.1–0.3 H), while a
//! lone droplet is not (one particle fills at most V W(0) = 0.27 of a support at h = 1.3 Δx). A line with no point
//! at φ ≥ ½ (a dry foot) reads 0.

use crate::kernel::CubicSpline;
use crate::sensors::PressureField;

/// Step of the upward scan, in units of Δx; the crossing is then interpolated linearly between two samples.
const SCAN_STEP: f64 = 0.1;

/// Height of the highest water surface above `foot` along the vertical line through it (0 where it is dry). The
/// particles are those of `field` (its pressures are not used).
pub fn water_level(field: &PressureField<'_>, foot: [f64; 2]) -> f64 {
    let kernel = CubicSpline::new(field.h);
    let reach = kernel.support();
    let wall_volume = field.spacing * field.spacing;
    // The particles within the kernel's reach of the line, with their volumes.
    let fluid = field
        .x
        .iter()
        .zip(field.m.iter().zip(field.rho))
        .map(|(x, (m, rho))| (*x, m / rho));
    let walls = field.wall_x.iter().map(|x| (*x, wall_volume));
    let column: Vec<([f64; 2], f64)> = fluid
        .chain(walls)
        .filter(|(x, v)| (x[0] - foot[0]).abs() < reach && x[1] >= foot[1] - reach && v.is_finite())
        .collect();
    let top = column.iter().map(|(x, _)| x[1]).fold(foot[1], f64::max) + reach;
    let phi = |y: f64| -> f64 {
        column
            .iter()
            .map(|(x, v)| {
                let r = (x[0] - foot[0]).hypot(x[1] - y);
                if r < reach {
                    v * kernel.w(r)
                } else {
                    0.0
                }
            })
            .sum()
    };
    let step = SCAN_STEP * field.spacing;
    // Down from above the highest particle: the first sample inside the water, then the crossing above it.
    let (mut y, mut f) = (top, phi(top));
    while y > foot[1] {
        let (y1, f1) = (y - step, phi(y - step));
        if f1 >= 0.5 {
            // φ rises through ½ between y1 and y
            return y1 + step * (f1 - 0.5) / (f1 - f) - foot[1];
        }
        (y, f) = (y1, f1);
    }
    0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A still lattice of water H deep (top row at H − Δx/2) on a three-layer floor: the gauge reads H within a
    /// twentieth of a spacing, anywhere along the tank; a dry floor reads 0.
    #[test]
    fn a_lattice_reads_its_depth_and_a_dry_floor_reads_zero() {
        let (dx, depth, width) = (0.01, 0.3, 0.5);
        let (nx, ny) = ((width / dx) as usize, (depth / dx) as usize);
        let mut x = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                x.push([(i as f64 + 0.5) * dx, (j as f64 + 0.5) * dx]);
            }
        }
        let mut walls = Vec::new();
        for j in 0..3 {
            for i in 0..(2 * nx) {
                walls.push([(i as f64 + 0.5) * dx, -(j as f64 + 0.5) * dx]);
            }
        }
        let (m, rho) = (vec![1000.0 * dx * dx; x.len()], vec![1000.0; x.len()]);
        let p = vec![0.0; x.len()];
        let field = PressureField {
            x: &x,
            m: &m,
            rho: &rho,
            p: &p,
            wall_x: &walls,
            h: 1.3 * dx,
            spacing: dx,
        };
        for xg in [0.1, 0.2543, 0.4] {
            let level = water_level(&field, [xg, 0.0]);
            assert!(
                (level - depth).abs() < 0.05 * dx,
                "x = {xg}: level {level}, depth {depth}"
            );
        }
        // Beyond the water's end (x = 0.5 m) by more than the kernel's reach: the floor alone.
        let dry = water_level(&field, [0.8, 0.0]);
        assert!(dry < 0.05 * dx, "dry floor reads {dry}");
    }
}
