//! Pausing a run between two steps (`cosim run --break CONDITION`, `cosim ctl RUN pause|resume|step N|stop`;
//! `docs/PROTOCOL.md` §11). The coordinator calls [`Debugger::after_step`] once every node answered a step, its
//! contact pass ran and its outputs were written: the nodes then wait for their next command, so a pause holds the
//! whole run where it is, every process alive, and going on sends exactly the commands a run never paused sends —
//! pausing changes no bit of the run. Where the commands come from (a zenoh queryable in the broker) is the
//! [`Controller`]'s business; nothing here does I/O.

use std::time::Duration;

use cosim_proto::control::{BreakCondition, ContactRecord, ControlCommand, ControlReply, DebugState, StateOf};

use super::inputs::Nodes;
use crate::interface::Corrections;
use crate::link::LinkError;

/// How long one wait for a command lasts while paused (the controller checks its own stop signals in between).
pub const PAUSED_POLL: Duration = Duration::from_millis(50);

/// Why `step N` cannot be taken: no step, or more than any run may take ([`crate::step_budget::MAX_STEPS`]; `cosim
/// ctl RUN step 18446744073709551615` resumed the run and then said it "did not pause again", found 2026-12-06 by
/// the sweep of debug tools, D25). `cosim ctl` says it before it asks; the broker refuses it from any other client.
pub fn refuse_steps(steps: u64) -> Option<String> {
    use crate::step_budget::MAX_STEPS;
    match steps {
        0 => Some("step: give at least 1 step".into()),
        n if n as f64 > MAX_STEPS => Some(format!("step {n}: more than the {MAX_STEPS:e} steps a run may take")),
        _ => None,
    }
}

/// The run between two steps, as a paused run shows it.
pub struct Halt<'a, 'n> {
    /// Last coupling step done.
    pub step: u64,
    /// Simulated time [s].
    pub t: f64,
    /// Deepest penetration so far [m].
    pub max_penetration: f64,
    /// `paused at step N: REASON`, empty while running.
    pub paused: String,
    pending: &'a Corrections,
    contacts: Option<&'a [ContactRecord]>,
    nodes: &'a mut Nodes<'n>,
}

impl<'a, 'n> Halt<'a, 'n> {
    pub(super) fn new(
        step: u64,
        t: f64,
        max_penetration: f64,
        pending: &'a Corrections,
        contacts: Option<&'a [ContactRecord]>,
        nodes: &'a mut Nodes<'n>,
    ) -> Self {
        Self {
            step,
            t,
            max_penetration,
            paused: String::new(),
            pending,
            contacts,
            nodes,
        }
    }

    /// The nodes' state now (their checkpoints, asked for as a checkpoint asks: between two steps, read only; the
    /// structure's only where `of` asks for it) and the corrections of the last contact pass.
    pub fn state(&mut self, of: StateOf) -> Result<DebugState, LinkError> {
        let fem = match self.nodes.fem.as_deref_mut() {
            Some(link) if of == StateOf::All => link.checkpoint(self.step)?,
            _ => Vec::new(),
        };
        let sph = match self.nodes.sph.as_deref_mut() {
            Some(link) => link.checkpoint(self.step)?,
            None => Vec::new(),
        };
        Ok(DebugState {
            paused: self.paused.clone(),
            fem,
            sph,
            fem_corrections: self.pending.fem.clone(),
            sph_corrections: self.pending.sph.clone(),
            max_penetration: self.max_penetration,
            contacts: self.contacts.map(<[ContactRecord]>::to_vec),
        })
    }

    /// An answer to a command, saying where the run is.
    pub fn reply(&self, ok: bool, message: impl Into<String>) -> ControlReply {
        ControlReply {
            ok,
            message: message.into(),
            step: self.step,
            t: self.t,
            paused: self.paused.clone(),
        }
    }
}

/// Where the commands of a live run come from, and where its pause is shown.
pub trait Controller {
    /// The next command that came in, if any, waiting up to `wait` for one (`None`: do not wait). Requests for the
    /// run's state ([`Halt::state`]) are answered here, from `halt`, without a word to the debugger. A controller
    /// that sees its run must stop (a signal, a launcher gone) returns [`ControlCommand::Stop`].
    fn next(&mut self, halt: &mut Halt<'_, '_>, wait: Option<Duration>) -> Option<ControlCommand>;

    /// The answer to the command [`Controller::next`] returned last.
    fn answer(&mut self, reply: ControlReply);

    /// The run paused (`line` is `paused at step N: REASON`) or went on (`line` empty).
    fn show(&mut self, line: &str);

    /// Why a paused run must stop now, if it must: a signal, or whoever launched it gone. Asked while paused
    /// (a running run hears of these through its progress callback).
    fn must_stop(&mut self) -> Option<String> {
        None
    }
}

enum Mode {
    Running,
    Paused(String),
    /// Steps still to take, and how many were asked for.
    Stepping(u64, u64),
}

/// A run's pause state: its break condition, whether it is paused, and the controller it takes commands from.
pub struct Debugger<'c> {
    break_on: Option<BreakCondition>,
    hit: bool,
    mode: Mode,
    controller: &'c mut dyn Controller,
}

/// Why a run stopped from its controller.
pub const STOPPED: &str = "stopped by `cosim ctl stop`";

impl<'c> Debugger<'c> {
    /// Pause when `break_on` first holds (never without one); commands from `controller`.
    pub fn new(break_on: Option<BreakCondition>, controller: &'c mut dyn Controller) -> Self {
        Self {
            break_on,
            hit: false,
            mode: Mode::Running,
            controller,
        }
    }

    /// Whether a blow-up pauses the run instead of ending it.
    pub fn breaks_on_unstable(&self) -> bool {
        self.break_on == Some(BreakCondition::Unstable)
    }

    /// After a step: pause where the break condition first holds or the steps asked for are taken, take the
    /// commands that came in, and wait while paused. `Err(reason)` stops the run.
    pub fn after_step(&mut self, halt: &mut Halt<'_, '_>) -> Result<(), String> {
        if let Mode::Stepping(left, asked) = self.mode {
            self.mode = match left {
                0 | 1 => Mode::Paused(format!("`step {asked}` done")),
                _ => Mode::Stepping(left - 1, asked),
            };
        }
        if let Some(cond) = self
            .break_on
            .filter(|c| !self.hit && c.holds(halt.step, halt.t, halt.max_penetration))
        {
            self.hit = true;
            self.mode = Mode::Paused(cond.to_string());
        }
        let mut shown = false;
        loop {
            let paused = match &self.mode {
                Mode::Paused(reason) => Some(format!("paused at step {}: {reason}", halt.step)),
                _ => None,
            };
            match (&paused, shown) {
                (Some(line), false) => {
                    halt.paused = line.clone();
                    self.controller.show(line);
                    shown = true;
                }
                (None, true) => {
                    halt.paused.clear();
                    self.controller.show("");
                    shown = false;
                }
                _ => {}
            }
            if paused.is_some() {
                if let Some(why) = self.controller.must_stop() {
                    return Err(why);
                }
            }
            let Some(command) = self.controller.next(halt, paused.is_some().then_some(PAUSED_POLL)) else {
                match paused {
                    Some(_) => continue,
                    None => return Ok(()),
                }
            };
            let reply = match command {
                ControlCommand::Pause => {
                    if paused.is_none() {
                        self.mode = Mode::Paused("paused by `cosim ctl pause`".into());
                    }
                    halt.reply(true, "paused")
                }
                ControlCommand::Resume => {
                    self.mode = Mode::Running;
                    halt.paused.clear();
                    halt.reply(true, "resumed")
                }
                ControlCommand::Step { steps } => match refuse_steps(steps) {
                    Some(why) => halt.reply(false, why),
                    None => {
                        self.mode = Mode::Stepping(steps, steps);
                        halt.paused.clear();
                        halt.reply(true, format!("taking {steps} step(s)"))
                    }
                },
                ControlCommand::Status => halt.reply(true, "status"),
                ControlCommand::Stop => {
                    self.controller.answer(halt.reply(true, "stopping"));
                    return Err(STOPPED.into());
                }
            };
            self.controller.answer(reply);
        }
    }

    /// A node blew up (`message`): with `--break unstable` the run pauses here, every process alive, until it is
    /// stopped (it cannot go on); the caller then ends it `unstable` as before.
    pub fn on_unstable(&mut self, halt: &mut Halt<'_, '_>, message: &str) {
        if !self.breaks_on_unstable() {
            return;
        }
        let line = format!("paused at step {}: unstable: {message}", halt.step);
        halt.paused = line.clone();
        self.controller.show(&line);
        loop {
            if self.controller.must_stop().is_some() {
                return;
            }
            let Some(command) = self.controller.next(halt, Some(PAUSED_POLL)) else {
                continue;
            };
            let reply = match command {
                ControlCommand::Stop => {
                    self.controller.answer(halt.reply(true, "stopping"));
                    return;
                }
                ControlCommand::Pause | ControlCommand::Status => halt.reply(true, "paused"),
                ControlCommand::Resume | ControlCommand::Step { .. } => halt.reply(
                    false,
                    "the run went unstable: it cannot go on; look inside it, then stop it (`cosim ctl RUN stop`)",
                ),
            };
            self.controller.answer(reply);
        }
    }
}

#[cfg(test)]
mod tests {
    use std::collections::VecDeque;

    use super::*;

    /// Commands handed out one per call, the pauses shown and the answers given.
    #[derive(Default)]
    struct Script {
        commands: VecDeque<ControlCommand>,
        shown: Vec<String>,
        answers: Vec<ControlReply>,
    }

    impl Controller for Script {
        fn next(&mut self, _halt: &mut Halt<'_, '_>, wait: Option<Duration>) -> Option<ControlCommand> {
            // A running run is only told to pause; the rest comes while it is paused.
            if wait.is_none() && self.commands.front() != Some(&ControlCommand::Pause) {
                return None;
            }
            let next = self.commands.pop_front();
            // A paused run with nothing left to say would wait for ever: a script must end it.
            assert!(next.is_some() || wait.is_none(), "paused with no command left");
            next
        }
        fn answer(&mut self, reply: ControlReply) {
            self.answers.push(reply);
        }
        fn show(&mut self, line: &str) {
            self.shown.push(line.to_string());
        }
    }

    /// Steps 1, 2, … at 0.01 s each through the debugger, until it stops the run or `last` is done; the step it
    /// stopped at, if it did.
    fn drive(debugger: &mut Debugger<'_>, last: u64) -> Option<u64> {
        let pending = Corrections::default();
        for step in 1..=last {
            let mut nodes = Nodes { fem: None, sph: None };
            let mut halt = Halt::new(step, 0.01 * step as f64, 0.0, &pending, None, &mut nodes);
            if debugger.after_step(&mut halt).is_err() {
                return Some(step);
            }
        }
        None
    }

    #[test]
    fn a_break_pauses_once_and_step_n_takes_exactly_n_steps() {
        let mut script = Script {
            // Paused at step 3 (t >= 0.025): 2 steps, then resume; nothing more to say after.
            commands: [ControlCommand::Step { steps: 2 }, ControlCommand::Resume].into(),
            ..Script::default()
        };
        let mut debugger = Debugger::new(Some(BreakCondition::TimeAtLeast(0.025)), &mut script);
        assert_eq!(drive(&mut debugger, 10), None);
        assert_eq!(
            script.shown,
            ["paused at step 3: t>=0.025", "", "paused at step 5: `step 2` done", ""]
        );
        assert_eq!(script.answers.len(), 2);
        assert!(script.answers.iter().all(|a| a.ok && a.paused.is_empty()));
        assert_eq!((script.answers[0].step, script.answers[1].step), (3, 5));
    }

    #[test]
    fn stop_ends_the_run_and_step_zero_is_refused() {
        let mut script = Script {
            commands: [
                ControlCommand::Pause,
                ControlCommand::Step { steps: 0 },
                ControlCommand::Step { steps: u64::MAX },
                ControlCommand::Status,
                ControlCommand::Stop,
            ]
            .into(),
            ..Script::default()
        };
        let mut debugger = Debugger::new(None, &mut script);
        assert_eq!(drive(&mut debugger, 10), Some(1));
        let oks: Vec<bool> = script.answers.iter().map(|a| a.ok).collect();
        assert_eq!(oks, [true, false, false, true, true]);
        assert_eq!(
            script.answers[2].message,
            "step 18446744073709551615: more than the 1e12 steps a run may take"
        );
        assert_eq!(
            script.answers[2].paused,
            "paused at step 1: paused by `cosim ctl pause`"
        );
        assert_eq!(script.shown, ["paused at step 1: paused by `cosim ctl pause`"]);
    }

    /// `nodes=sph` (`StateOf::Fluid`): the fluid's checkpoint alone, where the structure node cannot save one (an
    /// outside program), which makes the whole state fail.
    #[test]
    fn the_fluids_state_alone_is_given_where_the_structure_cannot_checkpoint() {
        use cosim_proto::messages::{FemMesh, FemState, SphSetup, SphState};

        use crate::link::InProcess;

        let mesh = FemMesh {
            solid_names: vec!["plate".into()],
            nodes: vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
            masses: vec![1.0; 3],
            node_solid: vec![0; 3],
            cells: vec![vec![0, 1, 2]],
            cell_solid: vec![0],
            interface: Vec::new(),
            fixed: Vec::new(),
            dt_stable: 1e-4,
        };
        let setup = SphSetup {
            particles: 1,
            spacing: 0.01,
            h: 0.013,
            density: 1000.0,
            walls: Vec::new(),
            dt_stable: 1e-4,
            sensors: 0,
        };
        // A structure without a checkpoint, as an outside node's link is; a fluid that saves three bytes.
        let mut fem = InProcess::<FemMesh, FemState>::new(mesh, |_| Ok(None));
        let mut sph = InProcess::<SphSetup, SphState>::new(setup, |_| Ok(None)).with_checkpoint(|| Ok(vec![1, 2, 3]));
        let mut nodes = Nodes {
            fem: Some(&mut fem),
            sph: Some(&mut sph),
        };
        let pending = Corrections::default();
        let mut halt = Halt::new(4, 0.04, 0.0, &pending, None, &mut nodes);
        let whole = halt.state(StateOf::All).unwrap_err().to_string();
        assert!(whole.contains("cannot save a checkpoint"), "{whole}");
        let fluid = halt.state(StateOf::Fluid).unwrap();
        assert_eq!((fluid.fem, fluid.sph), (Vec::new(), vec![1, 2, 3]));
        assert_eq!(
            StateOf::parse(Some(StateOf::Fluid.parameters().trim_start_matches("nodes="))),
            Ok(StateOf::Fluid)
        );
        assert_eq!(StateOf::parse(None), Ok(StateOf::All));
        assert_eq!(
            StateOf::parse(Some("fem")),
            Err("nodes=fem: ask for `all` or `sph`".into())
        );
    }

    #[test]
    fn an_unstable_run_pauses_only_with_break_unstable_and_cannot_go_on() {
        let pending = Corrections::default();
        let mut nodes = Nodes { fem: None, sph: None };
        let mut halt = Halt::new(7, 0.07, 0.0, &pending, None, &mut nodes);
        let mut quiet = Script::default();
        Debugger::new(Some(BreakCondition::Step(3)), &mut quiet).on_unstable(&mut halt, "blew up");
        assert!(quiet.shown.is_empty() && quiet.answers.is_empty());
        let mut script = Script {
            commands: [ControlCommand::Resume, ControlCommand::Stop].into(),
            ..Script::default()
        };
        Debugger::new(Some(BreakCondition::Unstable), &mut script).on_unstable(&mut halt, "blew up");
        assert_eq!(script.shown, ["paused at step 7: unstable: blew up"]);
        let oks: Vec<bool> = script.answers.iter().map(|a| a.ok).collect();
        assert_eq!(oks, [false, true]);
    }
}
