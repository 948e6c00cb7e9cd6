//! The cell-linked list finds exactly the brute-force neighbours.

use proptest::prelude::*;
use sph_node::neighbors::CellList;

fn points() -> impl Strategy<Value = Vec<[f64; 2]>> {
    prop::collection::vec((-1.0f64..1.0, -0.5f64..2.0).prop_map(|(x, y)| [x, y]), 1..400)
}

proptest! {
    #[test]
    fn equals_brute_force(pts in points(), h in 0.01f64..0.5) {
        let radius = 2.0 * h;
        let cells = CellList::new(&pts, radius);
        let list = cells.neighbor_list(&pts, pts.len(), radius);
        for i in 0..pts.len() {
            let mut got: Vec<u32> = list.of(i).to_vec();
            got.sort_unstable();
            let expected: Vec<u32> = (0..pts.len())
                .filter(|&j| {
                    j != i && {
                        let d = [pts[i][0] - pts[j][0], pts[i][1] - pts[j][1]];
                        d[0] * d[0] + d[1] * d[1] < radius * radius
                    }
                })
                .map(|j| j as u32)
                .collect();
            prop_assert_eq!(got, expected, "particle {}", i);
        }
        // Every particle appears once in the cell-sorted order.
        let mut sorted = cells.sorted().to_vec();
        sorted.sort_unstable();
        prop_assert_eq!(sorted, (0..pts.len() as u32).collect::<Vec<_>>());
    }
}
