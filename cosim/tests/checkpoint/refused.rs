//! Checkpoints a run must refuse up front, naming the file and the key: another scene's, another protocol version's,
//! and damaged ones.

use super::*;

/// A copy of the checkpoint folder `ck` at `to`; returns `to`.
fn copy_of(ck: &Path, to: &Path) -> PathBuf {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(ck).unwrap().flatten() {
        std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
    }
    to.to_path_buf()
}

#[test]
fn a_checkpoint_from_another_scene_or_version_is_refused() {
    let dir = scratch("checkpoint-refused");
    let out = dir.join("run");
    let out_s = out.display().to_string();
    let (gate, dam) = (scene("elastic_gate.toml"), scene("dam_break.toml"));
    run_ok(&[
        "run",
        &gate,
        "--quiet",
        "--in-process",
        "--out",
        &out_s,
        "--set",
        "fluid.spacing=0.006",
        "--set",
        "run.end_time=0.02",
        "--checkpoint-interval",
        "0.01",
    ]);
    let (_, ck) = checkpoints(&out).remove(0);
    let ck_s = ck.display().to_string();
    let refused = |args: &[&str], expect: &[&str]| {
        let got = cosim_run(args, LIMIT);
        let stderr = String::from_utf8_lossy(&got.stderr);
        assert_eq!(got.status.code(), Some(2), "bad input: {stderr}");
        assert_eq!(stderr.trim().lines().count(), 1, "one line: {stderr}");
        for e in expect {
            assert!(stderr.contains(e), "`{e}` in: {stderr}");
        }
    };
    let again = dir.join("again").display().to_string();
    // Another spacing: the line that differs is named.
    refused(
        &[
            "run",
            &gate,
            "--out",
            &again,
            "--set",
            "fluid.spacing=0.005",
            "--restart",
            &ck_s,
        ],
        &[
            "scene.toml",
            "another scene",
            "[fluid] spacing = 0.005",
            "[fluid] spacing = 0.006",
        ],
    );
    // Nothing left to run.
    refused(
        &[
            "run",
            &gate,
            "--out",
            &again,
            "--set",
            "fluid.spacing=0.006",
            "--set",
            "run.end_time=0.01",
            "--restart",
            &ck_s,
        ],
        &["checkpoint.json", "nothing to run"],
    );
    // Another scene altogether.
    refused(
        &["run", &dam, "--out", &again, "--restart", &ck_s],
        &["another scene", "name = \"dam_break\""],
    );
    // Another protocol version.
    let other = copy_of(&ck, &dir.join("other_version"));
    let manifest = other.join("checkpoint.json");
    let text = std::fs::read_to_string(&manifest).unwrap();
    std::fs::write(
        &manifest,
        text.replace(
            &format!("\"protocol_version\": {PROTOCOL_VERSION}"),
            "\"protocol_version\": 7",
        ),
    )
    .unwrap();
    let other_s = other.display().to_string();
    refused(
        &[
            "run",
            &gate,
            "--out",
            &again,
            "--set",
            "fluid.spacing=0.006",
            "--restart",
            &other_s,
        ],
        &["checkpoint.json", "protocol version 7"],
    );
    // A damaged copy: sph.bin cut short.
    let damaged = copy_of(&ck, &dir.join("damaged"));
    let sph = damaged.join("sph.bin");
    let bytes = std::fs::read(&sph).unwrap();
    std::fs::write(&sph, &bytes[..bytes.len() - 1]).unwrap();
    let damaged_s = damaged.display().to_string();
    refused(
        &[
            "run",
            &gate,
            "--out",
            &again,
            "--set",
            "fluid.spacing=0.006",
            "--restart",
            &damaged_s,
        ],
        &["sph.bin", "damaged", &format!("{} bytes", bytes.len() - 1)],
    );
    // Not a checkpoint folder.
    refused(
        &["run", &gate, "--out", &again, "--restart", &out_s],
        &["checkpoint.json", "not a checkpoint"],
    );
    // An outside program cannot save its state.
    refused(
        &[
            "run",
            &gate,
            "--out",
            &again,
            "--external",
            "fem",
            "--checkpoint-interval",
            "0.1",
        ],
        &["--external fem", "checkpoint"],
    );
    assert!(!dir.join("again").join("probes.csv").exists(), "nothing ran");
}
