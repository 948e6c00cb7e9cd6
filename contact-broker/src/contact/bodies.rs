//! The bodies in contact: the slave particles, the master nodes and the boundary segments between the nodes, and
//! the check of a call's arrays that every contact routine starts with.

use super::error::ContactError;

/// Slave particles: the fluid particles in the region of interest. `x` and `v` are corrected in place.
#[derive(Debug)]
pub struct Particles<'a> {
    /// Positions [m].
    pub x: &'a mut [[f64; 2]],
    /// Velocities [m/s].
    pub v: &'a mut [[f64; 2]],
    /// Masses [kg/m], positive.
    pub m: &'a [f64],
}

/// Structure nodes (masters). `x` and `v` of free nodes are corrected in place; fixed nodes are never written.
#[derive(Debug)]
pub struct Nodes<'a> {
    /// Positions [m].
    pub x: &'a mut [[f64; 2]],
    /// Velocities [m/s].
    pub v: &'a mut [[f64; 2]],
    /// Lumped masses [kg/m], positive for free nodes (ignored for fixed ones).
    pub m: &'a [f64],
    /// Fixed (clamped or prescribed) nodes: infinite mass, 1/m = 0.
    pub fixed: &'a [bool],
}

/// A boundary segment from node `a` to node `b` (indices into [`Nodes`]). The structure lies on its left, so its
/// outward normal n = (Δy, −Δx)/L points into the fluid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Segment {
    /// Start node.
    pub a: usize,
    /// End node.
    pub b: usize,
}

/// Checks array lengths, segment indices and that every value is usable.
pub(crate) fn validate(p: &Particles, n: &Nodes, segments: &[Segment]) -> Result<(), ContactError> {
    let len = |what, expected, got| {
        if expected == got {
            Ok(())
        } else {
            Err(ContactError::Length { what, expected, got })
        }
    };
    let np = p.x.len();
    len("particle velocities", np, p.v.len())?;
    len("particle masses", np, p.m.len())?;
    let nn = n.x.len();
    len("node velocities", nn, n.v.len())?;
    len("node masses", nn, n.m.len())?;
    len("node fixed flags", nn, n.fixed.len())?;
    for (j, s) in segments.iter().enumerate() {
        if s.a >= nn || s.b >= nn || s.a == s.b {
            return Err(ContactError::Segment {
                segment: j,
                a: s.a,
                b: s.b,
                nodes: nn,
            });
        }
    }
    let check = |what, xs: &[[f64; 2]], vs: &[[f64; 2]], ms: &[f64], mass_needed: &dyn Fn(usize) -> bool| {
        for i in 0..xs.len() {
            for (field, val) in [("x", xs[i]), ("v", vs[i])] {
                if let Some(&bad) = val.iter().find(|c| !c.is_finite()) {
                    return Err(ContactError::Value {
                        what,
                        index: i,
                        field,
                        value: bad,
                        positive: "",
                    });
                }
            }
            if mass_needed(i) && !(ms[i] > 0.0 && ms[i].is_finite()) {
                let positive = " and positive";
                return Err(ContactError::Value {
                    what,
                    index: i,
                    field: "m",
                    value: ms[i],
                    positive,
                });
            }
        }
        Ok(())
    };
    check("particle", p.x, p.v, p.m, &|_| true)?;
    check("node", n.x, n.v, n.m, &|k| !n.fixed[k])
}
