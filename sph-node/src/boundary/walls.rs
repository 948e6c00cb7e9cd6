//! `[[wall]]` boxes filled with fixed boundary particles on the lattice of the fluid.
//!
//! A wall must be at least [`MIN_LAYERS`] particles thick, and thick enough to fill the kernel support (2h) of a
//! fluid particle touching it; a thinner box is extended on its side away from the fluid.

use std::collections::BTreeSet;

use cosim_proto::scene::BoxSpec;

/// Fewest particle layers in a wall.
pub const MIN_LAYERS: usize = 3;

/// Layers a wall needs: at least [`MIN_LAYERS`] and ⌈2h/Δx⌉.
pub fn layers_needed(dx: f64, h: f64) -> usize {
    MIN_LAYERS.max((2.0 * h / dx - 1e-9).ceil() as usize)
}

/// The region `wall`'s particles fill: the box itself, or a box thinner than [`layers_needed`] rows grown away from
/// the fluid (`fluid_centre` tells which side faces it) so that it still holds them. (lower, upper) corner.
pub fn filled_box(wall: &BoxSpec, dx: f64, h: f64, fluid_centre: [f64; 2]) -> ([f64; 2], [f64; 2]) {
    let layers = layers_needed(dx, h) as f64;
    let (mut lo, mut hi) = (wall.min, wall.max);
    for k in 0..2 {
        let need = layers * dx - (hi[k] - lo[k]);
        if need > 1e-12 {
            if 0.5 * (lo[k] + hi[k]) < fluid_centre[k] {
                lo[k] -= need;
            } else {
                hi[k] += need;
            }
        }
    }
    (lo, hi)
}

/// Wall particle positions for `walls`, on the lattice x = origin + (k + ½) Δx. `fluid_centre` tells a thin box
/// which side faces the fluid. Points shared by overlapping boxes appear once; the order is by lattice row, then
/// column.
pub fn wall_positions(walls: &[BoxSpec], origin: [f64; 2], dx: f64, h: f64, fluid_centre: [f64; 2]) -> Vec<[f64; 2]> {
    let mut points: BTreeSet<(i64, i64)> = BTreeSet::new();
    for wall in walls {
        let (lo, hi) = filled_box(wall, dx, h, fluid_centre);
        let tol = 1e-9 * dx;
        let first = [0, 1].map(|k| ((lo[k] - origin[k]) / dx - 0.5 - 1e-9).ceil() as i64);
        let last = [0, 1].map(|k| ((hi[k] - origin[k]) / dx - 0.5 + 1e-9).floor() as i64);
        for iy in first[1]..=last[1] {
            for ix in first[0]..=last[0] {
                let p = lattice_point(origin, dx, ix, iy);
                if (0..2).all(|k| p[k] >= lo[k] - tol && p[k] <= hi[k] + tol) {
                    points.insert((iy, ix));
                }
            }
        }
    }
    points
        .into_iter()
        .map(|(iy, ix)| lattice_point(origin, dx, ix, iy))
        .collect()
}

fn lattice_point(origin: [f64; 2], dx: f64, ix: i64, iy: i64) -> [f64; 2] {
    [origin[0] + (ix as f64 + 0.5) * dx, origin[1] + (iy as f64 + 0.5) * dx]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thin_floor_grows_downwards_to_three_layers() {
        let floor = BoxSpec {
            min: [0.0, -0.01],
            max: [0.1, 0.0],
        };
        let pts = wall_positions(&[floor], [0.0, 0.0], 0.01, 0.013, [0.05, 0.2]);
        assert_eq!(pts.len(), 30);
        assert!(pts.iter().all(|p| p[1] < 0.0 && p[1] > -0.031));
    }
}
