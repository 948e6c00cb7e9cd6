//! `cosim bench [--quick] --out DIR`: the suite of validation scenes at several spacings, solvers and contact
//! algorithms, each measured for run time, memory and error against its reference, plus a scaling series
//! (issue 5). Writes `DIR/bench.json` ([`record`]), `DIR/report.md` ([`report`]), `DIR/pareto.svg`
//! ([`pareto`]); the cases' own outputs go to `DIR/runs/<case>`.

pub mod curve;
pub mod lobovsky;
pub mod metrics;
pub mod pareto;
pub mod record;
pub mod report;
pub mod runner;
pub mod suite;

use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::Context;

use crate::cli::{BenchArgs, BenchRunArgs};

/// Run `cosim bench`. Exit 0 when every case ran and has a finite error, 1 when some did not (their records say
/// why), `Err` for bad input.
pub fn bench(args: &BenchArgs) -> anyhow::Result<ExitCode> {
    for only in &args.only {
        anyhow::ensure!(
            suite::CASES.contains(&only.as_str()),
            "--only {only}: the cases are {}",
            suite::CASES.join(", ")
        );
    }
    for s in &args.spacing {
        anyhow::ensure!(s.is_finite() && *s > 0.0, "--spacing {s}: must be positive");
    }
    let sel = suite::Selection {
        quick: args.quick,
        only: args.only.clone(),
        solvers: args.solver.clone(),
        contacts: args.contact.clone(),
        spacings: args.spacing.clone(),
        end_time: args.end_time,
    };
    let cases = suite::suite(&args.scenes, &sel);
    anyhow::ensure!(!cases.is_empty(), "the selection leaves no case to run");
    for c in &cases {
        anyhow::ensure!(c.scene.is_file(), "{}: no such scene (--scenes)", c.scene.display());
    }
    std::fs::create_dir_all(&args.out).with_context(|| format!("cannot create {}", args.out.display()))?;
    let limit = Duration::from_secs(args.case_timeout.unwrap_or(if args.quick { 300 } else { 3600 }));
    let started = Instant::now();
    let load_at_start = load_average();
    let mut records = Vec::new();
    for (k, case) in cases.iter().enumerate() {
        let mut runs: Vec<record::Record> = (0..case.repeats.max(1))
            .map(|rep| {
                let id = match case.repeats {
                    0 | 1 => case.id(),
                    _ => format!("{}_r{}", case.id(), rep + 1),
                };
                let load = load_average();
                let out = args.out.join("runs").join(id);
                let mut r = runner::run_case(case, &out, &args.scenes, limit);
                r.load_average = load;
                if case.metric == suite::Metric::Scaling {
                    // Two frames of up to 100,000 particles (~35 MB) per run that nobody looks at.
                    let _ = std::fs::remove_dir_all(out.join("frames"));
                }
                r.repeats = case.repeats.max(1);
                r
            })
            .collect();
        // The median run by fluid cost per particle-step; a failed run sorts last.
        runs.sort_by(|a, b| {
            (a.status != "ok", a.sph_ns_per_particle_step)
                .partial_cmp(&(b.status != "ok", b.sph_ns_per_particle_step))
                .unwrap_or(std::cmp::Ordering::Equal)
        });
        let r = runs.swap_remove((runs.len() - 1) / 2);
        eprintln!("[{}/{}] {}", k + 1, cases.len(), progress_line(&r));
        records.push(r);
        // Written after every case, so a bench stopped half-way keeps what it measured.
        record::write(&args.out.join("bench.json"), &records)?;
    }
    let ctx = report::Context {
        load: (load_at_start, load_average()),
        cases: &cases,
        quick: args.quick,
        total_seconds: started.elapsed().as_secs_f64(),
        command: command_line(),
    };
    let report = args.out.join("report.md");
    std::fs::write(&report, report::render(&ctx, &records))
        .with_context(|| format!("cannot write {}", report.display()))?;
    pareto::plot(&args.out.join("pareto.svg"), &records)?;
    let failed = records.iter().filter(|r| r.status != "ok").count();
    println!(
        "bench: {} cases ({failed} without a result) in {:.0} s -> {}",
        records.len(),
        ctx.total_seconds,
        args.out.display()
    );
    Ok(if failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

fn progress_line(r: &record::Record) -> String {
    let contact = if r.contact == "none" {
        String::new()
    } else {
        format!(" {}", r.contact)
    };
    let threads = if r.case == "scaling" {
        format!(" {} thread(s)", r.threads)
    } else {
        String::new()
    };
    let variant = if r.variant.is_empty() {
        String::new()
    } else {
        format!(" {}", r.variant)
    };
    let mut line = format!(
        "{}{variant} {}{contact}{threads} dx={}: {}, {} particles, {} steps, {:.2} s, {:.2e} particle-steps/s",
        r.case, r.solver, r.spacing, r.status, r.particles, r.steps, r.wall_seconds, r.particle_steps_per_second
    );
    match (r.error, r.sensors.as_slice()) {
        (Some(_), [s1, s2, ..]) => {
            line += &format!(
                ", first impact t* {:.3} / {:.3}, peak {:.2} / {:.2} ρgH, RMS {:.3} / {:.3} ρgH",
                s1.first_impact, s2.first_impact, s1.peak, s2.peak, s1.rms, s2.rms
            )
        }
        (Some(e), _) => line += &format!(", error {:.2} %", 100.0 * e),
        (None, _) => {}
    }
    if let (Some(g), Some(d)) = (r.energy_growth, r.energy_drift) {
        line += &format!(", energy max {g:+.4} end {d:+.4} of the budget");
    }
    if let Some(note) = r.energy_note() {
        line += &format!(", {note}");
    }
    if let Some(b) = r.peak_rss_bytes {
        line += &format!(", peak RSS {:.1} MB", b as f64 / 1048576.0);
    }
    if r.status != "ok" {
        line += &format!(": {}", r.message);
    }
    line
}

fn command_line() -> String {
    let args: Vec<String> = std::env::args().skip(1).collect();
    format!("cosim {}", args.join(" "))
}

/// `cosim bench-run`: one case of the bench, `cosim run` in this process, then this process's peak resident
/// memory and CPU time written to `--stats-out` as JSON.
pub fn bench_run(args: &BenchRunArgs) -> anyhow::Result<ExitCode> {
    follow_the_bench()?;
    // The case's log and statistics are the bench's, beside the run's outputs in its folder.
    let run = crate::cli::RunArgs {
        beside: vec![runner::LOG_FILE.into(), runner::STATS_FILE.into()],
        ..args.run.clone()
    };
    let code = crate::run::run(&run)?;
    let stats = serde_json::to_string(&runner::ProcessStats::of_this_process())?;
    let path = &args.stats_out;
    std::fs::write(path, stats + "\n").with_context(|| format!("cannot write {}", path.display()))?;
    Ok(code)
}

/// A case started by `cosim bench` ends with it: the kernel sends it SIGTERM when the bench goes, however it goes
/// (SIGKILL included), and the run stops between two steps as on Ctrl-C, with its outputs written (before, a killed
/// bench left its case computing to the end). A bench already gone before this is set is an error.
fn follow_the_bench() -> anyhow::Result<()> {
    let Ok(parent) = std::env::var(runner::PARENT_ENV) else {
        return Ok(()); // started by hand
    };
    #[cfg(target_os = "linux")]
    nix::sys::prctl::set_pdeathsig(nix::sys::signal::Signal::SIGTERM).context("cannot follow the bench (prctl)")?;
    if nix::unistd::getppid().as_raw().to_string() != parent {
        anyhow::bail!("the bench that started this case (pid {parent}) is gone");
    }
    Ok(())
}

/// The 1-minute load average (`/proc/loadavg`): how busy the machine was besides the bench.
fn load_average() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg")
        .ok()?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}
