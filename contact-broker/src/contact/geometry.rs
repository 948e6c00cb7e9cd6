//! Small 2D vector helpers and the frame of a master segment (`DESIGN.md` §4.5, detection).

/// A 2D point or vector [m] (or [m/s] for velocities).
pub(crate) type Vec2 = [f64; 2];

#[inline]
pub(crate) fn sub(a: Vec2, b: Vec2) -> Vec2 {
    [a[0] - b[0], a[1] - b[1]]
}

#[inline]
pub(crate) fn add(a: Vec2, b: Vec2) -> Vec2 {
    [a[0] + b[0], a[1] + b[1]]
}

#[inline]
pub(crate) fn scale(a: Vec2, s: f64) -> Vec2 {
    [a[0] * s, a[1] * s]
}

#[inline]
pub(crate) fn dot(a: Vec2, b: Vec2) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// z-component of the 2D cross product a × b.
#[inline]
pub(crate) fn cross(a: Vec2, b: Vec2) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// y + a x.
#[inline]
pub(crate) fn axpy(y: Vec2, a: f64, x: Vec2) -> Vec2 {
    [y[0] + a * x[0], y[1] + a * x[1]]
}

#[inline]
pub(crate) fn norm(a: Vec2) -> f64 {
    // Not `hypot`: it is several times slower and the coordinates here are far from overflow.
    dot(a, a).sqrt()
}

/// `a / |a|`, or `None` for a zero (or non-finite) vector.
#[inline]
pub(crate) fn normalize(a: Vec2) -> Option<Vec2> {
    let l = norm(a);
    (l > 0.0 && l.is_finite()).then(|| scale(a, 1.0 / l))
}

/// ξ = (x − x1)·t/L, computed as (x − x1)·d/|d|² with d = x2 − x1 (no square root), the one formula used for
/// every ξ so that detection and correction agree to the bit.
#[inline]
pub(crate) fn xi(x1: Vec2, d: Vec2, x: Vec2) -> f64 {
    dot(sub(x, x1), d) / dot(d, d)
}

/// The frame of a master segment x1 → x2: unit tangent t = (x2 − x1)/L and outward unit normal
/// n = (t_y, −t_x), which points into the fluid when the structure lies on the left of x1 → x2.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Frame {
    pub x1: Vec2,
    pub x2: Vec2,
    pub t: Vec2,
    pub n: Vec2,
}

impl Frame {
    /// The frame, or `None` when the segment is shorter than `min_len` (a collapsed element has no normal).
    #[inline]
    pub fn new(x1: Vec2, x2: Vec2, min_len: f64) -> Option<Frame> {
        let d = sub(x2, x1);
        let len = norm(d);
        if !(len > min_len && len.is_finite()) {
            return None;
        }
        let t = scale(d, 1.0 / len);
        Some(Frame {
            x1,
            x2,
            t,
            n: [t[1], -t[0]],
        })
    }

    /// Natural coordinate of the projection of `x` on the segment: ξ = (x_s − x1)·t / L
    /// (Long et al. 2016 after Johnson & Stryk 2001; `DESIGN.md` §4.5).
    #[inline]
    pub fn xi(&self, x: Vec2) -> f64 {
        xi(self.x1, sub(self.x2, self.x1), x)
    }

    /// Contact point x_c = N1 x1 + N2 x2 with N1 = 1 − ξ, N2 = ξ (`DESIGN.md` §4.5).
    #[inline]
    pub fn point(&self, n1: f64, n2: f64) -> Vec2 {
        [n1 * self.x1[0] + n2 * self.x2[0], n1 * self.x1[1] + n2 * self.x2[1]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_normal_points_right_of_the_direction() {
        // Structure on the left of a -> b: for a segment along +x the structure is above, the fluid below.
        let f = Frame::new([0.0, 0.0], [2.0, 0.0], 0.0).unwrap();
        assert_eq!(f.n, [0.0, -1.0]);
        assert_eq!(f.xi([0.5, 3.0]), 0.25);
        assert_eq!(f.point(0.75, 0.25), [0.5, 0.0]);
        assert!(Frame::new([1.0, 1.0], [1.0, 1.0], 0.0).is_none());
    }

    #[test]
    fn cross_and_normalize() {
        assert_eq!(cross([1.0, 0.0], [0.0, 1.0]), 1.0);
        let u = normalize([3.0, 4.0]).unwrap();
        assert!((u[0] - 0.6).abs() < 1e-15 && (u[1] - 0.8).abs() < 1e-15);
        assert_eq!(normalize([0.0, 0.0]), None);
    }
}
