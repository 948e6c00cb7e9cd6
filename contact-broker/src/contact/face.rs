//! The structure's face behind a fluid particle: the nearest point of the boundary segments and the unit normal
//! there, out of the structure. Sent with the fluid's corrections of a `particle_particle` pass (`Correction::face`),
//! which changes velocities only, so that ISPH can put the particle's Neumann row on the structure where it is
//! (`sph-node/src/isph/contact.rs`; docs/CORRECTIONS.md "ISPH + `particle_particle`").

use super::bodies::Segment;
use super::geometry::{dot, scale, sub, Vec2};

/// The point of the boundary `segments` (node positions `x`) nearest to `p`, and the unit normal there out of the
/// structure: the outward normal (dy, −dx)/L of the segment that point lies on (boundaries run counter-clockwise).
/// At a convex corner, whose point both segments share, the segment `p` lies further in front of: the separating
/// plane (the direction from the corner to `p` instead made the coupled ISPH gate blow up sooner, t = 0.20 against
/// 0.32 s, docs/CORRECTIONS.md "ISPH + `particle_particle`"). `None` without a usable segment (none, or all of zero
/// length or naming nodes `x` does not have).
pub fn nearest_face(segments: &[Segment], x: &[Vec2], p: Vec2) -> Option<(Vec2, Vec2)> {
    // (squared distance, −distance in front of the segment's line, foot, normal): the least wins.
    let mut best: Option<(f64, f64, Vec2, Vec2)> = None;
    for s in segments {
        let (Some(&a), Some(&b)) = (x.get(s.a), x.get(s.b)) else {
            continue;
        };
        let t = sub(b, a);
        let len2 = dot(t, t);
        if len2.is_nan() || len2 <= 0.0 {
            continue;
        }
        let xi = (dot(sub(p, a), t) / len2).clamp(0.0, 1.0);
        let foot = [a[0] + xi * t[0], a[1] + xi * t[1]];
        let d = sub(p, foot);
        let dist2 = dot(d, d);
        let normal = scale([t[1], -t[0]], 1.0 / len2.sqrt());
        let behind = -dot(d, normal);
        if best.is_none_or(|(b2, b_behind, _, _)| (dist2, behind) < (b2, b_behind)) {
            best = Some((dist2, behind, foot, normal));
        }
    }
    best.map(|(_, _, foot, normal)| (foot, normal))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit square, counter-clockwise: in front of a side the face is that side, beyond a corner the corner.
    #[test]
    fn the_nearest_face_of_a_square() {
        let x = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let segments: Vec<Segment> = (0..4).map(|k| Segment { a: k, b: (k + 1) % 4 }).collect();
        // Above the top side (2 → 3): its outward normal +y.
        assert_eq!(
            nearest_face(&segments, &x, [0.25, 1.5]),
            Some(([0.25, 1.0], [0.0, 1.0]))
        );
        // Right of the right side (1 → 2): +x.
        assert_eq!(nearest_face(&segments, &x, [1.2, 0.5]), Some(([1.0, 0.5], [1.0, 0.0])));
        // Beyond the corner (1, 1), more above than right of it: the corner, on the top side's plane; more right
        // than above: on the right side's.
        assert_eq!(nearest_face(&segments, &x, [1.2, 1.5]), Some(([1.0, 1.0], [0.0, 1.0])));
        assert_eq!(nearest_face(&segments, &x, [1.5, 1.2]), Some(([1.0, 1.0], [1.0, 0.0])));
        // Nothing to be near.
        assert_eq!(nearest_face(&[], &x, [0.0, 0.0]), None);
        assert_eq!(nearest_face(&[Segment { a: 0, b: 9 }], &x, [0.0, 0.0]), None);
    }
}
