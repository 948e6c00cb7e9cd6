//! The price of distribution: wall time of `cosim run scenes/bench_5000.toml` as processes over zenoh against
//! `--in-process` (`cargo build --release && cargo bench -p cosim --bench distribution`). Prints medians of
//! several alternating runs and their ratio; nothing is asserted.

use std::path::PathBuf;
use std::process::Command;

/// (whole command wall time, the run's own wall time from summary.json) in seconds.
fn wall(mode_args: &[&str], out: &PathBuf, threads: &str) -> (f64, f64) {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf();
    let cosim = PathBuf::from(env!("CARGO_BIN_EXE_cosim"));
    let t0 = std::time::Instant::now();
    let status = Command::new(&cosim)
        .current_dir(&root)
        .args([
            "run",
            "scenes/bench_5000.toml",
            "--quiet",
            "--threads",
            threads,
            "--out",
        ])
        .arg(out)
        .args(mode_args)
        .env("COSIM_BIN_DIR", cosim.parent().unwrap())
        .status()
        .unwrap();
    let command = t0.elapsed().as_secs_f64();
    assert!(
        status.success(),
        "cosim run failed; build the node programs first: cargo build --release"
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    (command, summary["wall_seconds"].as_f64().unwrap())
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let out = std::env::temp_dir().join(format!("cosim-bench-dist-{}", std::process::id()));
    for threads in ["1", "2"] {
        let (mut p, mut i) = (Vec::new(), Vec::new());
        for _ in 0..5 {
            p.push(wall(&[], &out.join("p"), threads));
            i.push(wall(&["--in-process"], &out.join("i"), threads));
        }
        let (pc, pr) = (
            median(p.iter().map(|x| x.0).collect()),
            median(p.iter().map(|x| x.1).collect()),
        );
        let (ic, ir) = (
            median(i.iter().map(|x| x.0).collect()),
            median(i.iter().map(|x| x.1).collect()),
        );
        println!(
            "bench_5000 (5,000 quad4), {threads} thread(s): command processes {pc:.3} s / in-process {ic:.3} s = {:.3}; \
             stepping processes {pr:.3} s / in-process {ir:.3} s = {:.3}",
            pc / ic,
            pr / ir
        );
    }
    let _ = std::fs::remove_dir_all(&out);
}
