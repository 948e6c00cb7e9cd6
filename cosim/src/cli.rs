//! Command-line arguments (`DESIGN.md` §5, the run contract).

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};

/// FEM–SPH fluid–structure co-simulation over zenoh.
#[derive(Parser, Debug)]
#[command(version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Run a scene: by default contact-broker and the solver nodes as separate processes over zenoh.
    Run(RunArgs),
    /// Validate a scene and print what would run.
    Check(CheckArgs),
    /// Draw one probe of several finished runs in one plot (and print its extremes per run).
    Compare(CompareArgs),
    /// Show the live status of every process of a running run (a table that refreshes, or `--once` as JSON).
    Inspect(InspectArgs),
    /// Run the benchmark suite: run time, memory and error of the validation scenes at several spacings, and
    /// cost per particle-step at four sizes (writes DIR/bench.json, DIR/report.md, DIR/pareto.svg).
    Bench(BenchArgs),
    /// Serve as a zenoh router (the one `zenohd` runs) until killed: the hub of a run spread over hosts, which every
    /// process joins with `--connect ENDPOINT --client`.
    Router(RouterArgs),
    /// Run one node alone on the commands of a recorded run (`cosim run --record`) and compare its answers with
    /// the recorded ones: the first divergence is named (exit 1), else "matched N steps".
    Replay(ReplayArgs),
    /// One case of `cosim bench`: `cosim run` that also writes its peak resident memory and CPU time to a file.
    #[command(hide = true)]
    BenchRun(BenchRunArgs),
    /// Pause, resume, step or stop a live run (`cosim ctl RUN pause|resume|step [N]|stop|status`).
    Ctl(CtlArgs),
    /// Write the current state of a live run (particles, mesh, the last contact pass) as ParaView frames.
    Snapshot(SnapshotArgs),
}

/// `cosim ctl`.
#[derive(Args, Debug, Clone)]
pub struct CtlArgs {
    /// Run id.
    pub id: String,
    /// What to do.
    #[arg(value_enum)]
    pub action: CtlAction,
    /// Steps to take, with `step` (default 1).
    pub steps: Option<u64>,
    /// How to reach the run.
    #[command(flatten)]
    pub join: crate::join::JoinArgs,
}

/// What `cosim ctl` asks of a run.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum CtlAction {
    /// Pause after the step in progress (every process stays alive).
    Pause,
    /// Go on from a pause.
    Resume,
    /// Take N steps (default 1), then pause again; waits until they are taken.
    Step,
    /// End the run here, its outputs written (as Ctrl-C does).
    Stop,
    /// Say where the run is and whether it is paused.
    Status,
}

/// `cosim snapshot`.
#[derive(Args, Debug, Clone)]
pub struct SnapshotArgs {
    /// Run id.
    pub id: String,
    /// Folder to write the frames into (`DIR/frames/`).
    #[arg(long)]
    pub out: PathBuf,
    /// How to reach the run.
    #[command(flatten)]
    pub join: crate::join::JoinArgs,
}

/// `cosim run`.
#[derive(Args, Debug, Clone)]
pub struct RunArgs {
    /// Scene file (TOML).
    pub scene: PathBuf,
    /// Output folder (default `out/<run.name>`).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Run every node in this process instead of separate processes.
    #[arg(long)]
    pub in_process: bool,
    /// Override a scene key, `key.path=value` (repeatable), e.g. `--set run.end_time=0.1`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Run id (default: a fresh one).
    #[arg(long)]
    pub run_id: Option<String>,
    /// Connect every node to this zenoh router (e.g. `zenohd`) as a zenoh client instead of peer-to-peer on loopback.
    #[arg(long, value_parser = cosim_bus::session::endpoint)]
    pub connect: Option<String>,
    /// Worker threads per node (default: all cores; 1 to 1024).
    #[arg(long, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..=1024))]
    pub threads: Option<usize>,
    /// A zenoh JSON5 config file (user and password, TLS certificates, …) given to every process started, as
    /// their `--zenoh-config`; their own settings (mode, endpoints, multicast scouting off) go on top of it.
    /// Checked, but unused, with `--in-process`.
    #[arg(long, value_name = "FILE")]
    pub zenoh_config: Option<PathBuf>,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
    /// Start every node but this one and wait for an outside program that speaks `docs/PROTOCOL.md` to join in
    /// its place; the run id and the endpoint to give it are printed and written to `DIR/external.json`.
    #[arg(long, value_enum, value_name = "NODE")]
    pub external: Option<ExternalNode>,
    /// Seconds to wait for the external node to register (with `--external`).
    #[arg(long, value_parser = cosim_bus::seconds::positive, default_value_t = 300.0, value_name = "SECONDS")]
    pub wait_external: f64,
    /// Write a checkpoint, `DIR/checkpoints/<step>/` (every node's state, the broker's, the scene), every this
    /// many seconds of simulated time.
    #[arg(long, value_name = "SECONDS")]
    pub checkpoint_interval: Option<f64>,
    /// Continue from a checkpoint folder, `DIR/checkpoints/<step>`, instead of from the start: the scene must be
    /// the one it was written with (only `run.end_time` may differ).
    #[arg(long, value_name = "CHECKPOINT")]
    pub restart: Option<PathBuf>,
    /// Start even where the outputs (frames, probes, checkpoints; `cosim check` prints their size) are estimated
    /// larger than the free space of the output folder's disk: a file system that compresses them, or frames moved
    /// away as they come. Without it such a run is refused (exit 2) rather than failed when the disk is full.
    #[arg(long)]
    pub ignore_disk_space: bool,
    /// Files a launcher put into the output folder before the run (`cosim bench`'s case log): not the user's own,
    /// so the folder is still taken (`contact_broker::output::folder`). Not a command-line option.
    #[arg(skip)]
    pub beside: Vec<String>,
    /// Keep every message of the run (setup, commands, states, with their envelopes) in `DIR/trace/`, for
    /// `cosim replay` (format: `docs/PROTOCOL.md` §10).
    #[arg(long)]
    pub record: bool,
    /// Pause the run, every process alive, when CONDITION first holds: `t>=SECONDS`, `step=N`,
    /// `max_penetration>METRES` or `unstable` (a blow-up pauses instead of ending the run); go on with `cosim ctl`.
    #[arg(long = "break", value_name = "CONDITION")]
    pub break_on: Option<cosim_proto::control::BreakCondition>,
}

/// A node an outside program can take the place of.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExternalNode {
    /// The structure node (`fem-node`).
    Fem,
    /// The fluid node (`sph-node`).
    Sph,
}

impl ExternalNode {
    /// The program it stands in for.
    pub fn program(self) -> &'static str {
        match self {
            Self::Fem => "fem-node",
            Self::Sph => "sph-node",
        }
    }

    /// The name used in `--external` and `external.json`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Fem => "fem",
            Self::Sph => "sph",
        }
    }
}

/// `cosim check`.
#[derive(Args, Debug, Clone)]
pub struct CheckArgs {
    /// Scene file (TOML).
    pub scene: PathBuf,
    /// Override a scene key, `key.path=value` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Print one JSON document instead of text.
    #[arg(long)]
    pub json: bool,
    /// Count the checkpoints `cosim run --checkpoint-interval SECONDS` would write in the disk estimate.
    #[arg(long, value_name = "SECONDS")]
    pub checkpoint_interval: Option<f64>,
}

/// `cosim compare`.
#[derive(Args, Debug, Clone)]
pub struct CompareArgs {
    /// Output folders of finished runs (each with a probes.csv); `LABEL=DIR` names the curve.
    #[arg(required = true)]
    pub runs: Vec<String>,
    /// The probe (column of probes.csv) to draw.
    #[arg(long)]
    pub probe: String,
    /// SVG file to write.
    #[arg(long)]
    pub out: PathBuf,
}

/// `cosim bench`.
#[derive(Args, Debug, Clone)]
pub struct BenchArgs {
    /// The quick suite: coarse spacings and short end times (under 10 minutes on 2 cores).
    #[arg(long)]
    pub quick: bool,
    /// Output folder: bench.json, report.md, pareto.svg, and each case's run under runs/.
    #[arg(long)]
    pub out: PathBuf,
    /// Run only these cases (dam_break, hydrostatic_plate, elastic_gate, lobovsky_dam_break, scaling, stress;
    /// repeatable or comma-separated).
    #[arg(long, value_delimiter = ',')]
    pub only: Vec<String>,
    /// Run only these fluid solvers (wcsph, isph).
    #[arg(long, value_delimiter = ',')]
    pub solver: Vec<String>,
    /// Run the gate only with these contact algorithms (particle_element, particle_particle).
    #[arg(long, value_delimiter = ',')]
    pub contact: Vec<String>,
    /// Replace the suite's spacings [m] of every case but scaling and stress.
    #[arg(long, value_delimiter = ',')]
    pub spacing: Vec<f64>,
    /// Replace the suite's end time [s] of every case but scaling and stress.
    #[arg(long)]
    pub end_time: Option<f64>,
    /// Folder of the scenes and their reference data.
    #[arg(long, default_value = "scenes")]
    pub scenes: PathBuf,
    /// Stop a case after this many seconds (default 300 quick, 3600 full); it is recorded as `timeout`.
    #[arg(long)]
    pub case_timeout: Option<u64>,
}

/// `cosim bench-run`.
#[derive(Args, Debug, Clone)]
pub struct BenchRunArgs {
    /// The run.
    #[command(flatten)]
    pub run: RunArgs,
    /// File to write the process's peak resident memory and CPU time to (JSON).
    #[arg(long)]
    pub stats_out: PathBuf,
}

/// `cosim inspect`.
#[derive(Args, Debug, Clone)]
pub struct InspectArgs {
    /// Run id (printed by `cosim run`, and in `DIR/summary.json`); without it, the runs on this machine are listed.
    pub id: Option<String>,
    /// Print one JSON document with every process's status and exit.
    #[arg(long)]
    pub once: bool,
    /// Endpoint of the run (its broker's, or the router's) for a run on another host; a run on this machine is
    /// found without it.
    #[arg(long, value_parser = cosim_bus::session::endpoint)]
    pub connect: Option<String>,
    /// `--connect` is a zenoh router: join through it as a client.
    #[arg(long)]
    pub client: bool,
    /// A zenoh JSON5 config file the session starts from (as the run's `--zenoh-config`).
    #[arg(long, value_name = "FILE")]
    pub zenoh_config: Option<PathBuf>,
    /// Seconds to wait for the answers.
    #[arg(long, value_parser = cosim_bus::seconds::positive, default_value_t = 2.0)]
    pub timeout: f64,
    /// Seconds between refreshes of the table.
    #[arg(long, value_parser = cosim_bus::seconds::positive, default_value_t = 1.0)]
    pub interval: f64,
    /// Print one fluid particle's state (position, velocity, density, pressure, mass, neighbours, last contact
    /// correction) as JSON and exit.
    #[arg(long, value_name = "ID", conflicts_with = "node")]
    pub particle: Option<u32>,
    /// Print one FE node's state (position, velocity, displacement, interface segments, last contact correction)
    /// as JSON and exit.
    #[arg(long, value_name = "ID")]
    pub node: Option<u32>,
}

/// `cosim router`.
#[derive(Args, Debug, Clone)]
pub struct RouterArgs {
    /// Endpoints to listen on (repeatable), e.g. `tcp/0.0.0.0:7447`, `tls/0.0.0.0:7447`.
    #[arg(long, required = true, value_parser = cosim_bus::session::endpoint)]
    pub listen: Vec<String>,
    /// A zenoh JSON5 config file the router starts from (a user/password dictionary, TLS certificates, …); mode,
    /// listen endpoints and multicast scouting off are put on top of it.
    #[arg(long, value_name = "FILE")]
    pub zenoh_config: Option<PathBuf>,
}

/// `cosim replay`.
#[derive(Args, Debug, Clone)]
pub struct ReplayArgs {
    /// The trace: `DIR/trace` of a run made with `--record` (or the `trace.bin` file in it).
    pub trace: PathBuf,
    /// The node to run again.
    #[arg(long, value_enum)]
    pub node: ExternalNode,
    /// Run this program in the node's place instead of the built-in one: a shell command line, run as `sh -c
    /// 'COMMAND "$@"'` with `--run ID --connect ENDPOINT` as `"$@"`, so they go to its last simple command, which must
    /// be the node: `python3 node.py`, `cd dir && ./node`, `env X=1 ./node` (no trailing `;`, `&` or `# comment`).
    #[arg(long, value_name = "COMMAND")]
    pub exec: Option<String>,
    /// Compare numbers within this relative tolerance instead of byte for byte: |replayed − recorded| ≤ atol +
    /// rtol·|recorded|.
    #[arg(long, value_name = "R")]
    pub rtol: Option<f64>,
    /// Absolute tolerance (with or without `--rtol`).
    #[arg(long, value_name = "A")]
    pub atol: Option<f64>,
    /// Seconds to wait for the node to register, and for each of its answers.
    #[arg(long, value_parser = cosim_bus::seconds::positive, default_value_t = 60.0, value_name = "SECONDS")]
    pub timeout: f64,
    /// File for the node's log (stderr); default: a file in the temporary folder, named when the replay fails.
    #[arg(long, value_name = "FILE")]
    pub log: Option<PathBuf>,
}
