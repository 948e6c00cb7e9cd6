//! Checks on a fluid solver read back from a checkpoint (`docs/PROTOCOL.md` §9), before the node continues from it.
//!
//! A checkpoint holds the solver's state only ([`crate::fluid_solver::SavedSolver`]): parameters come from the scene,
//! and what a step rebuilds (cell order, cell bins, neighbour lists, scratch) is rebuilt on restore as the step
//! rebuilds it, so the continued run computes the same bits. The folder's checksums catch a damaged copy; these
//! checks catch a state that is intact but does not hold together, from another tool or a build with a bug, which
//! would otherwise panic on an index or run on silently wrong:
//! - what follows from the scene (walls, masses, particle count) equals what the scene gives;
//! - every per-particle array has one entry per particle, and the numbers a step starts from are finite;
//! - every position lies in the fluid's domain (the cell grid of the rebuilt caches must fit in memory).
//!
//! Each solver checks its own part ([`crate::WcsphSolver`], [`crate::IsphSolver`]) with the helpers here. A
//! refusal is one line naming the field, the index and the value.

use std::fmt::Debug;

use cosim_proto::scene::BoxSpec;
use cosim_proto::validate::within_largest;

use crate::particles::{FluidState, WallParticles};

/// `Err` is the refusal: one line naming the field, the index and the value.
pub(crate) type Check = Result<(), String>;

/// `values` holds `n` entries.
pub(crate) fn len<T>(field: &str, values: &[T], n: usize, what: &str) -> Check {
    if values.len() == n {
        Ok(())
    } else {
        Err(format!("{field} holds {} entries, there are {n} {what}", values.len()))
    }
}

/// Every entry of `values` is finite, within ±1e50.
pub(crate) fn finite(field: &str, values: &[f64]) -> Check {
    match values.iter().position(|&v| !within_largest(v)) {
        None => Ok(()),
        Some(k) => Err(format!("{field}[{k}] = {} is not finite within ±1e50", values[k])),
    }
}

/// Every vector of `values` is finite, within ±1e50.
pub(crate) fn finite2(field: &str, values: &[[f64; 2]]) -> Check {
    match values
        .iter()
        .position(|v| !(within_largest(v[0]) && within_largest(v[1])))
    {
        None => Ok(()),
        Some(k) => Err(format!("{field}[{k}] = {:?} is not finite within ±1e50", values[k])),
    }
}

/// `saved` equals `want` bit for bit (same length, then every entry).
pub(crate) fn same_bits<T: Bits + Debug>(field: &str, saved: &[T], want: &[T], of: &str) -> Check {
    if saved.len() != want.len() {
        return Err(format!(
            "{field} holds {} entries where {of} has {}",
            saved.len(),
            want.len()
        ));
    }
    match saved.iter().zip(want).position(|(a, b)| a.bits() != b.bits()) {
        None => Ok(()),
        Some(k) => Err(format!("{field}[{k}] = {:?} where {of} has {:?}", saved[k], want[k])),
    }
}

/// Values compared bit for bit (so that NaN is refused where a number is expected, and −0 is told from +0).
pub(crate) trait Bits {
    /// The bit pattern.
    fn bits(&self) -> [u64; 2];
}

impl Bits for f64 {
    fn bits(&self) -> [u64; 2] {
        [self.to_bits(), 0]
    }
}

impl Bits for [f64; 2] {
    fn bits(&self) -> [u64; 2] {
        self.map(f64::to_bits)
    }
}

/// Every position of `x` (field `field`) lies in `domain`.
pub(crate) fn inside(field: &str, x: &[[f64; 2]], domain: &BoxSpec) -> Check {
    match x.iter().position(|p| !domain.contains(*p)) {
        None => Ok(()),
        Some(i) => Err(format!("{field}[{i}] = {:?} is outside the fluid's domain", x[i])),
    }
}

/// The fluid particles: as many as the scene makes, their masses the scene's (a particle's mass never changes),
/// every array one entry per particle, positions, velocities, densities and pressures finite, densities positive.
pub(crate) fn check_state(state: &FluidState, scene: &FluidState) -> Check {
    let n = scene.len();
    let what = "fluid particles";
    if !(state.t.is_finite() && state.t >= 0.0) {
        return Err(format!("state.t = {} is not a time", state.t));
    }
    len("state.x", &state.x, n, what)?;
    len("state.v", &state.v, n, what)?;
    len("state.rho", &state.rho, n, what)?;
    len("state.p", &state.p, n, what)?;
    same_bits("state.m", &state.m, &scene.m, "the scene")?;
    finite2("state.x", &state.x)?;
    finite2("state.v", &state.v)?;
    finite("state.p", &state.p)?;
    match state.rho.iter().position(|r| !(r.is_finite() && *r > 0.0)) {
        None => Ok(()),
        Some(k) => Err(format!("state.rho[{k}] = {} is not a positive density", state.rho[k])),
    }
}

/// The wall particles: where the scene puts them, with its masses, and a finite pressure and positive density each.
pub(crate) fn check_walls(walls: &WallParticles, scene: &WallParticles) -> Check {
    same_bits("walls.x", &walls.x, &scene.x, "the scene")?;
    same_bits("walls.m", &walls.m, &scene.m, "the scene")?;
    let (n, what) = (scene.len(), "wall particles");
    len("walls.p", &walls.p, n, what)?;
    len("walls.rho", &walls.rho, n, what)?;
    finite("walls.p", &walls.p)?;
    match walls.rho.iter().position(|r| !(r.is_finite() && *r > 0.0)) {
        None => Ok(()),
        Some(k) => Err(format!("walls.rho[{k}] = {} is not a positive density", walls.rho[k])),
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use cosim_proto::scene::Scene;

    /// A small dam break (200 particles, Δx = 1 cm) for `fluid.solver` = `solver`, with a tank of walls 3Δx thick,
    /// and the scene overrides `sets` (`key=value`).
    pub(crate) fn tank(solver: &str, sets: &[&str]) -> Scene {
        let text = format!(
            r#"
version = 1
[run]
name = "tank"
end_time = 1.0
output_interval = 0.1
gravity = [0.0, -9.81]
[fluid]
solver = "{solver}"
density = 1000.0
spacing = 0.01
[[fluid.block]]
min = [0.0, 0.0]
max = [0.1, 0.2]
[[wall]]
min = [-0.03, -0.03]
max = [0.43, 0.0]
[[wall]]
min = [-0.03, 0.0]
max = [0.0, 0.3]
[[wall]]
min = [0.4, 0.0]
max = [0.43, 0.3]
"#
        );
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        cosim_proto::scene::parse("tank.toml", &text, &sets).expect("a valid scene")
    }

    #[test]
    fn bits_tell_nan_and_signed_zero() {
        assert_eq!(same_bits("a", &[1.0, 2.0], &[1.0, 2.0], "b"), Ok(()));
        assert_eq!(
            same_bits("a", &[1.0, -0.0], &[1.0, 0.0], "b"),
            Err("a[1] = -0.0 where b has 0.0".into())
        );
        assert_eq!(
            same_bits("a", &[[f64::NAN, 0.0]], &[[0.0, 0.0]], "b"),
            Err("a[0] = [NaN, 0.0] where b has [0.0, 0.0]".into())
        );
        assert_eq!(
            same_bits("a", &[1.0], &[], "b"),
            Err("a holds 1 entries where b has 0".into())
        );
    }
}
