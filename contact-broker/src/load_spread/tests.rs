use super::*;

/// `n` nodes 1 mm apart along x, joined in a line.
fn line(n: usize) -> (Vec<[f64; 2]>, Vec<Segment>) {
    let x = (0..n).map(|i| [i as f64 * 1e-3, 0.0]).collect();
    let s = (0..n - 1).map(|i| Segment { a: i, b: i + 1 }).collect();
    (x, s)
}

/// On a straight line the impulse of one node goes to the nodes within R with weights 1 − d/R, normalised: R = 2.5
/// mm gives 1, 0.6, 0.2 each side (sum 2.6); the sum and the first moment are the impulse's to round-off, and the
/// returned change is the spread less the impulse.
#[test]
fn a_node_s_impulse_spreads_symmetrically_and_keeps_its_sum_and_moment() {
    let (x, s) = line(11);
    let mut j = vec![[0.0; 2]; 11];
    j[5] = [0.3, -2.0];
    let mut spread = LoadSpread::new(2.5e-3);
    let change = spread.apply(&s, &x, &[false; 11], &mut j);
    for (k, w) in [(3, 0.2), (4, 0.6), (5, 1.0), (6, 0.6), (7, 0.2)] {
        let want = -2.0 * w / 2.6;
        assert!((j[k][1] - want).abs() < 1e-15, "node {k}: {:?} against {want}", j[k]);
    }
    assert_eq!(j[2], [0.0; 2]);
    assert_eq!(j[8], [0.0; 2]);
    let sum: [f64; 2] = j.iter().fold([0.0; 2], |a, v| [a[0] + v[0], a[1] + v[1]]);
    assert!((sum[0] - 0.3).abs() < 1e-15 && (sum[1] + 2.0).abs() < 1e-15, "{sum:?}");
    let moment: f64 = j.iter().zip(&x).map(|(v, p)| p[0] * v[1] - p[1] * v[0]).sum();
    assert!((moment - x[5][0] * -2.0).abs() < 1e-16, "{moment}");
    assert!((change[5][1] - (j[5][1] + 2.0)).abs() < 1e-15 && change[4] == j[4]);
}

/// A fixed node keeps its own impulse and receives none: the free nodes share the source's among themselves.
#[test]
fn fixed_nodes_keep_their_own_and_receive_none() {
    let (x, s) = line(6);
    let mut fixed = [false; 6];
    fixed[1] = true;
    let mut j = vec![[0.0; 2]; 6];
    j[2] = [0.0, 1.0];
    j[1] = [5.0, 0.0];
    LoadSpread::new(1.5e-3).apply(&s, &x, &fixed, &mut j);
    assert_eq!(j[1], [5.0, 0.0]);
    // Node 2 (weight 1) and node 3 (1 − 1/1.5 = 1/3): node 1 is fixed.
    assert!(
        (j[2][1] - 0.75).abs() < 1e-15 && (j[3][1] - 0.25).abs() < 1e-15,
        "{j:?}"
    );
}

/// The distance is along the segments: the other face of a thin wall, 1 mm away across it but 20 mm away around
/// its end, receives nothing at R = 3 mm.
#[test]
fn the_spread_follows_the_surface_not_the_straight_line() {
    // Face A: nodes 0..=10 at y = 0, x = 0..10 mm; the end at x = 10 mm joins face B: nodes 11..=21 at y = 1 mm,
    // x = 10..0 mm.
    let mut x: Vec<[f64; 2]> = (0..=10).map(|i| [i as f64 * 1e-3, 0.0]).collect();
    x.extend((0..=10).map(|i| [(10 - i) as f64 * 1e-3, 1e-3]));
    let s: Vec<Segment> = (0..21).map(|i| Segment { a: i, b: i + 1 }).collect();
    let mut j = vec![[0.0; 2]; 22];
    j[2] = [0.0, 1.0];
    LoadSpread::new(3e-3).apply(&s, &x, &[false; 22], &mut j);
    // Node 19 is at (2 mm, 1 mm), 1 mm from node 2 in a straight line.
    assert!(j[11..].iter().all(|v| *v == [0.0; 2]), "{:?}", &j[11..]);
    assert!(j[0][1] > 0.0 && j[4][1] > 0.0 && j[5] == [0.0; 2]);
}

/// Off (radius 0) nothing moves.
#[test]
fn off_changes_nothing() {
    let (x, s) = line(4);
    let mut j = vec![[1.0, 2.0]; 4];
    let change = LoadSpread::new(0.0).apply(&s, &x, &[false; 4], &mut j);
    assert_eq!(j, vec![[1.0, 2.0]; 4]);
    assert_eq!(change, vec![[0.0; 2]; 4]);
}
