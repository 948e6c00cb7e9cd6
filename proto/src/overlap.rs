//! The first pair of rectangles whose areas overlap, found by a sweep over x in O(n log n): rectangles that touch
//! along an edge or at a corner do not overlap.
//!
//! The sweep keeps the rectangles that span the current x, ordered by their lower y. As long as no two of them
//! overlap, their y intervals are disjoint, so a new one can overlap one of them only if it overlaps its neighbour
//! below or above in that order.

use std::collections::BTreeMap;

/// A rectangle: lower and upper corner.
pub type Rect = ([f64; 2], [f64; 2]);

/// Indices `(i, j)`, `i < j`, of two rectangles whose interiors intersect, or `None`. Every rectangle must be
/// finite with min < max in both components (as [`crate::scene::Scene::validate`] checks before).
pub fn first_overlap(rects: &[Rect]) -> Option<(usize, usize)> {
    // Leaving rectangles go before arriving ones at the same x: sharing an edge is no overlap.
    let mut events: Vec<(f64, bool, usize)> = Vec::with_capacity(2 * rects.len());
    for (i, (min, max)) in rects.iter().enumerate() {
        events.push((max[0], false, i));
        events.push((min[0], true, i));
    }
    events.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    // (lower y, index) → (lower y, upper y) of the rectangles spanning the sweep's x.
    let mut active: BTreeMap<(u64, usize), (f64, f64)> = BTreeMap::new();
    for (_, arrives, i) in events {
        let (min, max) = rects[i];
        let key = (ordered(min[1]), i);
        if !arrives {
            active.remove(&key);
            continue;
        }
        let below = active.range(..key).next_back();
        let above = active.range(key..).next();
        let hit = match (below, above) {
            (Some((&(_, j), &(_, top))), _) if top > min[1] => Some(j),
            (_, Some((&(_, j), &(bottom, _)))) if bottom < max[1] => Some(j),
            _ => None,
        };
        if let Some(j) = hit {
            return Some((i.min(j), i.max(j)));
        }
        active.insert(key, (min[1], max[1]));
    }
    None
}

/// A key whose order is the order of the finite `f64` values (−0 and +0 made one).
fn ordered(v: f64) -> u64 {
    let bits = (v + 0.0).to_bits();
    if bits >> 63 == 1 {
        !bits
    } else {
        bits | (1 << 63)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brute(rects: &[Rect]) -> bool {
        (0..rects.len())
            .any(|i| (0..i).any(|j| (0..2).all(|k| rects[i].0[k] < rects[j].1[k] && rects[j].0[k] < rects[i].1[k])))
    }

    #[test]
    fn touching_is_not_overlap_and_area_is() {
        let a = ([0.0, 0.0], [1.0, 1.0]);
        assert_eq!(first_overlap(&[a, ([1.0, 0.0], [2.0, 1.0])]), None);
        assert_eq!(first_overlap(&[a, ([1.0, 1.0], [2.0, 2.0])]), None);
        assert_eq!(first_overlap(&[a, ([0.0, 1.0], [1.0, 2.0])]), None);
        assert_eq!(first_overlap(&[a, ([0.5, 0.5], [2.0, 2.0])]), Some((0, 1)));
        // Inside, and crossing without a corner inside the other.
        assert_eq!(first_overlap(&[a, ([0.2, 0.2], [0.3, 0.3])]), Some((0, 1)));
        assert_eq!(first_overlap(&[([-1.0, 0.4], [2.0, 0.6]), a]), Some((0, 1)));
        assert_eq!(
            first_overlap(&[([0.0, -0.0], [1.0, 1.0]), ([0.5, 0.0], [2.0, 2.0])]),
            Some((0, 1))
        );
    }

    #[test]
    fn agrees_with_all_pairs_on_a_lattice_of_small_rectangles() {
        // Corners on a coarse lattice, so that edges often coincide: pseudo-random, fixed seed.
        let mut seed = 12345u64;
        let mut next = |m: u64| {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 33) % m
        };
        for _ in 0..2000 {
            let n = 1 + next(6) as usize;
            let rects: Vec<Rect> = (0..n)
                .map(|_| {
                    let (x, y) = (next(6) as f64, next(6) as f64);
                    ([x, y], [x + 1.0 + next(3) as f64, y + 1.0 + next(3) as f64])
                })
                .collect();
            assert_eq!(first_overlap(&rects).is_some(), brute(&rects), "{rects:?}");
        }
    }

    #[test]
    fn a_hundred_thousand_stacked_plates_take_no_quadratic_time() {
        // Every plate spans the same x: an all-pairs test would compare 5e9 pairs.
        let plates: Vec<Rect> = (0..100_000).map(|i| ([0.0, i as f64], [1.0, i as f64 + 1.0])).collect();
        let started = std::time::Instant::now();
        assert_eq!(first_overlap(&plates), None);
        assert!(started.elapsed().as_secs_f64() < 2.0, "{:?}", started.elapsed());
    }
}
