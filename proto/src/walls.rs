//! The tank's walls as the structure meets them: their boxes, how deep a point lies in them, the nearest way out,
//! and which structure nodes they stop.
//!
//! The walls (`[[wall]]`) are the fluid's boundary particles; the structure solver knows them from the scene. A
//! node that a step takes into a wall is put back on the nearest point of the walls' surface and loses the
//! velocity component into it: a frictionless, perfectly inelastic contact with an immovable body, the one the
//! particle–element contact applies to a particle against a fixed master (`DESIGN.md` §4.5), here with the wall as
//! the master. fem-node applies it after every sub-step's drift (`fem-node/src/solver/central_difference.rs`), and
//! the broker once more after each contact pass for what the pass moved (`contact-broker/src/wall_contact.rs`): the
//! same rule, from this module.
//!
//! Not stopped: a node inside a wall where the scene put it (a clamped end's neighbours), and a node of a clamped
//! solid within half a fluid spacing of a wall where the scene put it. The shipped gate hangs from its wall with its
//! free end on the floor's face, and dipped up to 3.6 µm into it; stopping that end there (the floor a frictionless
//! prop under the tip) made energy: at Δx = 4 mm to 0.05 s, 0.137 of the water's releasable energy against 0.0004
//! without (2026-12-07, thirty-third session, when the broker stopped the nodes once a coupling step). Stopped inside
//! the sub-steps (2026-12-08) that WCSPH case makes nothing (0.00035), but the exception stays: the ISPH gate at
//! `coupling.max_dt` 1e-4 with `structure_courant` 0 and the gate at 1e20 kg/m³ made energy with the end stopped
//! (0.108 of the budget, against under 0.1 spared; 872,311 budgets against a rounding of 24), which
//! `cosim/tests/stress/energy_balance.rs` catches.

use crate::scene::Scene;

/// A wall's box, (lower corner, upper corner).
pub type WallBox = ([f64; 2], [f64; 2]);

/// The scene's walls as boxes, in its order (`wall[k]`).
pub fn wall_boxes(scene: &Scene) -> Vec<WallBox> {
    scene.walls.iter().map(|w| (w.min, w.max)).collect()
}

/// How far `p` lies inside the box `lo`–`hi` (0 on its boundary, negative outside).
pub fn depth(p: [f64; 2], (lo, hi): WallBox) -> f64 {
    (p[0] - lo[0]).min(hi[0] - p[0]).min(p[1] - lo[1]).min(hi[1] - p[1])
}

/// The largest [`depth`] of `p` in any of `walls` (−∞ without walls).
pub fn deepest(p: [f64; 2], walls: &[WallBox]) -> f64 {
    walls.iter().map(|&w| depth(p, w)).fold(f64::NEG_INFINITY, f64::max)
}

/// The nearest point to `p` on the boundary of the union of the `walls` when `p` lies in one of them (their closed
/// boxes), `None` outside them or on that boundary. Walls may touch or overlap (a floor and a side wall meet in a
/// corner), so a box's face may lie inside the union: the candidates are `p` projected on every face of every box
/// and every box's corners, and one counts only where a point a hair away from it, along an axis or a diagonal,
/// lies outside every wall. Ties go to the first candidate (boxes in the scene's order, faces −x, +x, −y, +y, then
/// the corners).
fn exit_point(p: [f64; 2], walls: &[WallBox], hair: f64) -> Option<[f64; 2]> {
    if walls.iter().all(|&w| depth(p, w) < 0.0) {
        return None;
    }
    let outside = |q: [f64; 2]| walls.iter().all(|&w| depth(q, w) < 0.0);
    let on_boundary = |c: [f64; 2]| {
        [
            [1.0, 0.0],
            [-1.0, 0.0],
            [0.0, 1.0],
            [0.0, -1.0],
            [1.0, 1.0],
            [1.0, -1.0],
            [-1.0, 1.0],
            [-1.0, -1.0],
        ]
        .iter()
        .any(|d: &[f64; 2]| outside([c[0] + hair * d[0], c[1] + hair * d[1]]))
    };
    let mut best: Option<([f64; 2], f64)> = None;
    for &(lo, hi) in walls {
        let (cx, cy) = (p[0].clamp(lo[0], hi[0]), p[1].clamp(lo[1], hi[1]));
        let candidates = [
            [lo[0], cy],
            [hi[0], cy],
            [cx, lo[1]],
            [cx, hi[1]],
            lo,
            [hi[0], lo[1]],
            [lo[0], hi[1]],
            hi,
        ];
        for c in candidates {
            let d2 = (c[0] - p[0]).powi(2) + (c[1] - p[1]).powi(2);
            if best.is_none_or(|(_, b)| d2 < b) && on_boundary(c) {
                best = Some((c, d2));
            }
        }
    }
    best.filter(|&(_, d2)| d2 > 0.0).map(|(c, _)| c)
}

/// The scene's walls as the structure meets them.
#[derive(Clone, Debug, PartialEq)]
pub struct Walls {
    boxes: Vec<WallBox>,
    /// The fluid's spacing [m] (a clamped solid's node within half of it from a wall is not stopped).
    spacing: f64,
    /// How far from a candidate exit point the union's outside is looked for [m].
    hair: f64,
}

impl Walls {
    /// The walls of `scene`; `None` without a fluid (the walls are its boundary) or without walls.
    pub fn new(scene: &Scene) -> Option<Self> {
        let spacing = scene.fluid.as_ref()?.spacing;
        if scene.walls.is_empty() {
            return None;
        }
        let boxes = wall_boxes(scene);
        // A hair: far below any wall's size, far above the coordinates' round-off.
        let scale = boxes.iter().fold(1.0f64, |m, (lo, hi)| {
            m.max(lo[0].abs()).max(lo[1].abs()).max(hi[0].abs()).max(hi[1].abs())
        });
        Some(Self {
            boxes,
            spacing,
            hair: 1e-9 * scale,
        })
    }

    /// The boxes, in the scene's order.
    pub fn boxes(&self) -> &[WallBox] {
        &self.boxes
    }

    /// Per node of a mesh at its `reference` positions (clamped where `fixed`, of solid `node_solid`): whether the
    /// walls stop it (the module docs: not clamped, not inside a wall, and not a clamped solid's node within half a
    /// spacing of one). Entries past the shorter of the slices are not stopped.
    pub fn stopped(&self, reference: &[[f64; 2]], fixed: &[bool], node_solid: &[u32]) -> Vec<bool> {
        let solids = node_solid.iter().map(|&s| s as usize + 1).max().unwrap_or(0);
        let mut held = vec![false; solids];
        for (&f, &s) in fixed.iter().zip(node_solid) {
            if f {
                held[s as usize] = true;
            }
        }
        (0..reference.len())
            .map(|k| {
                let (Some(&p), Some(&f), Some(&s)) = (reference.get(k), fixed.get(k), node_solid.get(k)) else {
                    return false;
                };
                let deepest = deepest(p, &self.boxes);
                !f && deepest <= 0.0 && !(held[s as usize] && deepest >= -0.5 * self.spacing)
            })
            .collect()
    }

    /// The correction `(dx, dv)` that puts a node at `p` moving at `u` back out of the walls: to the nearest point
    /// of their surface, the velocity into the walls (against that way out) taken off; `None` where `p` is not
    /// inside a wall (on its surface or outside).
    pub fn stop(&self, p: [f64; 2], u: [f64; 2]) -> Option<([f64; 2], [f64; 2])> {
        let c = exit_point(p, &self.boxes, self.hair)?;
        let dx = [c[0] - p[0], c[1] - p[1]];
        let len = dx[0].hypot(dx[1]);
        let n = [dx[0] / len, dx[1] / len];
        let into = (u[0] * n[0] + u[1] * n[1]).min(0.0);
        Some((dx, [-into * n[0], -into * n[1]]))
    }
}
