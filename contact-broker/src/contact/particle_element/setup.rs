//! The set-up of one particle–element pass: the nodes' inverse masses, the segment grid, the tolerances, which
//! nodes the position phase may move, and the detection context every phase shares; and what the pass knows about
//! each particle ([`Mark`]).

use std::borrow::Cow;

use super::detection::{Detector, Master, Topology};
use super::params::ContactParams;
use super::segment_grid::SegmentGrid;
use crate::contact::bodies::{Nodes, Segment};
use crate::contact::geometry::{Frame, Vec2};

/// What the pass knows about one particle: whether it was corrected, and what its position-phase visits learnt,
/// for the skips that hold while the nodes are static.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Mark {
    /// Its position or velocity was changed.
    pub corrected: bool,
    /// Its last position-phase visit left it where it was (no master penetrated at its position).
    pub still: bool,
    /// Its first-sweep visit found no master within the touch gap at its position.
    pub clear: bool,
    /// Its memo ([`Memo`](super::memo::Memo)): the gaps its last position-phase visit ended with.
    pub memo: Option<u32>,
}

/// What a pass computes once when its nodes are static (`Setup::nodes_static`) instead of at each detection: the
/// frame of every segment, which nodes may act as masters at all (`Detector::node_may_act`), and each grid item's
/// segment box. Scratch.
#[derive(Clone, Debug, Default)]
pub(super) struct StaticGeometry {
    frames: Vec<Option<Frame>>,
    node_acts: Vec<bool>,
    /// The box of the segment of each entry of the grid's items, in their order (cell after cell), not inflated:
    /// [x min, x max, y min, y max], so a gather reads its cell's boxes in one run instead of each segment's nodes.
    boxes: Vec<[f64; 4]>,
}

/// The context of one pass, fixed for its whole length (node positions are not in it: they change in the position
/// phase).
pub(super) struct Setup<'a> {
    pub params: ContactParams,
    pub segments: &'a [Segment],
    topo: &'a Topology,
    grid: &'a mut SegmentGrid,
    /// 1/m per node, 0 for a fixed node.
    pub inv_m: &'a [f64],
    /// The fixed nodes (infinite mass).
    pub fixed: &'a [bool],
    /// The nodes the position phase leaves in place: the fixed ones, or all of them when the masters are held
    /// (`move_masters` off).
    pub pos_fixed: Cow<'a, [bool]>,
    /// Every master immovable in the position phase, and no test asked for exhaustive visits: see
    /// [`position::phase`](super::position::phase).
    pub nodes_static: bool,
    /// How far a segment's box is inflated for the candidate search.
    inflate: f64,
    /// How far for [`Setup::gather_near`] (at most `inflate`).
    inflate_near: f64,
    /// Convergence tolerance of the position phase [m].
    pub tol_x: f64,
    /// Round-off allowance of the exact rigid projection [m] (16 ulp of the coordinates).
    pub tol_round: f64,
    /// Contacts within this gap after the position phase get the velocity correction [m].
    pub touch: f64,
    min_len: f64,
    /// Frames and acting nodes, computed once while the nodes are static.
    statics: Option<&'a StaticGeometry>,
}

impl<'a> Setup<'a> {
    /// Builds the node → segment tables, the inverse masses and the segment grid into the workspace's arrays and
    /// derives the tolerances from `params` and the node coordinates; with static nodes, also `statics`.
    /// `segments` is not empty.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        grid: &'a mut SegmentGrid,
        topo: &'a mut Topology,
        inv_m: &'a mut Vec<f64>,
        statics: &'a mut StaticGeometry,
        nodes: &Nodes<'a>,
        segments: &'a [Segment],
        params: &ContactParams,
        exhaustive: bool,
    ) -> Self {
        let nn = nodes.x.len();
        let fixed = nodes.fixed;
        topo.build(nn, segments);
        inv_m.clear();
        inv_m.extend((0..nn).map(|k| if fixed[k] { 0.0 } else { 1.0 / nodes.m[k] }));

        // Segments are binned with their boxes inflated by twice the detection reach, so that a particle's
        // candidate list also covers the places an exact rigid projection may move it to.
        let (r_c, d_max) = (params.thickness, params.far_side);
        let inflate = 2.0 * r_c.max(d_max);
        // Tracked where the masters may move in the position phase (`segment_grid.rs`).
        grid.build(nodes.x, segments, inflate, params.move_masters);
        let coord = nodes.x.iter().fold(0.0f64, |c, x| c.max(x[0].abs()).max(x[1].abs()));
        // Convergence tolerance, and the round-off allowance of the exact rigid projection (16 ulp of the
        // coordinates).
        let tol_x = params.tolerance * r_c;
        let tol_round = 1e-12 * r_c + 16.0 * f64::EPSILON * coord;
        // Contacts within this gap after the position phase get the velocity correction (never below round-off).
        let touch = tol_x.max(tol_round);

        // Masters held in place (`move_masters` off) are immovable in the position phase: the exact rigid
        // projection.
        let pos_fixed = if params.move_masters {
            Cow::Borrowed(fixed)
        } else {
            Cow::Owned(vec![true; nn])
        };
        let nodes_static = !exhaustive && pos_fixed.iter().all(|&f| f);
        let min_len = 1e-12 * r_c;
        let topo = &*topo;
        let det = Detector {
            x: nodes.x,
            segments,
            topo,
            thickness: params.thickness,
            far_side: params.far_side,
            min_len,
            reach: touch,
            frames: None,
        };
        // The detection zone, with r_c more as a margin far above round-off (as `Detector::detect`'s own).
        let inflate_near = (det.zone() + r_c).min(inflate);
        let statics = nodes_static.then(|| {
            det.frames_into(&mut statics.frames);
            statics.node_acts.clear();
            statics.node_acts.extend((0..nn).map(|k| det.node_may_act(k)));
            statics.boxes.clear();
            statics.boxes.extend(grid.cells.items().iter().map(|&j| {
                let s = segments[j as usize];
                let (a, b) = (nodes.x[s.a], nodes.x[s.b]);
                [a[0].min(b[0]), a[0].max(b[0]), a[1].min(b[1]), a[1].max(b[1])]
            }));
            &*statics
        });
        Setup {
            params: *params,
            segments,
            topo,
            grid,
            inv_m,
            fixed,
            pos_fixed,
            nodes_static,
            inflate,
            inflate_near,
            tol_x,
            tol_round,
            touch,
            min_len,
            statics,
        }
    }

    /// Bins the segments again at node positions `x` when the masters have moved more than the grid allows for
    /// ([`SegmentGrid::stale`]); whether it did. Never with static nodes (nothing moves).
    pub fn regrid_if_stale(&mut self, x: &[Vec2]) -> bool {
        if self.nodes_static || !self.grid.stale(x) {
            return false;
        }
        self.grid.rebuild(x, self.segments);
        true
    }

    /// The detector at node positions `x`.
    pub fn detector<'b>(&'b self, x: &'b [Vec2]) -> Detector<'b> {
        Detector {
            x,
            segments: self.segments,
            topo: self.topo,
            thickness: self.params.thickness,
            far_side: self.params.far_side,
            min_len: self.min_len,
            // The touch gap: no caller of `detect` here acts on a larger gap.
            reach: self.touch,
            frames: self.statics.map(|g| &g.frames[..]),
        }
    }

    /// The masters near `xs` (node positions `x`), in a fixed order: those of the segments in its grid cell whose
    /// box, inflated by `inflate`, holds `xs` (a node master lies within its owning segment's box); with static
    /// nodes, not the nodes that act nowhere.
    pub fn gather(&self, x: &[Vec2], xs: Vec2, out: &mut Vec<Master>) {
        self.gather_within(x, xs, self.inflate, out);
    }

    /// The masters of [`Setup::gather`] whose detection at `xs` may find a contact, with others: those of the
    /// segments whose box inflated by the detection zone (plus r_c for round-off) holds `xs`. Any master
    /// [`Setup::gather`] lists beyond it finds no contact at `xs` (`Detector::zone`).
    pub fn gather_near(&self, x: &[Vec2], xs: Vec2, out: &mut Vec<Master>) {
        self.gather_within(x, xs, self.inflate_near, out);
    }

    fn gather_within(&self, x: &[Vec2], xs: Vec2, inflate: f64, out: &mut Vec<Master>) {
        out.clear();
        if let Some(g) = self.statics {
            // Static nodes: the boxes of the grid's build, read in the cell's order; the same comparisons of the
            // same numbers as below, so the same masters.
            let range = self.grid.cells.query_range(xs);
            let (items, boxes) = (&self.grid.cells.items()[range.clone()], &g.boxes[range]);
            for (&j, bx) in items.iter().zip(boxes) {
                let outside = xs[0] < bx[0] - inflate
                    || xs[0] > bx[1] + inflate
                    || xs[1] < bx[2] - inflate
                    || xs[1] > bx[3] + inflate;
                if !outside {
                    let s = self.segments[j as usize];
                    // A node that acts nowhere (concave or straight corner) finds no contact: leaving it out
                    // changes nothing.
                    self.topo.masters_near(j as usize, s, Some(&g.node_acts), out);
                }
            }
            return;
        }
        for &j in self.grid.cells.query(xs) {
            let s = self.segments[j as usize];
            let (a, b) = (x[s.a], x[s.b]);
            let outside = |k: usize| xs[k] < a[k].min(b[k]) - inflate || xs[k] > a[k].max(b[k]) + inflate;
            if !(outside(0) || outside(1)) {
                self.topo.masters_near(j as usize, s, None, out);
            }
        }
    }
}
