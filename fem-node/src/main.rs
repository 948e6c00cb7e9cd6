//! `fem-node`: the structure solver as its own process (`fem-node --run ID --connect ENDPOINT`).

use cosim_bus::serve::{Failure, NodeCore};
use cosim_proto::messages::{FemMesh, FemState, StepCommand};
use cosim_proto::sizing::Part;
use fem_node::core::FemCore;

/// Test double for `cosim replay` (`cosim/tests/replay.rs`): with `COSIM_TEST_PERTURB_STEP=K` in its environment the
/// node answers its K-th command (step K of a run started from the scene) with its first reported position one ulp
/// off, and is otherwise the real node; with `COSIM_TEST_NAN_SECONDS_STEP=K`, its `compute_seconds` NaN there. Unset,
/// nothing changes.
const PERTURB: &str = "COSIM_TEST_PERTURB_STEP";
const NAN_SECONDS: &str = "COSIM_TEST_NAN_SECONDS_STEP";

fn main() {
    let step = |var: &str| std::env::var(var).ok().and_then(|v| v.parse::<u64>().ok());
    let (perturb, nan_seconds) = (step(PERTURB), step(NAN_SECONDS));
    cosim_bus::cli::node_main(cosim_proto::keys::FEM, |scene| {
        // Sized before anything is built: a scene too big for this machine fails with one line, not an abort.
        cosim_bus::memory::node_fits(scene, Part::Structure)?;
        let core = FemCore::new(scene).map_err(Failure::from)?;
        Ok(Perturbed {
            core,
            at: perturb,
            nan_seconds,
            answered: 0,
        })
    })
}

/// The node, one value of one answer off when asked to be ([`PERTURB`]).
struct Perturbed {
    core: FemCore,
    at: Option<u64>,
    nan_seconds: Option<u64>,
    answered: u64,
}

impl NodeCore for Perturbed {
    type Setup = FemMesh;
    type State = FemState;

    fn setup(&self) -> &FemMesh {
        self.core.mesh()
    }

    fn handle(&mut self, cmd: &StepCommand) -> Result<Option<FemState>, Failure> {
        let mut state = self.core.handle(cmd).map_err(Failure::from)?;
        if let (Some(s), Some(x)) = (state.as_mut(), self.at.filter(|&k| k == self.answered)) {
            eprintln!("fem-node: {PERTURB}={x}: answering with x[0][0] one ulp off");
            if let Some(p) = s.x.first_mut() {
                p[0] = f64::from_bits(p[0].to_bits() + 1);
            }
        }
        if let (Some(s), Some(_)) = (state.as_mut(), self.nan_seconds.filter(|&k| k == self.answered)) {
            eprintln!("fem-node: {NAN_SECONDS}: answering with compute_seconds NaN");
            s.compute_seconds = f64::NAN;
        }
        self.answered += 1;
        Ok(state)
    }

    fn counts(&self) -> Vec<(&'static str, u64)> {
        NodeCore::counts(&self.core)
    }

    fn energy(&self) -> Vec<(&'static str, f64)> {
        NodeCore::energy(&self.core)
    }

    fn checkpoint(&self) -> Option<Vec<u8>> {
        NodeCore::checkpoint(&self.core)
    }

    fn restore(&mut self, data: &[u8]) -> Result<(), Failure> {
        NodeCore::restore(&mut self.core, data)
    }
}
