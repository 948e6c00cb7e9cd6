//! Run one case as a child `cosim bench-run` process (`cosim run --in-process` that reports its peak resident
//! memory), bounded in time, and turn its `summary.json` and `probes.csv` into a [`Record`].

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use anyhow::Context;
use contact_broker::summary::Summary;
use serde::{Deserialize, Serialize};

use super::metrics;
use super::record::Record;
use super::suite::Case;

/// File the child writes its [`ProcessStats`] to, in its output folder.
pub const STATS_FILE: &str = "bench_process.json";
/// The child's stdout and stderr, in its output folder.
pub const LOG_FILE: &str = "bench.log";

/// Run `case` with its outputs in `out`; `scenes` holds the reference data. Never fails: a case that cannot run
/// is a record with status `failed` or `timeout`.
pub fn run_case(case: &Case, out: &Path, scenes: &Path, limit: Duration) -> Record {
    let started = Instant::now();
    let outcome = spawn_and_wait(case, out, limit);
    let process_seconds = started.elapsed().as_secs_f64();
    let summary: Option<Summary> = std::fs::read_to_string(out.join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok());
    let stats: ProcessStats = std::fs::read_to_string(out.join(STATS_FILE))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok())
        .unwrap_or_default();
    let mut record = Record {
        case: case.case.into(),
        variant: case.variant.into(),
        solver: case.solver.into(),
        contact: case.contact.into(),
        spacing: case.spacing,
        threads: case.threads.unwrap_or_else(rayon::current_num_threads),
        repeats: 1,
        particles: 0,
        steps: 0,
        coupling_steps: 0,
        sim_time: 0.0,
        end_time: case.end_time,
        wall_seconds: process_seconds,
        process_seconds,
        particle_steps_per_second: 0.0,
        sph_seconds: 0.0,
        sph_ns_per_particle_step: 0.0,
        error: None,
        error_max: None,
        value: None,
        reference: None,
        energy_growth: None,
        energy_made: None,
        energy_drift: None,
        sensors: Vec::new(),
        metric: super::suite::describe(case.metric).into(),
        peak_rss_bytes: stats.peak_rss_bytes,
        cpu_seconds: stats.cpu_seconds,
        load_average: None,
        status: "failed".into(),
        message: String::new(),
        sets: case.sets(),
        out: out.display().to_string(),
    };
    if let Some(s) = &summary {
        let particle_steps = (s.particles * s.sph_substeps) as f64;
        record.particles = s.particles;
        record.steps = s.sph_substeps;
        record.coupling_steps = s.steps;
        record.sim_time = s.sim_time;
        record.wall_seconds = s.wall_seconds;
        record.particle_steps_per_second = particle_steps / s.wall_seconds.max(1e-9);
        record.sph_seconds = s.timings.sph;
        record.sph_ns_per_particle_step = 1e9 * s.timings.sph / particle_steps.max(1.0);
        record.status = s.status.to_string();
        record.message = s.message.clone();
        record.energy_made = s.energy_growth.as_ref().map(|g| g.largest);
    }
    match outcome {
        Outcome::TimedOut => {
            record.status = "timeout".into();
            record.message = format!("stopped after {} s (the case's time limit)", limit.as_secs());
        }
        Outcome::Failed(message) => {
            record.status = "failed".into();
            record.message = message;
        }
        Outcome::Exited if summary.is_none() => {
            record.message = format!("no summary.json; see {}", out.join(LOG_FILE).display());
        }
        Outcome::Exited => {}
    }
    if case.metric == super::suite::Metric::Stress && summary.is_some() {
        // Whatever the status: a run a guard stopped has its energy up to the stop.
        match metrics::measure(case.metric, out, scenes, case.spacing) {
            Ok(m) => {
                record.energy_growth = m.energy_growth;
                record.energy_drift = m.energy_drift;
            }
            Err(e) if record.status == "ok" => {
                record.status = "failed".into();
                record.message = format!("cannot measure: {e:#}");
            }
            Err(_) => {}
        }
        if record.status == "ok" && !record.energy_growth.is_some_and(f64::is_finite) {
            record.status = "failed".into();
            record.message = "status ok but the energy is not finite".into();
        }
    } else if record.status == "ok" {
        match metrics::measure(case.metric, out, scenes, case.spacing) {
            Ok(m) => {
                record.error = m.error;
                record.error_max = m.error_max;
                record.value = m.value;
                record.reference = m.reference;
                record.sensors = m.sensors;
                if m.error.is_some_and(|e| !e.is_finite()) {
                    record.status = "failed".into();
                    record.message = "the error is not finite".into();
                }
            }
            Err(e) => {
                record.status = "failed".into();
                record.message = format!("cannot measure: {e:#}");
            }
        }
    }
    record
}

enum Outcome {
    Exited,
    TimedOut,
    Failed(String),
}

fn spawn_and_wait(case: &Case, out: &Path, limit: Duration) -> Outcome {
    match spawn(case, out) {
        Ok(mut child) => {
            let until = Instant::now() + limit;
            loop {
                match child.try_wait() {
                    Ok(Some(_)) => return Outcome::Exited,
                    Ok(None) if Instant::now() >= until => {
                        let _ = child.kill();
                        let _ = child.wait();
                        return Outcome::TimedOut;
                    }
                    Ok(None) => std::thread::sleep(Duration::from_millis(50)),
                    Err(e) => return Outcome::Failed(format!("waiting for the run: {e}")),
                }
            }
        }
        Err(e) => Outcome::Failed(format!("{e:#}")),
    }
}

/// Environment variable through which the bench gives a case its own pid (see `bench_run`).
pub const PARENT_ENV: &str = "COSIM_BENCH_PARENT";

fn spawn(case: &Case, out: &Path) -> anyhow::Result<std::process::Child> {
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    for stale in ["summary.json", STATS_FILE] {
        let _ = std::fs::remove_file(out.join(stale));
    }
    let log = std::fs::File::create(out.join(LOG_FILE)).context("cannot create the case's log")?;
    // This very executable, even when a rebuild has replaced the file since the bench started.
    let exe: PathBuf = match Path::new("/proc/self/exe") {
        p if p.exists() => p.to_path_buf(),
        _ => std::env::current_exe().context("cannot find the cosim executable")?,
    };
    let mut cmd = Command::new(exe);
    cmd.arg("bench-run")
        .arg(&case.scene)
        .arg("--out")
        .arg(out)
        .args([
            "--in-process",
            "--quiet",
            "--run-id",
            &format!("bench-{}", std::process::id()),
        ])
        .arg("--stats-out")
        .arg(out.join(STATS_FILE));
    if let Some(n) = case.threads {
        cmd.args(["--threads", &n.to_string()]);
    }
    for set in case.sets() {
        cmd.args(["--set", &set]);
    }
    // The case stops when the bench does (`bench_run`), even when the bench is killed outright.
    cmd.env(PARENT_ENV, std::process::id().to_string());
    cmd.stdin(Stdio::null())
        .stdout(log.try_clone()?)
        .stderr(log)
        .spawn()
        .context("cannot start the case")
}

/// What the child measures of itself as it ends.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct ProcessStats {
    /// Peak resident set size (VmHWM of `/proc/self/status`) [bytes].
    pub peak_rss_bytes: Option<u64>,
    /// CPU time of all the process's threads, from `/proc/self/task/*/schedstat` (time on a CPU, so not the time
    /// spent waiting for a core another program holds; idle rayon workers spinning do count) [s].
    pub cpu_seconds: Option<f64>,
}

impl ProcessStats {
    /// This process's figures; `None` fields where there is no procfs.
    pub fn of_this_process() -> Self {
        Self {
            peak_rss_bytes: peak_rss_bytes(),
            cpu_seconds: cpu_seconds(),
        }
    }
}

fn peak_rss_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line
        .trim_start_matches("VmHWM:")
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    Some(kb * 1024)
}

fn cpu_seconds() -> Option<f64> {
    let mut ns = 0u64;
    for task in std::fs::read_dir("/proc/self/task").ok()? {
        let stat = std::fs::read_to_string(task.ok()?.path().join("schedstat")).ok()?;
        ns += stat.split_whitespace().next()?.parse::<u64>().ok()?;
    }
    Some(ns as f64 * 1e-9)
}
