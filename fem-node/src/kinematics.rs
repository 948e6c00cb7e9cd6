//! Small 2D kinematics helpers shared by elements and materials.

use nalgebra::{Matrix2, Vector2};

/// Rotation of the polar decomposition `F = R U` (2D, `det F > 0`), as `(cos θ, sin θ)`.
///
/// In 2D, `Rᵀ F` is symmetric exactly when `tan θ = (F₂₁ − F₁₂) / (F₁₁ + F₂₂)`; the branch with
/// `cos θ (F₁₁ + F₂₂) + sin θ (F₂₁ − F₁₂) = tr U > 0` is the one with `U` positive definite.
/// Returns `None` when `F₁₁ + F₂₂` and `F₂₁ − F₁₂` both vanish (no unique rotation; only possible for
/// `det F ≤ 0`).
pub fn polar_rotation(f: &Matrix2<f64>) -> Option<(f64, f64)> {
    let c = f[(0, 0)] + f[(1, 1)];
    let s = f[(1, 0)] - f[(0, 1)];
    let r = c.hypot(s);
    if r > 0.0 && r.is_finite() {
        Some((c / r, s / r))
    } else {
        None
    }
}

/// The rotation matrix of angle θ from `(cos θ, sin θ)`.
pub fn rotation_matrix((c, s): (f64, f64)) -> Matrix2<f64> {
    Matrix2::new(c, -s, s, c)
}

/// 2D cross product `a × b = a_x b_y − a_y b_x`.
pub fn cross(a: Vector2<f64>, b: Vector2<f64>) -> f64 {
    a.x * b.y - a.y * b.x
}

/// `[f64; 2]` as a vector.
pub fn vec2(p: [f64; 2]) -> Vector2<f64> {
    Vector2::new(p[0], p[1])
}
