//! Parameters of the particle–element contact (`DESIGN.md` §4.5) and their check.

use crate::contact::error::{param, ContactError};

/// Parameters of the particle–element contact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactParams {
    /// Contact thickness r_c [m]: particles are kept this far from the segments (`DESIGN.md` §4.5: Δx/2).
    pub thickness: f64,
    /// Far-side limit d_max [m]: a particle more than this far behind a segment is on the other side of the
    /// structure and ignored. Keep it below the thinnest part of the structure (plus r_c), or particles on one face
    /// are caught by the segments of the opposite face.
    pub far_side: f64,
    /// Maximum Gauss–Seidel sweeps of each phase (positions, velocities); the paper uses 2–3. Sweeps stop earlier
    /// once converged.
    pub sweeps: u32,
    /// Relative convergence tolerance: a phase stops when a sweep's largest correction is below
    /// `tolerance · thickness` (positions) or `tolerance ·` the first sweep's largest approach speed (velocities).
    /// Contacts within `tolerance · thickness` of touching after the position phase get the velocity correction
    /// (and those within 1e-12 · thickness plus 16 ulp of the coordinates, whatever the tolerance).
    pub tolerance: f64,
    /// Whether the position phase moves the master nodes too (x_a −= λ N_a/m_a n, `DESIGN.md` §4.5 as written).
    /// When false the masters are held in place for the position phase (the particle alone is projected, exactly,
    /// as against a rigid structure) and take their share of the velocity phase only: momentum is exchanged the
    /// same way, and no FE node is displaced by a share of the penetration that goes with 1/m instead of with the
    /// structure's stiffness.
    pub move_masters: bool,
}

impl Default for ContactParams {
    /// [`ContactParams::for_spacing`] of 0.01 m.
    fn default() -> Self {
        Self::for_spacing(0.01)
    }
}

impl ContactParams {
    /// The defaults for particle spacing `dx`: r_c = Δx/2, d_max = 2Δx, 3 sweeps, tolerance 1e-9, masters moved
    /// by the position phase (the paper's algorithm).
    pub fn for_spacing(dx: f64) -> Self {
        ContactParams {
            thickness: 0.5 * dx,
            far_side: 2.0 * dx,
            sweeps: 3,
            tolerance: 1e-9,
            move_masters: true,
        }
    }

    pub(super) fn validate(&self) -> Result<(), ContactError> {
        param("thickness", self.thickness, self.thickness > 0.0, "positive and finite")?;
        param("far_side", self.far_side, self.far_side > 0.0, "positive and finite")?;
        param("sweeps", self.sweeps as f64, self.sweeps >= 1, "at least 1")?;
        param(
            "tolerance",
            self.tolerance,
            (0.0..1.0).contains(&self.tolerance),
            "in [0, 1)",
        )
    }
}
