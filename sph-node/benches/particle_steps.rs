//! Fluid particle-steps per second of the WCSPH solver on the dam break (`cargo bench -p sph-node`), 1 and 2
//! threads, at about 20,000 and 80,000 fluid particles; also neighbours per fluid particle and memory per fluid
//! particle (the solver's own count of its arrays, and the growth of the peak resident set of a process that
//! runs one size only). Prints medians; nothing is asserted (machines are shared and noisy). Besides the wall-clock
//! rate per core, the rate per CPU-second of the process (all its threads, from `/proc/self/task/*/schedstat`) is
//! printed: it does not count the time the process waited for a core another program held, but it does count the
//! time idle rayon workers spin.
//!
//! Environment: `SPH_BENCH_SPACINGS` (comma-separated Δx, default `0.001,0.0005`), `SPH_BENCH_THREADS` (default
//! `1,2`), `SPH_BENCH_STEPS` (steps per repetition, default 20), `SPH_BENCH_REPS` (default 5).
//! `SPH_BENCH_SOLVER=isph` measures the ISPH solver on the same scene instead (steps default 3, repetitions 3: a
//! step solves a PPE; its neighbour column counts the wall particles' lists too, per fluid particle, and its heap
//! column is the peak of the heap in use from building the solver through its first two steps, temporaries
//! included, from the counting allocator; the PPE iterations of the last step are printed after the row).
//! `SPH_BENCH_SET` (scene overrides separated by `;`, e.g. `fluid.kinematic_viscosity=1e-6;fluid.xsph=0`) measures a
//! variant of the scene: what a switched-off term saves (the laminar viscosity loop is skipped at ν = 0, XSPH at
//! ε = 0, the density filter at `none`).
//! `SPH_BENCH_WARMUP` (simulated seconds, WCSPH only; default 0) advances the dam break that far before the timed
//! steps, so that they measure the flow in motion (the surge along the floor) rather than the column at rest.
//! `SPH_BENCH_FINGERPRINT=1` instead prints a hash of the state after short runs of a few configurations (default
//! dam break, MLS + APD, inviscid, a drop without walls), for checking that an optimisation leaves the results
//! bit-identical.

mod common;

use std::process::Command;

use common::{cpu_seconds, median};
use std::time::Instant;

use peak_alloc::PeakAlloc;
use sph_node::{IsphSolver, WcsphSolver};

/// Counts the heap in use and its peak: ISPH allocates its matrix and Krylov vectors inside the step, which a count
/// of the solver's own arrays (WCSPH's `heap_bytes`) would not see.
#[global_allocator]
static HEAP: PeakAlloc = PeakAlloc;

fn scene(spacing: f64, extra: &[&str]) -> cosim_proto::scene::Scene {
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/dam_break.toml")).unwrap();
    let mut overrides = vec![format!("fluid.spacing={spacing}")];
    overrides.extend(extra.iter().map(|s| s.to_string()));
    cosim_proto::scene::parse("dam_break.toml", &text, &overrides).unwrap()
}

/// Peak resident set size of this process [bytes] (Linux), 0 elsewhere.
fn peak_rss() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| s.lines().find(|l| l.starts_with("VmHWM:")).map(str::to_string))
        .and_then(|l| l.split_whitespace().nth(1).and_then(|kb| kb.parse::<u64>().ok()))
        .map_or(0, |kb| kb * 1024)
}

fn env_list<T: std::str::FromStr>(name: &str, default: &str) -> Vec<T> {
    std::env::var(name)
        .unwrap_or_else(|_| default.into())
        .split(',')
        .filter_map(|s| s.trim().parse().ok())
        .collect()
}

fn env_usize(name: &str, default: usize) -> usize {
    std::env::var(name).ok().and_then(|s| s.parse().ok()).unwrap_or(default)
}

/// One size of the ISPH solver, in this process: prints one line per thread count.
fn run_size_isph(spacing: f64) {
    let threads: Vec<usize> = env_list("SPH_BENCH_THREADS", "1,2");
    let steps = env_usize("SPH_BENCH_STEPS", 3);
    let reps = env_usize("SPH_BENCH_REPS", 3);
    let before = peak_rss();
    let heap_before = HEAP.current_usage();
    HEAP.reset_peak_usage();
    let mut solver = IsphSolver::new(&scene(spacing, &["fluid.solver=\"isph\""])).unwrap();
    let n = solver.state().len();
    let walls = solver.walls().x.len();
    for _ in 0..2 {
        let dt = solver.stable_dt();
        solver.step(dt).unwrap();
    }
    let rss = peak_rss().saturating_sub(before) as f64 / n as f64;
    // Peak heap of the solver and its first two steps (lists, matrix, Krylov vectors and all temporaries).
    let heap = HEAP.peak_usage().saturating_sub(heap_before) as f64 / n as f64;
    for t in threads {
        let (rates, cpu_rates, lo, hi) = measure(t, n, steps, reps, || {
            let dt = solver.stable_dt();
            solver.step(dt).unwrap();
        });
        println!(
            "{n:>9} {walls:>7} {t:>7} {:>14.3e} {:>19} {:>12.3e} {:>10.1} {heap:>10.0} B {rss:>8.0} B  (ISPH, PPE {} it.)",
            rates,
            format!("{lo:.2e}–{hi:.2e}"),
            cpu_rates,
            solver.pair_count() as f64 / n as f64,
            solver.last_ppe().iterations,
        );
    }
}

/// `reps` runs of `steps` calls of `step` on `threads` threads, over `n` particles: median particle-steps per second
/// per core, median per CPU-second, and the lowest and highest per core.
fn measure(threads: usize, n: usize, steps: usize, reps: usize, mut step: impl FnMut() + Send) -> (f64, f64, f64, f64) {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    let (rates, cpu_rates): (Vec<f64>, Vec<f64>) = (0..reps)
        .map(|_| {
            let (t0, c0) = (Instant::now(), cpu_seconds());
            pool.install(|| {
                for _ in 0..steps {
                    step();
                }
            });
            let work = (n * steps) as f64;
            (
                work / t0.elapsed().as_secs_f64() / threads as f64,
                work / (cpu_seconds() - c0),
            )
        })
        .unzip();
    let (lo, hi) = rates
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &r| (a.min(r), b.max(r)));
    (median(rates), median(cpu_rates), lo, hi)
}

/// One size, in this process: prints one line per thread count.
fn run_size(spacing: f64) {
    let threads: Vec<usize> = env_list("SPH_BENCH_THREADS", "1,2");
    let steps = env_usize("SPH_BENCH_STEPS", 20);
    let reps = env_usize("SPH_BENCH_REPS", 5);
    let before = peak_rss();
    let set = std::env::var("SPH_BENCH_SET").unwrap_or_default();
    let extra: Vec<&str> = set.split(';').filter(|s| !s.trim().is_empty()).collect();
    let mut solver = WcsphSolver::new(&scene(spacing, &extra)).unwrap();
    let n = solver.state().len();
    let walls = solver.walls().len();
    // Two steps, and on to `SPH_BENCH_WARMUP` for the flow in motion rather than at rest (the Verlet candidates then
    // hold for fewer steps).
    let warm_up = std::env::var("SPH_BENCH_WARMUP")
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
        .unwrap_or(0.0);
    while solver.state().step < 2 || solver.state().t < warm_up {
        let dt = solver.stable_dt();
        solver.step(dt).unwrap();
    }
    let rss = peak_rss().saturating_sub(before) as f64 / n as f64;
    let neighbours = solver.pair_count() as f64 / n as f64;
    let heap = solver.heap_bytes() as f64 / n as f64;
    for t in threads {
        let (rates, cpu_rates, lo, hi) = measure(t, n, steps, reps, || {
            let dt = solver.stable_dt();
            solver.step(dt).unwrap();
        });
        println!(
            "{n:>9} {walls:>7} {t:>7} {:>14.3e} {:>19} {:>12.3e} {neighbours:>10.1} {heap:>10.0} B {rss:>8.0} B",
            rates,
            format!("{lo:.2e}–{hi:.2e}"),
            cpu_rates,
        );
    }
}

fn main() {
    if std::env::var("SPH_BENCH_FINGERPRINT").is_ok_and(|v| v == "1") {
        fingerprint();
        return;
    }
    if let Ok(spacing) = std::env::var("SPH_BENCH_CHILD") {
        if std::env::var("SPH_BENCH_SOLVER").is_ok_and(|v| v == "isph") {
            run_size_isph(spacing.parse().unwrap());
        } else {
            run_size(spacing.parse().unwrap());
        }
        return;
    }
    println!(
        "{:>9} {:>7} {:>7} {:>14} {:>19} {:>12} {:>10} {:>12} {:>10}",
        "fluid", "walls", "threads", "steps/s/core", "(min–max)", "per CPU-s", "nbrs/part", "heap/part", "RSS/part"
    );
    // One process per size, so that each peak resident set is its own.
    let exe = std::env::current_exe().unwrap();
    for spacing in env_list::<f64>("SPH_BENCH_SPACINGS", "0.001,0.0005") {
        let out = Command::new(&exe)
            .env("SPH_BENCH_CHILD", spacing.to_string())
            .output()
            .unwrap();
        print!("{}", String::from_utf8_lossy(&out.stdout));
        eprint!("{}", String::from_utf8_lossy(&out.stderr));
    }
}

/// FNV-1a over the bits of the fluid state, the wall pressures, the accelerations and the stable step, every
/// 100 steps of a few short runs.
fn fingerprint() {
    let configs: [(&str, f64, &[&str]); 5] = [
        ("drop", 0.0, &[]),
        ("default", 0.004, &[]),
        (
            "mls_apd",
            0.005,
            &["fluid.density_filter=\"mls\"", "fluid.density_filter_interval=5"],
        ),
        (
            "inviscid",
            0.004,
            &[
                "fluid.kinematic_viscosity=0.0",
                "fluid.xsph=0.0",
                "fluid.artificial_viscosity=0.0",
            ],
        ),
        ("fine", 0.002, &[]),
    ];
    for (name, spacing, extra) in configs {
        let mut solver = if name == "drop" {
            drop_solver()
        } else {
            WcsphSolver::new(&scene(spacing, extra)).unwrap()
        };
        if name == "mls_apd" {
            solver.set_apd(0.1);
        }
        for step in 0..400 {
            let dt = solver.stable_dt();
            solver.step(dt).unwrap();
            if step % 100 == 99 {
                let s = solver.state();
                let mut h: u64 = 0xcbf29ce484222325;
                let mut eat = |x: f64| {
                    h ^= x.to_bits();
                    h = h.wrapping_mul(0x100000001b3);
                };
                eat(s.t);
                for i in 0..s.len() {
                    for x in [s.x[i][0], s.x[i][1], s.v[i][0], s.v[i][1], s.rho[i], s.p[i], s.m[i]] {
                        eat(x);
                    }
                }
                solver.walls().p.iter().for_each(|&p| eat(p));
                solver.accelerations().iter().for_each(|a| {
                    eat(a[0]);
                    eat(a[1]);
                });
                eat(solver.stable_dt());
                println!("{name} {} {:016x} KE {:e}", s.step, h, solver.kinetic_energy());
            }
        }
    }
}

/// A drop without walls in a central force field (as the oscillating-drop test, coarser).
fn drop_solver() -> WcsphSolver {
    use sph_node::{SphParams, WcsphParams};
    let dx = 1.0 / 20.0;
    let mut x = Vec::new();
    for iy in -20i64..20 {
        for ix in -20i64..20 {
            let p = [(ix as f64 + 0.5) * dx, (iy as f64 + 0.5) * dx];
            if p[0].hypot(p[1]) < 1.0 {
                x.push(p);
            }
        }
    }
    let params = SphParams {
        rho0: 1000.0,
        dx,
        h: 1.3 * dx,
        nu: 0.0,
        gravity: [0.0, 0.0],
        xsph: 0.3,
        domain: cosim_proto::scene::BoxSpec {
            min: [-4.0, -4.0],
            max: [4.0, 4.0],
        },
    };
    let eos = sph_node::eos::Tait::new(1000.0, 15.0);
    let p: Vec<f64> = x.iter().map(|r| 625.0 * (1.0 - (r[0] * r[0] + r[1] * r[1]))).collect();
    let state = sph_node::FluidState {
        t: 0.0,
        step: 0,
        v: x.iter().map(|r| [0.5 * r[0], -0.5 * r[1]]).collect(),
        rho: p.iter().map(|&p| eos.density(p)).collect(),
        m: vec![1000.0 * dx * dx; x.len()],
        p,
        x,
    };
    let options = WcsphParams {
        c0: 15.0,
        alpha: 0.01,
        shepard_interval: Some(7),
        central_force: 1.0,
        ..Default::default()
    };
    WcsphSolver::from_particles(params, options, state, sph_node::WallParticles::default()).unwrap()
}
