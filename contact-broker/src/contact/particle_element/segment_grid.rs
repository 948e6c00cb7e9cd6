//! The segments binned in cells for the candidate search, and when moving masters have made it stale.
//!
//! A segment is binned with its box inflated by `inflate` (twice the detection reach), at the node positions of the
//! build. While the masters move in the position phase (`move_masters`), a node may travel farther than that margin
//! within one pass: a light node pressed by several particles can be pushed several spacings. The segment then
//! covers particles in cells it was never binned in, whose visits never gather it: they stay inside it uncorrected,
//! and the touching set misses them too. So the grid keeps the node positions it was built at, and the position
//! phase rebuilds it when a node has moved more than half the reach since ([`SegmentGrid::stale`]).

use crate::contact::bodies::Segment;
use crate::contact::geometry::{sub, Vec2};
use crate::contact::grid::CellGrid;

/// The cell grid of the segments and the node positions it was built at.
#[derive(Clone, Debug, Default)]
pub(super) struct SegmentGrid {
    /// The segments in cells, their boxes inflated by `inflate`.
    pub cells: CellGrid,
    /// The node positions of the build (kept only where the nodes may move in the pass: `track`).
    built_at: Vec<Vec2>,
    /// How far each segment's box is inflated.
    inflate: f64,
}

impl SegmentGrid {
    /// Bins `segments` at node positions `x`, each box inflated by `inflate`, in cells no smaller than `inflate`
    /// or the mean segment length; keeps `x` when `track` (the nodes may move before the pass ends).
    pub fn build(&mut self, x: &[Vec2], segments: &[Segment], inflate: f64, track: bool) {
        let mean_len = segments.iter().map(|s| dist(x[s.a], x[s.b])).sum::<f64>() / segments.len() as f64;
        self.cells.build(segments.len(), inflate.max(mean_len), |j| {
            let (a, b) = (x[segments[j].a], x[segments[j].b]);
            let lo = [a[0].min(b[0]) - inflate, a[1].min(b[1]) - inflate];
            let hi = [a[0].max(b[0]) + inflate, a[1].max(b[1]) + inflate];
            (lo, hi)
        });
        self.inflate = inflate;
        self.built_at.clear();
        if track {
            self.built_at.extend_from_slice(x);
        }
    }

    /// Whether a node at `x` has moved more than half the inflation since the build (tracked builds only): the
    /// particles within the detection reach of its segments (at most half the inflation: r_c or d_max) may then
    /// lie outside the cells it was binned in. The position phase asks after each sweep and, where it is, sweeps
    /// once more on a new grid: a node that moved within a sweep may have passed particles visited before.
    pub fn stale(&self, x: &[Vec2]) -> bool {
        let limit2 = 0.25 * self.inflate * self.inflate;
        self.built_at.iter().zip(x).any(|(a, b)| {
            let d = sub(*b, *a);
            // NaN is not stale: a NaN node is refused before any pass (`bodies::validate`).
            d[0] * d[0] + d[1] * d[1] > limit2
        })
    }

    /// Bins the segments again at node positions `x`, with the inflation of the last build, still tracking.
    pub fn rebuild(&mut self, x: &[Vec2], segments: &[Segment]) {
        self.build(x, segments, self.inflate, true);
    }
}

/// |a − b| (`hypot`: the mean segment length that sizes the grid).
#[inline]
pub(super) fn dist(a: Vec2, b: Vec2) -> f64 {
    let d = sub(a, b);
    d[0].hypot(d[1])
}
