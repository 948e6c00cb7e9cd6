//! The space the output folder's disk has free, and the refusal of a run whose outputs cannot fit it
//! (`proto::scene::disk`).

use std::path::Path;

use cosim_proto::scene::disk::DiskEstimate;
use cosim_proto::scene::sizing::Sizing;
use cosim_proto::scene::{Scene, SceneError};

/// Bytes an unprivileged writer may still use on the disk that holds `dir` (the disk of its nearest existing
/// ancestor: the folder may not exist yet), or `None` where it cannot be read, or where the file system counts no
/// blocks at all (`/proc`, `/sys`: then creating the folder fails with its own error): then no run is refused for it.
pub fn free(dir: &Path) -> Option<u64> {
    let absolute = std::path::absolute(dir).ok()?;
    let existing = absolute.ancestors().find(|p| p.exists())?;
    let stat = rustix::fs::statvfs(existing).ok()?;
    if stat.f_blocks == 0 {
        return None;
    }
    stat.f_bavail.checked_mul(stat.f_frsize)
}

/// Refuse `scene` (read from `file`) if what it writes into `out` from simulated time `from`, with a checkpoint
/// every `checkpoint_interval` seconds, needs more than the `free` bytes of its disk (no refusal when `None`): one
/// line naming `file`, the key that makes the outputs large, what they need and what is free.
pub fn refuse_above(
    scene: &Scene,
    file: &str,
    out: &Path,
    checkpoint_interval: Option<f64>,
    from: f64,
    free: Option<u64>,
) -> Result<(), SceneError> {
    let Some(free) = free else {
        return Ok(());
    };
    let estimate = DiskEstimate::of(scene, &Sizing::of(scene), checkpoint_interval, from);
    estimate
        .refuse_above(scene, free, &out.display().to_string())
        .map_err(|(key, message)| SceneError {
            file: file.to_string(),
            key,
            message,
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_folder_not_made_yet_has_the_free_space_of_its_disk() {
        let here = std::env::temp_dir();
        let free = free(&here).expect("the temporary folder's disk");
        assert!(free > 0);
        let later = free_of_missing(&here);
        // The same disk: the same free space, to what other processes wrote in between (64 MiB).
        assert!(later.abs_diff(free) < 64 << 20, "{later} against {free}");
    }

    /// A file system without blocks (`/proc`) has no free space to compare with: a folder there fails when it is
    /// made, with its own error, not as "0 B free".
    #[test]
    fn a_file_system_without_blocks_has_no_free_space_to_refuse_for() {
        if Path::new("/proc/self").exists() {
            assert_eq!(free(Path::new("/proc/nope/x")), None);
        }
    }

    fn free_of_missing(here: &Path) -> u64 {
        free(&here.join("not-made-yet").join("deeper")).expect("its ancestor's disk")
    }

    /// A scene of 4,000,002 particle frames (output every 1e-7 s) is refused naming `run.output_interval`, with what the
    /// frames need and what is free; with a frame every 0.01 s it fits.
    #[test]
    fn outputs_larger_than_the_disk_are_refused_naming_the_key() {
        let text = r#"
version = 1
[run]
name = "frames"
end_time = 0.4
output_interval = 1e-7
[fluid]
density = 1000.0
spacing = 0.002
[[fluid.block]]
min = [0.0, 0.0]
max = [0.2, 0.2]
"#;
        let scene = cosim_proto::scene::parse("frames.toml", text, &[]).unwrap();
        let gib = 1u64 << 30;
        let out = Path::new("/data/out");
        let err = refuse_above(&scene, "frames.toml", out, None, 0.0, Some(100 * gib)).unwrap_err();
        let line = err.to_string();
        assert!(
            line.starts_with("frames.toml: run.output_interval: 1e-7 s writes 4000002 frames of 1.1 MiB: the outputs"),
            "{line}"
        );
        assert!(
            line.ends_with("/data/out has 100.0 GiB free (--ignore-disk-space starts it anyway)"),
            "{line}"
        );
        assert!(refuse_above(&scene, "f", out, None, 0.0, None).is_ok());
        let coarse = cosim_proto::scene::parse("f.toml", text, &["run.frame_interval=0.01".into()]).unwrap();
        assert!(refuse_above(&coarse, "f", out, None, 0.0, Some(gib)).is_ok());
        // Checkpoints at every step: refused naming the option when they are what fills the disk.
        let every = cosim_proto::scene::parse("f.toml", text, &["run.output_interval=0.1".into()]).unwrap();
        let err = refuse_above(&every, "f", out, Some(1e-300), 0.0, Some(100 << 20)).unwrap_err();
        assert_eq!(err.key, "--checkpoint-interval", "{err}");
    }
}
