//! The structure's share of the contact impulses spread along its surface over a fluid particle's reach
//! (`contact.load_spread`, issue 16; docs/CORRECTIONS.md "The structure's mesh against the fluid's particles").
//!
//! The particle–element contact (Long et al. 2016) and the repulsive force exchange momentum between one particle and
//! the two nodes of a segment (or one node). A fluid particle stands for a parcel of water Δx wide; where the
//! structure's mesh is much finer than that, its impulse lands on nodes that weigh a small fraction of it and rings the
//! mesh at its own scale, and the coupled run gains energy (the gate: 0.106 of the budget with WCSPH when a particle
//! weighs 58 cells). Here each free interface node's impulse J_j is shared among the free interface nodes k within
//! the surface distance R of it, along the interface segments (never across the structure to its other face), with
//! the weights w_jk = (1 − d_jk / R) / Σ_k (1 − d_jk / R): Σ_k w_jk = 1, so the linear momentum the structure
//! receives is the pass's to round-off. Its moment moves by at most |J| R per node, and not at all on a straight
//! stretch of surface longer than 2R each side, where the weights are symmetric. Fixed nodes keep their own impulse
//! and receive none. The fluid's corrections are the algorithm's, untouched.

use crate::contact::Segment;

/// Spreads impulses over the surface distance `radius` [m]; 0 leaves them where the contact put them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LoadSpread {
    radius: f64,
    /// Per node, its neighbours along the segments: built at the first pass (an interface's segments do not change).
    adjacent: Vec<Vec<usize>>,
}

impl LoadSpread {
    /// Spreading over `radius` [m] (0: none).
    pub fn new(radius: f64) -> Self {
        Self {
            radius,
            adjacent: Vec::new(),
        }
    }

    /// Whether impulses are spread at all.
    pub fn active(&self) -> bool {
        self.radius > 0.0
    }

    /// Replaces `impulse` (one per interface node, the nodes at `x`, joined by `segments`, the same segments at every
    /// call) by its spread, and returns per node the spread less the impulse it had (to add to the node's velocity
    /// times its mass). Nothing changes where [`LoadSpread::active`] is false.
    pub fn apply(
        &mut self,
        segments: &[Segment],
        x: &[[f64; 2]],
        fixed: &[bool],
        impulse: &mut [[f64; 2]],
    ) -> Vec<[f64; 2]> {
        let n = impulse.len();
        let mut change = vec![[0.0; 2]; n];
        if !self.active() || n == 0 {
            return change;
        }
        if self.adjacent.len() != n {
            self.adjacent = vec![Vec::new(); n];
            for s in segments.iter().filter(|s| s.a < n && s.b < n && s.a != s.b) {
                self.adjacent[s.a].push(s.b);
                self.adjacent[s.b].push(s.a);
            }
        }
        let length = |a: usize, b: usize| {
            let (p, q) = (
                x.get(a).copied().unwrap_or_default(),
                x.get(b).copied().unwrap_or_default(),
            );
            (p[0] - q[0]).hypot(p[1] - q[1])
        };
        let is_fixed = |k: usize| fixed.get(k).copied().unwrap_or(true);
        let mut spread = vec![[0.0; 2]; n];
        // Surface distances from the source, found by Dijkstra over the few nodes within R (a linear scan for the
        // nearest unsettled node: the neighbourhoods are a handful of nodes).
        let mut dist: Vec<(usize, f64, bool)> = Vec::new();
        for (j, &jj) in impulse.iter().enumerate() {
            if jj == [0.0; 2] {
                continue;
            }
            if is_fixed(j) {
                spread[j] = [spread[j][0] + jj[0], spread[j][1] + jj[1]];
                continue;
            }
            dist.clear();
            dist.push((j, 0.0, false));
            while let Some(at) = (0..dist.len())
                .filter(|&i| !dist[i].2)
                .min_by(|&a, &b| dist[a].1.total_cmp(&dist[b].1).then(dist[a].0.cmp(&dist[b].0)))
            {
                dist[at].2 = true;
                let (node, d) = (dist[at].0, dist[at].1);
                for &next in &self.adjacent[node] {
                    let dn = d + length(node, next);
                    if dn >= self.radius {
                        continue;
                    }
                    match dist.iter_mut().find(|e| e.0 == next) {
                        Some(e) if e.2 || e.1 <= dn => {}
                        Some(e) => e.1 = dn,
                        None => dist.push((next, dn, false)),
                    }
                }
            }
            // In node order, so that every sum runs in one order whatever the search visited first.
            dist.sort_by_key(|e| e.0);
            let weight = |d: f64| 1.0 - d / self.radius;
            let total: f64 = dist.iter().filter(|e| !is_fixed(e.0)).map(|e| weight(e.1)).sum();
            for &(k, d, _) in dist.iter().filter(|e| !is_fixed(e.0)) {
                let w = weight(d) / total;
                spread[k] = [spread[k][0] + w * jj[0], spread[k][1] + w * jj[1]];
            }
        }
        for ((c, s), j) in change.iter_mut().zip(&spread).zip(impulse.iter_mut()) {
            *c = [s[0] - j[0], s[1] - j[1]];
            *j = *s;
        }
        change
    }
}

#[cfg(test)]
mod tests;
