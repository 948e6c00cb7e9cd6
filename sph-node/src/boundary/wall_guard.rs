//! Fluid particles found inside a rigid wall are put back on its face (coupled runs).
//!
//! The PPE cannot hold a fluid particle inside a wall: its neighbours are wall particles only, whose rows
//! (Adami et al. 2012, Eq. (27)) extrapolate from that particle alone, so the group has no Dirichlet row and is
//! singular, and nothing pushes the particle out (the wall pressures extrapolated from it carry only the hydrostatic
//! term ρ g Δx, less than its weight): it sinks through the wall and leaves the domain. In a coupled run the
//! broker's contact puts particles there: a structure face that lies on a wall (the lower face of the elastic
//! obstacle, clamped to the floor; the gate's tip, resting on the floor when the run starts) pushes the particles
//! that pass next to it by up to r_c + the penetration into the floor (`DESIGN.md` §4.5: the contact does not
//! know the SPH walls).
//!
//! Each wall box (grown as the wall particles fill it, [`crate::boundary::walls::wall_positions`]) is a rigid
//! obstacle: a fluid particle strictly inside one is moved to the nearest face through which it leaves every box, and
//! the part of its velocity into that face is removed (a perfectly plastic normal impact, as the particle–element
//! contact does). Particles outside the walls are never touched, so a run without contact is unchanged unless a
//! particle enters a wall.

use cosim_proto::scene::BoxSpec;
use serde::{Deserialize, Serialize};

use crate::boundary::walls::filled_box;

/// The wall boxes of a scene.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct WallBoxes {
    boxes: Vec<([f64; 2], [f64; 2])>,
    /// A particle put back goes this far out of the face (a millionth of Δx), so that it is outside every box.
    margin: f64,
}

impl WallBoxes {
    /// The boxes of `walls`, each grown away from the fluid to the layers its particles fill (as
    /// [`crate::boundary::walls::wall_positions`] does for a box thinner than the kernel support).
    pub fn new(walls: &[BoxSpec], dx: f64, h: f64, fluid_centre: [f64; 2]) -> Self {
        let boxes = walls.iter().map(|w| filled_box(w, dx, h, fluid_centre)).collect();
        Self {
            boxes,
            margin: 1e-6 * dx,
        }
    }

    /// The boxes, (lower, upper) corner each.
    pub fn boxes(&self) -> &[([f64; 2], [f64; 2])] {
        &self.boxes
    }

    /// Whether `x` is strictly inside a box.
    fn inside(&self, x: [f64; 2]) -> bool {
        self.boxes
            .iter()
            .any(|(lo, hi)| (0..2).all(|k| x[k] > lo[k] && x[k] < hi[k]))
    }

    /// The unit direction from `x` to the nearest point outside every box (the normal of the wall face nearest to a
    /// point inside a wall; diagonal in a corner where boxes meet); `None` outside the walls.
    pub fn exit_direction(&self, x: [f64; 2]) -> Option<[f64; 2]> {
        let (mut y, mut v) = (x, [0.0; 2]);
        if !self.push_out(&mut y, &mut v) {
            return None;
        }
        let d = [y[0] - x[0], y[1] - x[1]];
        let n = d[0].hypot(d[1]);
        (n > 0.0).then(|| [d[0] / n, d[1] / n])
    }

    /// The distance from `x` to the nearest point outside every box (how deep a wall particle sits behind the face;
    /// 0 outside the walls).
    pub fn depth(&self, x: [f64; 2]) -> f64 {
        let (mut y, mut v) = (x, [0.0; 2]);
        if !self.push_out(&mut y, &mut v) {
            return 0.0;
        }
        (y[0] - x[0]).hypot(y[1] - x[1])
    }

    /// The displacement `d` of a particle at `x` (outside the walls), with the part that would take it nearer than
    /// `gap` to a wall box taken off along the box's normal (from its nearest point to `x`), box by box: a particle
    /// already nearer keeps no motion towards that box; motion along or away from the faces is kept.
    pub fn hold_off(&self, x: [f64; 2], mut d: [f64; 2], gap: f64) -> [f64; 2] {
        for (lo, hi) in &self.boxes {
            let c = [x[0].clamp(lo[0], hi[0]), x[1].clamp(lo[1], hi[1])];
            let r = [x[0] - c[0], x[1] - c[1]];
            let dist = r[0].hypot(r[1]);
            if dist <= 0.0 || dist >= gap + d[0].hypot(d[1]) {
                continue;
            }
            let n = [r[0] / dist, r[1] / dist];
            let towards = -(d[0] * n[0] + d[1] * n[1]);
            let allowed = (dist - gap).max(0.0);
            if towards > allowed {
                let cut = towards - allowed;
                d = [d[0] + cut * n[0], d[1] + cut * n[1]];
            }
        }
        d
    }

    /// Moves a particle strictly inside a wall box to the nearest point outside every box whose coordinates are
    /// its own or those of box faces (just outside them: a face, or a corner where boxes meet), and removes the
    /// part of its velocity into the wall along each coordinate that changed. Returns whether it was moved.
    pub fn push_out(&self, x: &mut [f64; 2], v: &mut [f64; 2]) -> bool {
        if !self.inside(*x) {
            return false;
        }
        let d = self.margin;
        let coords =
            |k: usize| std::iter::once(x[k]).chain(self.boxes.iter().flat_map(move |(lo, hi)| [lo[k] - d, hi[k] + d]));
        let mut best: Option<(f64, [f64; 2])> = None;
        for cx in coords(0) {
            for cy in coords(1) {
                let y = [cx, cy];
                let dist = (cx - x[0]).hypot(cy - x[1]);
                if best.is_none_or(|(b, _)| dist < b) && !self.inside(y) {
                    best = Some((dist, y));
                }
            }
        }
        let Some((_, y)) = best else {
            return false; // cannot happen: the corner beyond every box is outside them all
        };
        for k in 0..2 {
            let out = y[k] - x[k];
            if out != 0.0 && v[k] * out < 0.0 {
                v[k] = 0.0;
            }
        }
        *x = y;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tank() -> WallBoxes {
        let b = |min, max| BoxSpec { min, max };
        WallBoxes::new(
            &[b([-0.012, -0.012], [0.5, 0.0]), b([-0.012, 0.0], [0.0, 0.3])],
            0.004,
            0.0052,
            [0.1, 0.1],
        )
    }

    #[test]
    fn particles_outside_are_untouched() {
        let w = tank();
        for p in [[0.1, 0.002], [0.001, 0.1], [0.0, 0.0], [0.2, 0.0]] {
            let (mut x, mut v) = (p, [1.0, -1.0]);
            assert!(!w.push_out(&mut x, &mut v));
            assert_eq!((x, v), (p, [1.0, -1.0]));
        }
    }

    #[test]
    fn a_particle_in_the_floor_goes_back_up() {
        let w = tank();
        let (mut x, mut v) = ([0.2, -0.002], [2.0, -0.5]);
        assert!(w.push_out(&mut x, &mut v));
        assert!((x[0] - 0.2).abs() < 1e-15 && x[1] > 0.0 && x[1] < 1e-8, "{x:?}");
        assert_eq!(v, [2.0, 0.0]);
    }

    #[test]
    fn a_shift_stops_at_the_gap_and_keeps_its_tangential_part() {
        let w = tank();
        let gap = 0.002;
        // 3 mm above the floor, shifted 2 mm down and 1 mm along: it stops 2 mm above the floor.
        let d = w.hold_off([0.2, 0.003], [0.001, -0.002], gap);
        assert!((d[0] - 0.001).abs() < 1e-15 && (d[1] + 0.001).abs() < 1e-15, "{d:?}");
        // Already nearer than the gap: no motion towards the floor, away from it unchanged.
        assert_eq!(w.hold_off([0.2, 0.001], [0.0005, -0.0001], gap), [0.0005, 0.0]);
        assert_eq!(w.hold_off([0.2, 0.001], [0.0005, 0.0001], gap), [0.0005, 0.0001]);
        // Far from every box: unchanged.
        assert_eq!(w.hold_off([0.2, 0.1], [0.0, -0.001], gap), [0.0, -0.001]);
        // In the corner, against both walls.
        let d = w.hold_off([0.001, 0.001], [-0.001, -0.001], gap);
        assert!(d[0].abs() < 1e-18 && d[1].abs() < 1e-18, "{d:?}");
    }

    #[test]
    fn a_particle_in_the_corner_leaves_both_walls() {
        let w = tank();
        let (mut x, mut v) = ([-0.001, -0.0015], [-1.0, -1.0]);
        assert!(w.push_out(&mut x, &mut v));
        assert!(!w.inside(x), "{x:?}");
        assert!(x[0] > 0.0 && x[1] > 0.0 && x[0] < 1e-8 && x[1] < 1e-8, "{x:?}");
        assert_eq!(v, [0.0, 0.0]);
    }
}
