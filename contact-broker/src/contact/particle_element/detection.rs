//! Contact detection (`DESIGN.md` §4.5): which master a slave particle touches — a boundary segment, or a boundary
//! node at a convex corner or at the free end of an open chain — and the geometry of that contact.

use crate::contact::bodies::Segment;
use crate::contact::geometry::{add, cross, dot, norm, normalize, scale, sub, xi, Frame, Vec2};

/// "No segment" in the node → segment tables.
const NONE: u32 = u32::MAX;

/// A master: a boundary segment, or a boundary node acting on its own (convex corner, chain end).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Master {
    Segment(u32),
    Node(u32),
}

/// Geometry of one particle–master contact. The master point is x_c = na·x_a + nb·x_b (a node contact has
/// a = b, na = 1, nb = 0), `n` is the unit normal pointing from the master into the fluid and `g` the gap
/// (negative: penetration).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Hit {
    pub a: usize,
    pub b: usize,
    pub na: f64,
    pub nb: f64,
    pub n: Vec2,
    pub g: f64,
}

/// The boundary of a master's exclusion zone, used by the exact projection on immovable masters: the line
/// n·x = c at distance r_c from a segment, or the circle of radius r_c around a node.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Shape {
    Line { n: Vec2, c: f64 },
    Circle { centre: Vec2, r: f64, fallback: Vec2 },
}

/// Node → segment adjacency: for each node the first segment (by index) ending at it and the first starting at it.
/// A node where more than two segments meet uses those two for its corner test.
#[derive(Clone, Debug, Default)]
pub(crate) struct Topology {
    prev: Vec<u32>,
    next: Vec<u32>,
}

impl Topology {
    /// Rebuilds the tables (segments are validated by the caller).
    pub fn build(&mut self, nodes: usize, segments: &[Segment]) {
        self.prev.clear();
        self.prev.resize(nodes, NONE);
        self.next.clear();
        self.next.resize(nodes, NONE);
        for (j, s) in segments.iter().enumerate() {
            if self.prev[s.b] == NONE {
                self.prev[s.b] = j as u32;
            }
            if self.next[s.a] == NONE {
                self.next[s.a] = j as u32;
            }
        }
    }

    /// Appends the masters a particle near segment `j` may touch, in a fixed order: the segment, then the node it
    /// ends at (owned by this segment when it is that node's first incoming segment), then the node it starts at
    /// when that node starts an open chain. Each node master is thus listed under exactly one segment.
    ///
    /// With `acts` (per node, `Detector::node_may_act`), a node that acts nowhere is left out: it would find no
    /// contact wherever the particle is.
    pub fn masters_near(&self, j: usize, s: Segment, acts: Option<&[bool]>, out: &mut Vec<Master>) {
        let acting = |k: usize| acts.is_none_or(|a| a[k]);
        out.push(Master::Segment(j as u32));
        if self.prev[s.b] == j as u32 && acting(s.b) {
            out.push(Master::Node(s.b as u32));
        }
        if self.prev[s.a] == NONE && self.next[s.a] == j as u32 && acting(s.a) {
            out.push(Master::Node(s.a as u32));
        }
    }
}

/// Everything detection needs: current node positions, the boundary and the contact parameters.
pub(crate) struct Detector<'a> {
    pub x: &'a [Vec2],
    pub segments: &'a [Segment],
    pub topo: &'a Topology,
    /// Contact thickness r_c [m].
    pub thickness: f64,
    /// Far-side limit d_max [m].
    pub far_side: f64,
    /// Segments shorter than this are skipped (a collapsed element has no normal).
    pub min_len: f64,
    /// The largest gap g any caller acts on (the touch gap of the velocity phase; `f64::INFINITY` for every
    /// contact): [`Detector::detect`] may answer `None` for a master whose gap is certainly above it.
    pub reach: f64,
    /// The frame of every segment at `x` (`Frame::new` of its nodes, `None` for a collapsed one), when the caller
    /// computed them once for nodes that do not move; `None`: computed at each use.
    pub frames: Option<&'a [Option<Frame>]>,
}

impl Detector<'_> {
    fn frame(&self, j: u32) -> Option<Frame> {
        if let Some(frames) = self.frames {
            return frames[j as usize];
        }
        let s = self.segments[j as usize];
        Frame::new(self.x[s.a], self.x[s.b], self.min_len)
    }

    /// Fills `out` with the frame of every segment at these node positions (what [`Detector::frames`] holds).
    pub fn frames_into(&self, out: &mut Vec<Option<Frame>>) {
        out.clear();
        out.extend(
            self.segments
                .iter()
                .map(|s| Frame::new(self.x[s.a], self.x[s.b], self.min_len)),
        );
    }

    /// Whether node `k` may act as a master at these node positions: `false` at a concave or straight corner,
    /// where [`Detector::detect`] finds no contact wherever the particle is (its corner test, which depends on the
    /// nodes only).
    pub fn node_may_act(&self, k: usize) -> bool {
        let (p, q) = (self.topo.prev[k], self.topo.next[k]);
        !(p != NONE && q != NONE && cross(self.delta(p), self.delta(q)) <= 0.0)
    }

    /// Whether the master cannot move (all its nodes fixed: infinite mass, 1/m = 0).
    pub fn is_rigid(&self, m: Master, fixed: &[bool]) -> bool {
        match m {
            Master::Segment(j) => {
                let s = self.segments[j as usize];
                fixed[s.a] && fixed[s.b]
            }
            Master::Node(k) => fixed[k as usize],
        }
    }

    /// The detection zone: [`Detector::detect`] finds no contact for a particle farther than this from a segment
    /// (beyond `far` on the fluid side, `back` behind it, or outside its ξ range) or from a node master.
    pub fn zone(&self) -> f64 {
        let (far, back) = self.reaches();
        far.max(back)
    }

    /// `far` and `back` of [`Detector::detect`]: twice the largest distance a caller looks at on the fluid side
    /// (far above any round-off between detect's tests and `attach`), and the far-side limit plus r_c behind.
    #[inline]
    fn reaches(&self) -> (f64, f64) {
        (2.0 * (self.thickness + self.reach), self.far_side + self.thickness)
    }

    /// The contact geometry of particle position `xs` with master `m` when `xs` lies in the master's detection
    /// zone (any gap; the caller tests `g`), else `None`. Same result as [`Detector::attach`] filtered on its flag,
    /// with the cheap rejections (ξ range, corner wedge) done before any square root.
    ///
    /// A master whose gap is certainly above [`Detector::reach`] is `None` too, found without a square root: a
    /// particle among the masters gathered near it is mostly several spacings from all but one or two of them, and
    /// every caller ignores such a hit (they act on g < 0 or g ≤ reach only), so their results do not change.
    pub fn detect(&self, m: Master, xs: Vec2) -> Option<Hit> {
        let (far, back) = self.reaches();
        match m {
            Master::Segment(j) => {
                let s = self.segments[j as usize];
                let x1 = self.x[s.a];
                let d = sub(self.x[s.b], x1);
                // (x_s − x_c)·n · L = (x_s − x1) × d, n = (t_y, −t_x) (`Frame`): beyond `far` on the fluid side, or
                // beyond the far-side limit plus r_c (a margin as far above round-off as `far`'s) behind the
                // segment, where `attach` finds the particle outside (dn ≤ −d_max). Tested before ξ: no division,
                // and most masters gathered near a particle are rejected here (the far face of a thin structure).
                let dn_len = cross(sub(xs, x1), d);
                let reach2 = if dn_len > 0.0 { far * far } else { back * back };
                if dn_len * dn_len > reach2 * dot(d, d) {
                    return None;
                }
                if !(0.0..=1.0).contains(&xi(x1, d, xs)) {
                    return None;
                }
            }
            Master::Node(k) => {
                let k = k as usize;
                let (p, q) = (self.topo.prev[k], self.topo.next[k]);
                let r = sub(xs, self.x[k]);
                // g = |r| − r_c (`attach`): beyond `far` from the node.
                if dot(r, r) > far * far {
                    return None;
                }
                // ξ_P > 1 ⟺ r·d_P > 0 and ξ_Q < 0 ⟺ r·d_Q < 0 (d the unnormalised segment vectors).
                if p != NONE && dot(r, self.delta(p)) <= 0.0 || q != NONE && dot(r, self.delta(q)) >= 0.0 {
                    return None;
                }
                if p != NONE && q != NONE && cross(self.delta(p), self.delta(q)) <= 0.0 {
                    return None;
                }
            }
        }
        self.attach(m, xs).and_then(|(hit, inside)| inside.then_some(hit))
    }

    /// x_b − x_a of segment `j`.
    fn delta(&self, j: u32) -> Vec2 {
        let s = self.segments[j as usize];
        sub(self.x[s.b], self.x[s.a])
    }

    /// The contact geometry of `xs` with master `m` whether or not `xs` lies in its detection zone (`true` when it
    /// does). `None` only for a collapsed segment or a node that acts on its own nowhere (concave or straight
    /// corner, node of no segment).
    pub fn attach(&self, m: Master, xs: Vec2) -> Option<(Hit, bool)> {
        match m {
            Master::Segment(j) => {
                let s = self.segments[j as usize];
                let f = self.frame(j)?;
                // DESIGN.md §4.5 detection: ξ = (x_s − x1)·t/L, N1 = 1 − ξ, N2 = ξ, x_c = N1 x1 + N2 x2,
                // g = (x_s − x_c)·n − r_c (Long et al. 2016 after Johnson & Stryk 2001).
                let xi = f.xi(xs);
                let (na, nb) = (1.0 - xi, xi);
                let dn = dot(sub(xs, f.point(na, nb)), f.n);
                // Active if 0 ≤ ξ ≤ 1 and the particle is not beyond the far side, (x_s − x_c)·n > −d_max.
                let inside = (0.0..=1.0).contains(&xi) && dn > -self.far_side;
                let hit = Hit {
                    a: s.a,
                    b: s.b,
                    na,
                    nb,
                    n: f.n,
                    g: dn - self.thickness,
                };
                Some((hit, inside))
            }
            Master::Node(k) => {
                let k = k as usize;
                let (p, q) = (self.topo.prev[k], self.topo.next[k]);
                let r = sub(xs, self.x[k]);
                // Which side the node acts on, and the normal used if the particle sits exactly on the node.
                let (inside, fallback) = match (p != NONE, q != NONE) {
                    (true, true) => {
                        let (fp, fq) = (self.frame(p)?, self.frame(q)?);
                        // Convex corner (left turn of a counter-clockwise boundary): the wedge outside both
                        // segments' ξ ranges belongs to the node (DESIGN.md §4.5). Concave or straight: both
                        // segments act, no node contact.
                        if cross(fp.t, fq.t) <= 0.0 {
                            return None;
                        }
                        let inside = fp.xi(xs) > 1.0 && fq.xi(xs) < 0.0;
                        (inside, normalize(add(fp.n, fq.n)).unwrap_or(fp.n))
                    }
                    // Free end of an open chain: the half-disc beyond the end acts like a rounded cap.
                    (true, false) => {
                        let fp = self.frame(p)?;
                        (fp.xi(xs) > 1.0 && dot(r, fp.n) > -self.far_side, fp.t)
                    }
                    (false, true) => {
                        let fq = self.frame(q)?;
                        (fq.xi(xs) < 0.0 && dot(r, fq.n) > -self.far_side, scale(fq.t, -1.0))
                    }
                    (false, false) => return None,
                };
                // Convex corner: node contact with n = (x_s − x_node)/|x_s − x_node| (DESIGN.md §4.5).
                let dist = norm(r);
                let n = normalize(r).unwrap_or(fallback);
                let hit = Hit {
                    a: k,
                    b: k,
                    na: 1.0,
                    nb: 0.0,
                    n,
                    g: dist - self.thickness,
                };
                Some((hit, inside))
            }
        }
    }

    /// The boundary of the master's exclusion zone (see [`Shape`]).
    pub fn shape(&self, m: Master) -> Option<Shape> {
        match m {
            Master::Segment(j) => {
                let f = self.frame(j)?;
                Some(Shape::Line {
                    n: f.n,
                    c: dot(f.n, f.x1) + self.thickness,
                })
            }
            Master::Node(k) => {
                let (hit, _) = self.attach(m, self.x[k as usize])?;
                Some(Shape::Circle {
                    centre: self.x[k as usize],
                    r: self.thickness,
                    fallback: hit.n,
                })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit square [0,1]² as a counter-clockwise boundary: all four corners convex.
    fn square() -> (Vec<Vec2>, Vec<Segment>) {
        let x = vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let s = (0..4).map(|i| Segment { a: i, b: (i + 1) % 4 }).collect();
        (x, s)
    }

    #[test]
    fn segment_and_corner_detection() {
        let (x, s) = square();
        let mut topo = Topology::default();
        topo.build(4, &s);
        let det = Detector {
            x: &x,
            segments: &s,
            topo: &topo,
            thickness: 0.1,
            far_side: 0.3,
            min_len: 0.0,
            reach: f64::INFINITY,
            frames: None,
        };
        // Below the bottom edge (fluid side), 0.05 away: penetrates the 0.1 thickness by 0.05.
        let h = det.detect(Master::Segment(0), [0.25, -0.05]).unwrap();
        assert_eq!(h.n, [0.0, -1.0]);
        assert!((h.g + 0.05).abs() < 1e-15 && (h.na - 0.75).abs() < 1e-15);
        // Inside the structure but within the far side: still detected; beyond it: not.
        assert!(det.detect(Master::Segment(0), [0.5, 0.2]).is_some());
        assert!(det.detect(Master::Segment(0), [0.5, 0.4]).is_none());
        // Outside the ξ range of the bottom edge, in the convex corner's wedge at node 1.
        assert!(det.detect(Master::Segment(0), [1.05, -0.05]).is_none());
        let h = det.detect(Master::Node(1), [1.03, -0.04]).unwrap();
        assert!((h.g - (0.05 - 0.1)).abs() < 1e-15);
        assert!((h.n[0] - 0.6).abs() < 1e-15 && (h.n[1] + 0.8).abs() < 1e-15);
        // Node 1's wedge does not extend over the edges.
        assert!(det.detect(Master::Node(1), [0.95, -0.05]).is_none());
    }

    proptest::proptest! {
        /// The early rejection of far masters changes nothing a caller acts on: with a finite `reach` every master
        /// gives the same hit, to the bit, as without one whenever that hit's gap is at most `reach`, and is `None`
        /// only where the full detection finds no hit or one beyond `reach`.
        #[test]
        fn far_masters_are_dropped_only_beyond_reach(
            px in -0.6f64..1.6, py in -0.6f64..1.6, reach in 0.0f64..0.2, tilt in -0.3f64..0.3,
        ) {
            // A skewed quadrilateral, so that no test point sits on a symmetry line.
            let x = vec![[0.0, 0.0], [1.0, tilt], [1.0 + tilt, 1.0], [tilt, 1.0 - tilt]];
            let s: Vec<Segment> = (0..4).map(|i| Segment { a: i, b: (i + 1) % 4 }).collect();
            let mut topo = Topology::default();
            topo.build(4, &s);
            let full = Detector { x: &x, segments: &s, topo: &topo, thickness: 0.1, far_side: 0.3, min_len: 0.0,
                reach: f64::INFINITY, frames: None };
            let near = Detector { reach, ..full };
            let masters = (0..4u32).flat_map(|i| [Master::Segment(i), Master::Node(i)]);
            for m in masters {
                let (a, b) = (full.detect(m, [px, py]), near.detect(m, [px, py]));
                match (a, b) {
                    (Some(a), Some(b)) => proptest::prop_assert_eq!(
                        (a.g.to_bits(), a.n.map(f64::to_bits), a.na.to_bits()),
                        (b.g.to_bits(), b.n.map(f64::to_bits), b.na.to_bits())
                    ),
                    (Some(a), None) => proptest::prop_assert!(a.g > reach, "{m:?}: dropped a hit with g = {}", a.g),
                    (None, Some(_)) => proptest::prop_assert!(false, "{m:?}: a hit the full detection does not find"),
                    (None, None) => {}
                }
                // Against the full geometry: `detect` is `attach` filtered on its flag, to the bit, up to `reach`.
                match (full.attach(m, [px, py]).filter(|(_, inside)| *inside), b) {
                    (Some((a, _)), Some(b)) => proptest::prop_assert_eq!(
                        (a.g.to_bits(), a.n.map(f64::to_bits), a.na.to_bits()),
                        (b.g.to_bits(), b.n.map(f64::to_bits), b.na.to_bits())
                    ),
                    (Some((a, _)), None) => proptest::prop_assert!(a.g > reach, "{m:?}: dropped g = {}", a.g),
                    (None, Some(_)) => proptest::prop_assert!(false, "{m:?}: a hit outside the detection zone"),
                    (None, None) => {}
                }
            }
        }
    }

    #[test]
    fn concave_corner_has_no_node_contact() {
        // Clockwise square = the inside of a tank: every corner concave.
        let x = vec![[0.0, 0.0], [0.0, 1.0], [1.0, 1.0], [1.0, 0.0]];
        let s: Vec<Segment> = (0..4).map(|i| Segment { a: i, b: (i + 1) % 4 }).collect();
        let mut topo = Topology::default();
        topo.build(4, &s);
        let det = Detector {
            x: &x,
            segments: &s,
            topo: &topo,
            thickness: 0.1,
            far_side: 0.3,
            min_len: 0.0,
            reach: f64::INFINITY,
            frames: None,
        };
        assert!(det.attach(Master::Node(0), [0.05, 0.05]).is_none());
        // Both walls act on a particle in the corner.
        assert!(det.detect(Master::Segment(3), [0.05, 0.05]).unwrap().g < 0.0);
        assert!(det.detect(Master::Segment(0), [0.05, 0.05]).unwrap().g < 0.0);
    }

    #[test]
    fn open_chain_ends_are_rounded_caps() {
        let x = vec![[0.0, 0.0], [1.0, 0.0]];
        let s = vec![Segment { a: 0, b: 1 }];
        let mut topo = Topology::default();
        topo.build(2, &s);
        let mut m = Vec::new();
        topo.masters_near(0, s[0], None, &mut m);
        assert_eq!(m, vec![Master::Segment(0), Master::Node(1), Master::Node(0)]);
        let det = Detector {
            x: &x,
            segments: &s,
            topo: &topo,
            thickness: 0.1,
            far_side: 0.3,
            min_len: 0.0,
            reach: f64::INFINITY,
            frames: None,
        };
        assert!(det.detect(Master::Node(1), [1.05, 0.0]).unwrap().g < 0.0);
        assert!(det.detect(Master::Node(0), [-0.05, 0.0]).unwrap().g < 0.0);
        assert!(det.detect(Master::Node(0), [0.05, 0.0]).is_none());
    }
}
