//! What a run writes into its output folder against what `cosim check` estimated (`proto::scene::disk`, which
//! `cosim run` compares with the free space of the folder's disk): the frames within 2 % (they are counted from the
//! frame writer's arrays), the checkpoints within 10 % (from what each node saves, measured), on the shipped gate
//! coupled to WCSPH and to ISPH and on the structure alone (csm3 to its end, 1,001 probe rows). Found 2026-12-06: `--checkpoint-interval=1e-300` wrote a
//! checkpoint every step (5,000 on csm3, 216 MB) and `run.output_interval = 1e-7` asked the gate for 4 TB of
//! frames, with nothing to say so before the disk filled.

mod common;

use std::path::Path;

use common::*;
use cosim_proto::scene::disk::DiskEstimate;
use cosim_proto::sizing::Sizing;

/// Bytes of the files under `dir` (all of it, recursively), or of the file `dir`.
fn bytes(dir: &Path) -> f64 {
    let meta = std::fs::metadata(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    if meta.is_file() {
        return meta.len() as f64;
    }
    std::fs::read_dir(dir).unwrap().map(|e| bytes(&e.unwrap().path())).sum()
}

/// Run `scene` with `sets` in-process with a checkpoint every `interval` s; assert the folder's frames, checkpoints
/// and probe table against the estimate.
fn compare(name: &str, scene: &str, sets: &[&str], interval: f64) {
    let out = scratch(&format!("output-size-{name}"));
    let mut args = vec!["run", scene, "--in-process", "--quiet", "--out", out.to_str().unwrap()];
    let interval_text = interval.to_string();
    args.extend(["--checkpoint-interval", &interval_text]);
    for s in sets {
        args.extend(["--set", s]);
    }
    run_ok(&args);
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let loaded = cosim_proto::scene::load(&root().join(scene), &sets).unwrap();
    let s = &loaded.scene;
    let estimate = DiskEstimate::of(s, &Sizing::of(s), Some(interval), 0.0);
    let summary = json(&out.join("summary.json"));
    assert_eq!(summary["status"], "ok", "{summary}");
    let frames = bytes(&out.join("frames"));
    let checkpoints = bytes(&out.join("checkpoints"));
    let probes = bytes(&out.join("probes.csv"));
    let written = std::fs::read_dir(out.join("checkpoints")).unwrap().count() as f64;
    println!(
        "{name}: frames {frames} B against {} ({} x {}), checkpoints {checkpoints} B against {} ({written} against \
         {}), probes.csv {probes} B against {}",
        estimate.frames * estimate.frame_bytes + estimate.collection_bytes,
        estimate.frames,
        estimate.frame_bytes,
        estimate.checkpoints * estimate.checkpoint_bytes,
        estimate.checkpoints,
        estimate.probe_bytes
    );
    let frame_files = summary["frames"].as_f64().unwrap();
    assert_eq!(estimate.frames, frame_files, "{name}: frame times");
    assert_eq!(estimate.checkpoints, written, "{name}: checkpoints");
    let near = |got: f64, want: f64, tol: f64, what: &str| {
        assert!(
            (got - want).abs() <= tol * want,
            "{name}: {what} estimated {got} B, written {want} B"
        );
    };
    near(
        estimate.frames * estimate.frame_bytes + estimate.collection_bytes,
        frames,
        0.02,
        "frames",
    );
    near(
        estimate.checkpoints * estimate.checkpoint_bytes,
        checkpoints,
        0.10,
        "checkpoints",
    );
    // The probe table is estimated from above (24 characters a value): it may be smaller, never much larger.
    assert!(
        estimate.probe_bytes >= probes && estimate.probe_bytes <= 3.0 * probes,
        "{name}: probes.csv estimated {} B, written {probes} B",
        estimate.probe_bytes
    );
}

#[test]
fn the_outputs_of_the_gate_and_of_a_structure_alone_are_what_check_estimates() {
    let short = ["run.end_time=0.02", "run.output_interval=0.005"];
    compare("gate-wcsph", "scenes/elastic_gate.toml", &short, 0.01);
    let isph = [short[0], short[1], "fluid.solver=\"isph\""];
    compare("gate-isph", "scenes/elastic_gate.toml", &isph, 0.01);
    // The whole run: the broker's checkpoints grow with the probe table (1,001 rows at the end).
    compare("csm3", "scenes/csm3.toml", &[], 2.5);
}
