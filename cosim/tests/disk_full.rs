//! A disk that fills up during a run (`DESIGN.md` §5, `contact_broker::summary`): the run ends with exit code 1 and
//! a `summary.json` whose status is `failed` and whose message names the file that could not be written; no
//! `*.tmp` file is left behind, and `probes.csv` holds whole rows only. Before this, the broker died of its own log
//! line (its stderr is a file on the same disk), `cosim` said "No space left on device (os error 28)" without a path,
//! and there was no summary (an empty `summary.json.tmp` and a `.vtu.tmp` were left).
//!
//! The disk is a 256 KiB tmpfs mounted for the test in a mount namespace of its own (`unshare --user
//! --map-root-user --mount`, which works as root and, where the kernel allows user namespaces, as anyone): it
//! disappears with the namespace, so nothing is left mounted whatever happens. The run, a structure alone writing
//! 68 kB frames, fills it within its first frames; the namespace's shell copies what the test looks at out of it.

mod common;

use std::path::Path;
use std::process::Command;
use std::time::Duration;

use common::*;

const LIMIT: Duration = Duration::from_secs(120);

/// Run `cosim run SCENE ARGS --out DISK/out` (processes or in-process) with DISK a fresh 256 KiB tmpfs, and copy
/// into `keep`: `rc` (its exit code), `stderr`, `summary.json`, `probes.csv` and `files` (every path on the disk).
fn run_on_a_small_disk(keep: &Path, args: &[&str]) {
    std::fs::create_dir_all(keep).unwrap();
    let disk = keep.join("disk");
    std::fs::create_dir_all(&disk).unwrap();
    let script = r#"
        set -e
        mount -t tmpfs -o size=256k tmpfs "$DISK"
        touch "$KEEP/mounted"
        set +e
        "$COSIM" run "$@" --quiet --out "$DISK/out" 2> "$KEEP/stderr"
        echo $? > "$KEEP/rc"
        cp "$DISK/out/summary.json" "$DISK/out/probes.csv" "$KEEP/"
        find "$DISK" > "$KEEP/files"
    "#;
    let out = run_bounded(
        Command::new("unshare")
            .args(["--user", "--map-root-user", "--mount", "sh", "-c", script, "sh"])
            .args(args)
            .current_dir(root())
            .env("COSIM", cosim())
            .env("COSIM_BIN_DIR", bin_dir())
            .env("DISK", &disk)
            .env("KEEP", keep),
        LIMIT,
    );
    assert!(
        keep.join("mounted").is_file(),
        "this test mounts a tmpfs in a user and mount namespace of its own (`unshare --user --map-root-user \
         --mount`), which this machine refused: run it as root, or where the kernel allows unprivileged user \
         namespaces. unshare said: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn check(keep: &Path) {
    let read = |name: &str| std::fs::read_to_string(keep.join(name)).unwrap_or_default();
    let stderr = read("stderr");
    assert_eq!(read("rc").trim(), "1", "exit code; stderr: {stderr}");
    let summary = json(&keep.join("summary.json"));
    assert_eq!(summary["status"], "failed", "{summary}");
    let message = summary["message"].as_str().unwrap();
    // The file named is one of the run's, on the full disk.
    let out = keep.join("disk/out/");
    let named = message
        .split_whitespace()
        .find(|w| w.starts_with(out.to_str().unwrap()))
        .unwrap_or_else(|| panic!("the summary's message names no file of {}: {message}", out.display()));
    assert!(
        named.ends_with(':') && message.contains("No space left on device"),
        "{message}"
    );
    assert!(
        stderr.contains(named) && stderr.contains("No space left on device"),
        "stderr: {stderr}"
    );
    // Nothing half-written is left: no temporary file, no torn probe row.
    let files = read("files");
    assert!(files.contains("summary.json"), "{files}");
    assert!(!files.lines().any(|f| f.ends_with(".tmp")), "{files}");
    let csv = read("probes.csv");
    let columns = csv.lines().next().unwrap().split(',').count();
    assert!(
        csv.ends_with('\n') && csv.lines().all(|l| l.split(',').count() == columns),
        "{csv}"
    );
    assert!(csv.lines().count() > 1, "no sample kept: {csv}");
}

#[test]
fn a_full_disk_ends_the_run_with_a_summary_naming_the_file() {
    let dir = scratch("disk-full");
    let scene = "scenes/csm3.toml";
    let (processes, in_process) = (dir.join("processes"), dir.join("in-process"));
    // Started anyway: the 68 kB frames fill the disk within the first few.
    let anyway = "--ignore-disk-space";
    run_on_a_small_disk(&processes, &[scene, anyway, "--run-id", &run_id("disk-full")]);
    check(&processes);
    run_on_a_small_disk(&in_process, &[scene, anyway, "--in-process"]);
    check(&in_process);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The same run without `--ignore-disk-space` is refused before it starts (exit 2, one line): its 1001 frames of
/// 66.6 KiB (`proto::scene::disk`: 65 MiB with the probe table) against the 256 KiB the disk has, naming
/// `run.output_interval`; nothing is written there.
#[test]
fn outputs_larger_than_the_disk_are_refused_before_the_run_starts() {
    let dir = scratch("disk-refused");
    let keep = dir.join("every-output");
    run_on_a_small_disk(&keep, &["scenes/csm3.toml", "--in-process"]);
    let read = |name: &str| std::fs::read_to_string(keep.join(name)).unwrap_or_default();
    let stderr = read("stderr");
    assert_eq!(read("rc").trim(), "2", "exit code; stderr: {stderr}");
    let lines: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "one line expected: {stderr}");
    assert!(
        lines[0].contains("scenes/csm3.toml: run.output_interval: 0.01 s writes 1001 frames of 66.6 KiB")
            && lines[0].contains("has 256.0 KiB free"),
        "{stderr}"
    );
    let files = read("files");
    assert!(!files.contains("/out"), "the refused run wrote: {files}");
    let _ = std::fs::remove_dir_all(&dir);
}
