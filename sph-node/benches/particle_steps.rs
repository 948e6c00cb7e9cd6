//! Particle-steps per second of the WCSPH solver on the dam break (`cargo bench -p sph-node`), 1 and 2 threads,
//! at about 20,000 and 80,000 fluid particles; also the peak resident memory per particle. Prints medians;
//! nothing is asserted (machines are shared and noisy).

use std::time::Instant;

use sph_node::WcsphSolver;

fn scene(spacing: f64) -> cosim_proto::scene::Scene {
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/dam_break.toml")).unwrap();
    cosim_proto::scene::parse("dam_break.toml", &text, &[format!("fluid.spacing={spacing}")]).unwrap()
}

/// Peak resident set size of this process [bytes] (Linux), 0 elsewhere.
fn peak_rss() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| s.lines().find(|l| l.starts_with("VmHWM:")).map(str::to_string))
        .and_then(|l| l.split_whitespace().nth(1).and_then(|kb| kb.parse::<u64>().ok()))
        .map_or(0, |kb| kb * 1024)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    println!(
        "{:>9} {:>7} {:>8} {:>22} {:>16}",
        "particles", "walls", "threads", "particle-steps/s/core", "peak RSS/particle"
    );
    for spacing in [0.001, 0.0005] {
        let before = peak_rss();
        let mut solver = WcsphSolver::new(&scene(spacing)).unwrap();
        let n = solver.state().len();
        let walls = solver.walls().len();
        for threads in [1usize, 2] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let steps = 20;
            let rates: Vec<f64> = (0..3)
                .map(|_| {
                    let t0 = Instant::now();
                    pool.install(|| {
                        for _ in 0..steps {
                            let dt = solver.stable_dt();
                            solver.step(dt).unwrap();
                        }
                    });
                    (n * steps) as f64 / t0.elapsed().as_secs_f64() / threads as f64
                })
                .collect();
            let rss = (peak_rss().saturating_sub(before)) as f64 / n as f64;
            println!(
                "{n:>9} {walls:>7} {threads:>8} {:>22.3e} {:>14.0} B",
                median(rates),
                rss
            );
        }
    }
}
