//! How fast and how far a state of a run can be: a node whose state goes beyond has blown up, though its numbers are
//! finite (`docs/PROTOCOL.md` §7). The speed is bounded by the scene's fastest wave speed, the position by where the
//! scene starts grown by that speed over the run's end time.

use super::{Check, Result};
use crate::readable::significant;
use crate::Num;

/// How many times the scene's fastest wave speed a state may move at most ([`speed_limit`]).
pub const SPEED_LIMIT_FACTOR: f64 = 10.0;

/// The fastest a fluid particle or a structure node of a run may move: [`SPEED_LIMIT_FACTOR`] times the fastest
/// wave speed of the scene, the fluid's sound speed `c0` (where it has one) or a solid's bar wave speed √(E/ρ)
/// (`solid_wave_speeds`). Nothing a run can reach comes near it: a weakly compressible fluid's model holds below a
/// tenth of `c0` (`DESIGN.md` §4.2, c0 ≥ 10 v_max), and a node moving at its solid's wave speed strains it by order
/// one. A node that reports more has blown up, though its numbers are finite: found 2026-12-06 by a sweep of
/// hostile external nodes, a structure reporting 1e20 m/s, or one whose spring flung it at 1e11 m/s, blew up the
/// fluid node, which took the blame, or made the coupling step crawl (1e5 steps to reach t = 0.0006 s). Infinite
/// where the scene gives no wave speed.
pub fn speed_limit(c0: Option<f64>, solid_wave_speeds: impl IntoIterator<Item = f64>) -> f64 {
    let fastest = solid_wave_speeds
        .into_iter()
        .chain(c0)
        .filter(|c| c.is_finite() && *c > 0.0)
        .fold(0.0, f64::max);
    if fastest > 0.0 {
        SPEED_LIMIT_FACTOR * fastest
    } else {
        f64::INFINITY
    }
}

/// How fast and how far a particle or a node of a run may be. The broker makes it from the scene and the
/// registrations (`contact-broker/src/coordinator/exchange.rs` `Expected`); infinite bounds check nothing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reach {
    /// The fastest a particle or a node may move [m/s] ([`speed_limit`]).
    pub speed: f64,
    /// The box every position lies in [m]: lower corner.
    pub min: [f64; 2],
    /// Upper corner.
    pub max: [f64; 2],
}

impl Reach {
    /// No bound at all.
    pub const ANY: Self = Self {
        speed: f64::INFINITY,
        min: [f64::NEG_INFINITY; 2],
        max: [f64::INFINITY; 2],
    };

    /// A run that starts within the box `start` (lower, upper corner) and moves no faster than `speed` until
    /// `end_time` stays within that box grown by `speed` × `end_time` on every side. A structure reported at 1e10 m
    /// with a plausible speed (its positions jumping from one step to the next) was taken, the contact's region of
    /// interest built round it, and the fluid node blamed for what followed (found 2026-12-06 by the sweep of hostile
    /// external nodes, D12). Infinite where the speed is.
    pub fn new(speed: f64, start: ([f64; 2], [f64; 2]), end_time: f64) -> Self {
        let grow = speed * end_time.max(0.0);
        if !grow.is_finite() {
            return Self { speed, ..Self::ANY };
        }
        let (lo, hi) = start;
        Self {
            speed,
            min: [lo[0] - grow, lo[1] - grow],
            max: [hi[0] + grow, hi[1] + grow],
        }
    }
}

impl Check {
    /// Every velocity of `vs` no faster than `reach.speed`.
    pub(super) fn speeds(self, field: &'static str, vs: &[[f64; 2]], reach: &Reach) -> Result {
        let limit = reach.speed;
        match vs.iter().position(|v| v[0].hypot(v[1]) > limit) {
            None => Ok(()),
            Some(i) => Err(self
                .fail(
                    field,
                    &[i],
                    format!("{:?}", vs[i]),
                    format!(
                        "{} m/s, faster than any run of the scene moves ({} m/s: {SPEED_LIMIT_FACTOR} times its \
                         fastest wave speed)",
                        Num(significant(vs[i][0].hypot(vs[i][1]), 6)),
                        Num(limit)
                    ),
                )
                .implausible()),
        }
    }

    /// Every position of `xs` within `reach`'s box.
    pub(super) fn positions(self, field: &'static str, xs: &[[f64; 2]], reach: &Reach) -> Result {
        let inside = |x: &[f64; 2]| (0..2).all(|k| x[k] >= reach.min[k] && x[k] <= reach.max[k]);
        match xs.iter().position(|x| !inside(x)) {
            None => Ok(()),
            Some(i) => Err(self
                .fail(
                    field,
                    &[i],
                    format!("{:?}", xs[i]),
                    format!(
                        "farther than any run of the scene reaches (x in {}…{} m, y in {}…{} m: where it starts, \
                         grown by {SPEED_LIMIT_FACTOR} times its fastest wave speed over its end time)",
                        Num(significant(reach.min[0], 6)),
                        Num(significant(reach.max[0], 6)),
                        Num(significant(reach.min[1], 6)),
                        Num(significant(reach.max[1], 6))
                    ),
                )
                .implausible()),
        }
    }
}
