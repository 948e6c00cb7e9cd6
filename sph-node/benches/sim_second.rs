//! CPU seconds per simulated second of the dam break, WCSPH and ISPH side by side (issue 20: ISPH's larger step
//! must pay for its pressure solve). `cargo bench -p sph-node --bench sim_second`.
//!
//! Each repetition runs both solvers one after the other from the same scene (`scenes/dam_break.toml`) for
//! `SPH_BENCH_SIM_TIME` simulated seconds (default 0.05) at their own stable steps, on `SPH_BENCH_THREADS` threads
//! (default 1), in a child process of
//! its own (so that one solver's memory does not weigh on the other); the medians over `SPH_BENCH_REPS`
//! repetitions (default 3) are printed with the steps taken and, for ISPH, the PPE's BiCGSTAB iterations per step
//! (mean and largest). Sizes: `SPH_BENCH_SPACINGS` (default `0.001,0.0005`: 20,000 and 80,000 fluid particles).
//! CPU seconds are the process's own (`/proc/self/task/*/schedstat`): time spent waiting for a core another program
//! held is not counted. Nothing is asserted.

mod common;

use std::process::Command;

use common::{cpu_seconds, median};

use sph_node::{FluidSolver, IsphSolver, WcsphSolver};

fn scene(spacing: f64, solver: &str) -> cosim_proto::scene::Scene {
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/dam_break.toml")).unwrap();
    let overrides = vec![format!("fluid.spacing={spacing}"), format!("fluid.solver=\"{solver}\"")];
    cosim_proto::scene::parse("dam_break.toml", &text, &overrides).unwrap()
}

fn env_or<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name).ok().and_then(|s| s.parse().ok()).unwrap_or(default)
}

/// Runs one solver for `t_end` simulated seconds in this process; prints `cpu_s steps it_mean it_max particles
/// wall_s`.
fn child(spacing: f64, solver: &str, t_end: f64) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(env_or("SPH_BENCH_THREADS", 1))
        .build()
        .unwrap();
    let scene = scene(spacing, solver);
    pool.install(|| {
        let mut fluid: Box<dyn FluidSolver> = match solver {
            "isph" => Box::new(IsphSolver::new(&scene).unwrap()),
            _ => Box::new(WcsphSolver::new(&scene).unwrap()),
        };
        let n = fluid.state().len();
        let (c0, w0) = (cpu_seconds(), std::time::Instant::now());
        let (mut t, mut steps, mut it_sum, mut it_max) = (0.0, 0u64, 0usize, 0usize);
        while t < t_end {
            let dt = fluid.stable_dt().min(t_end - t);
            fluid.step(dt).unwrap();
            t += dt;
            steps += 1;
            if let Some(ppe) = fluid.ppe_iterations() {
                it_sum += ppe;
                it_max = it_max.max(ppe);
            }
        }
        let (cpu, wall) = (cpu_seconds() - c0, w0.elapsed().as_secs_f64());
        println!("{cpu} {steps} {} {it_max} {n} {wall}", it_sum as f64 / steps as f64);
    });
}

fn main() {
    if let Ok(spec) = std::env::var("SPH_BENCH_SIM_CHILD") {
        let mut it = spec.split(',');
        let (spacing, solver, t_end) = (it.next().unwrap(), it.next().unwrap(), it.next().unwrap());
        child(spacing.parse().unwrap(), solver, t_end.parse().unwrap());
        return;
    }
    let t_end: f64 = env_or("SPH_BENCH_SIM_TIME", 0.05);
    let reps: usize = env_or("SPH_BENCH_REPS", 3);
    let spacings: Vec<f64> = std::env::var("SPH_BENCH_SPACINGS")
        .unwrap_or_else(|_| "0.001,0.0005".into())
        .split(',')
        .filter_map(|s| s.trim().parse().ok())
        .collect();
    let exe = std::env::current_exe().unwrap();
    println!(
        "dam break, {t_end} s simulated, {} thread(s), median of {reps} (interleaved)",
        env_or("SPH_BENCH_THREADS", 1usize)
    );
    println!(
        "{:>9} {:>6} {:>16} {:>17} {:>8} {:>10} {:>8}",
        "fluid", "solver", "CPU-s per sim s", "wall s per sim s", "steps", "PPE mean", "PPE max"
    );
    for spacing in spacings {
        type Row<'a> = (&'a str, Vec<f64>, Vec<f64>, Vec<String>);
        let mut rows: Vec<Row> = vec![("wcsph", vec![], vec![], vec![]), ("isph", vec![], vec![], vec![])];
        for _ in 0..reps {
            for (solver, cpu, wall, rest) in rows.iter_mut() {
                let out = Command::new(&exe)
                    .env("SPH_BENCH_SIM_CHILD", format!("{spacing},{solver},{t_end}"))
                    .output()
                    .unwrap();
                let text = String::from_utf8_lossy(&out.stdout);
                let fields: Vec<String> = text.split_whitespace().map(str::to_string).collect();
                // cpu_s steps it_mean it_max particles wall_s (`child`)
                assert!(
                    fields.len() == 6,
                    "child {solver} at {spacing}: {text} {}",
                    String::from_utf8_lossy(&out.stderr)
                );
                cpu.push(fields[0].parse::<f64>().unwrap() / t_end);
                wall.push(fields[5].parse::<f64>().unwrap() / t_end);
                *rest = fields[1..].to_vec();
            }
        }
        for (solver, cpu, wall, rest) in rows {
            let ppe = if solver == "isph" {
                (rest[1].as_str(), rest[2].as_str())
            } else {
                ("", "")
            };
            println!(
                "{:>9} {solver:>6} {:>16.1} {:>17.1} {:>8} {:>10} {:>8}",
                rest[3],
                median(cpu),
                median(wall),
                rest[0],
                ppe.0.parse::<f64>().map(|m| format!("{m:.1}")).unwrap_or_default(),
                ppe.1
            );
        }
    }
}
