//! Controlling a live run (`docs/PROTOCOL.md` §11): the break conditions of `cosim run --break`, the commands of
//! `cosim ctl` (pause, resume, step, stop) with the broker's answer, and the state a paused run hands out for
//! `cosim snapshot` and `cosim inspect --particle/--node`.
//!
//! The commands and answers are JSON (the queryable `cosim/<run>/broker/control`), so that any tool can drive a
//! run; the state is an [`Envelope`](crate::Envelope) of [`DebugState`] (the queryable `cosim/<run>/broker/state`),
//! because it carries the nodes' checkpoints, which are bytes.

use serde::{Deserialize, Serialize};

use crate::messages::Correction;

/// When `cosim run --break CONDITION` pauses the run: after the first coupling step at whose end it holds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BreakCondition {
    /// `t>=T`: simulated time at least `T` [s].
    TimeAtLeast(f64),
    /// `step=N`: coupling step `N` done.
    Step(u64),
    /// `max_penetration>P`: the deepest penetration so far (`contact_stats.max_penetration`) beyond `P` [m].
    MaxPenetrationAbove(f64),
    /// `unstable`: a node blew up (it said so, or sent a NaN or an infinity); the run pauses instead of ending, and
    /// ends `unstable` as before when it is stopped.
    Unstable,
}

/// What `--break` accepts, for the error of one it does not.
pub const BREAK_FORMS: &str = "`t>=SECONDS`, `step=N`, `max_penetration>METRES` or `unstable`";

impl std::str::FromStr for BreakCondition {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        let s: String = text.chars().filter(|c| !c.is_whitespace()).collect();
        let bad = |why: &str| format!("--break `{text}`: {why}; use {BREAK_FORMS}");
        let number = |v: &str| -> Result<f64, String> {
            match v.parse::<f64>() {
                Ok(x) if x.is_finite() && x >= 0.0 => Ok(x),
                _ => Err(bad(&format!("`{v}` is not a non-negative number"))),
            }
        };
        if s == "unstable" {
            Ok(Self::Unstable)
        } else if let Some(v) = s.strip_prefix("t>=") {
            number(v).map(Self::TimeAtLeast)
        } else if let Some(v) = s.strip_prefix("step=") {
            match v.parse::<u64>() {
                Ok(n) if n >= 1 => Ok(Self::Step(n)),
                _ => Err(bad(&format!("`{v}` is not a step number (1, 2, …)"))),
            }
        } else if let Some(v) = s.strip_prefix("max_penetration>") {
            number(v).map(Self::MaxPenetrationAbove)
        } else {
            Err(bad("not a condition"))
        }
    }
}

impl std::fmt::Display for BreakCondition {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::TimeAtLeast(t) => write!(f, "t>={t}"),
            Self::Step(n) => write!(f, "step={n}"),
            Self::MaxPenetrationAbove(p) => write!(f, "max_penetration>{p}"),
            Self::Unstable => f.write_str("unstable"),
        }
    }
}

impl BreakCondition {
    /// Whether the condition holds at the end of coupling step `step` (time `t`, deepest penetration so far
    /// `max_penetration`). [`BreakCondition::Unstable`] never holds here: a blow-up is seen where it happens.
    pub fn holds(&self, step: u64, t: f64, max_penetration: f64) -> bool {
        match *self {
            Self::TimeAtLeast(at) => t >= at,
            Self::Step(n) => step >= n,
            Self::MaxPenetrationAbove(p) => max_penetration > p,
            Self::Unstable => false,
        }
    }
}

/// A command of `cosim ctl` (JSON on `cosim/<run>/broker/control`): `{"command":"pause"}`,
/// `{"command":"resume"}`, `{"command":"step","steps":10}`, `{"command":"stop"}`, or `{"command":"status"}`
/// (changes nothing).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "command", rename_all = "snake_case", deny_unknown_fields)]
pub enum ControlCommand {
    /// Pause after the step in progress.
    Pause,
    /// Go on from a pause.
    Resume,
    /// Take this many more coupling steps, then pause again.
    Step {
        /// Steps to take (at least 1).
        steps: u64,
    },
    /// End the run here, its outputs written, as Ctrl-C does (a run paused on `unstable` ends `unstable`).
    Stop,
    /// Only answer where the run is.
    Status,
}

/// The broker's answer to a [`ControlCommand`] (JSON).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ControlReply {
    /// Whether the command was taken.
    pub ok: bool,
    /// What was done, or why not.
    pub message: String,
    /// Last coupling step done.
    pub step: u64,
    /// Simulated time [s].
    pub t: f64,
    /// `paused at step N: REASON` while paused, else empty.
    pub paused: String,
}

/// Whose checkpoints a state query asks for: the selector parameter `nodes` of `cosim/<run>/broker/state`
/// (`docs/PROTOCOL.md` §11). Without it, every node's; `nodes=sph`, the fluid node's alone, as `cosim inspect
/// --particle` asks again where the structure node cannot save one (an outside program in its place): the whole query
/// failed with it before (found 2026-12-06 by the sweep of hostile external nodes, D25).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StateOf {
    /// Every node of the run.
    All,
    /// The fluid node alone; `fem` comes back empty.
    Fluid,
}

impl StateOf {
    /// The selector parameter's name.
    pub const PARAMETER: &'static str = "nodes";

    /// The selector's parameters that ask for `self` (`""` for every node).
    pub fn parameters(self) -> &'static str {
        match self {
            Self::All => "",
            Self::Fluid => "nodes=sph",
        }
    }

    /// From the parameter's value (`None`: absent).
    pub fn parse(value: Option<&str>) -> Result<Self, String> {
        match value {
            None | Some("all") => Ok(Self::All),
            Some("sph") => Ok(Self::Fluid),
            Some(other) => Err(format!("nodes={other}: ask for `all` or `sph`")),
        }
    }
}

/// The state of a run between two steps (`cosim/<run>/broker/state`, an envelope whose step and t are those of
/// the last step done): every node's checkpoint and the corrections of the last contact pass, still to be sent.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DebugState {
    /// `paused at step N: REASON`, or empty while running.
    pub paused: String,
    /// The structure node's checkpoint (its own format, `docs/PROTOCOL.md` §9); empty without a structure.
    pub fem: Vec<u8>,
    /// The fluid node's checkpoint; empty without a fluid.
    pub sph: Vec<u8>,
    /// Corrections of the last contact pass to the structure's nodes.
    pub fem_corrections: Vec<Correction>,
    /// Corrections of the last contact pass to the fluid's particles.
    pub sph_corrections: Vec<Correction>,
    /// Deepest penetration so far [m].
    pub max_penetration: f64,
    /// The contacts the last contact pass recorded, each (particle, master) pair it acted on, as the algorithm
    /// recorded them; `None` where the algorithm records none (`particle_particle`) or no pass ran since a restart.
    pub contacts: Option<Vec<ContactRecord>>,
}

/// One (particle, master) pair the last particle–element pass acted on (`docs/PROTOCOL.md` §11).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ContactRecord {
    /// Fluid particle id.
    pub particle: u32,
    /// The master: an interface segment (index into `fem/mesh` `interface`) ...
    pub segment: Option<u32>,
    /// ... or an interface node acting on its own (FE node id: convex corner, end of an open chain).
    pub node: Option<u32>,
    /// Gap g when the pass first acted on the pair [m] (negative: penetrating).
    pub gap: f64,
    /// Position multiplier λ applied to the pair, all sweeps [kg m] (`DESIGN.md` §4.5).
    pub lambda: f64,
    /// Velocity impulse J applied to the pair, all sweeps [kg m/s].
    pub impulse: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn break_conditions_parse_and_print_back() {
        for (text, want) in [
            ("t>=0.1", BreakCondition::TimeAtLeast(0.1)),
            ("t >= 0.1", BreakCondition::TimeAtLeast(0.1)),
            ("step=1200", BreakCondition::Step(1200)),
            ("max_penetration>1e-4", BreakCondition::MaxPenetrationAbove(1e-4)),
            ("unstable", BreakCondition::Unstable),
        ] {
            let got: BreakCondition = text.parse().unwrap();
            assert_eq!(got, want, "{text}");
            assert_eq!(got.to_string().parse::<BreakCondition>().unwrap(), want);
        }
    }

    #[test]
    fn a_bad_condition_is_refused_naming_it() {
        for text in [
            "t>0.1",
            "step=0",
            "step=-3",
            "t>=nan",
            "t>=-1",
            "max_penetration<1",
            "blowup",
            "",
        ] {
            let e = text.parse::<BreakCondition>().unwrap_err();
            assert!(e.contains(&format!("`{text}`")), "{e}");
            assert!(e.contains("unstable"), "lists the forms: {e}");
        }
    }

    #[test]
    fn conditions_hold_from_their_step_on() {
        assert!(!BreakCondition::TimeAtLeast(0.1).holds(5, 0.0999, 0.0));
        assert!(BreakCondition::TimeAtLeast(0.1).holds(6, 0.1, 0.0));
        assert!(BreakCondition::Step(3).holds(3, 0.0, 0.0));
        assert!(!BreakCondition::Step(3).holds(2, 0.0, 0.0));
        assert!(BreakCondition::MaxPenetrationAbove(1e-4).holds(1, 0.0, 2e-4));
        assert!(!BreakCondition::Unstable.holds(1, 1.0, 1.0));
    }

    #[test]
    fn commands_are_json_with_a_command_field() {
        let step: ControlCommand = serde_json::from_str(r#"{"command":"step","steps":10}"#).unwrap();
        assert_eq!(step, ControlCommand::Step { steps: 10 });
        assert_eq!(
            serde_json::to_string(&ControlCommand::Pause).unwrap(),
            r#"{"command":"pause"}"#
        );
        assert!(serde_json::from_str::<ControlCommand>(r#"{"command":"jump"}"#).is_err());
    }
}
