//! The memory this machine can give a run, and the refusal of a scene that needs more (`proto::sizing`).
//!
//! Available is `MemAvailable` of `/proc/meminfo`, lowered to what the process's cgroup still allows
//! (`memory.max` − `memory.current`, cgroup v2): in a container `/proc/meminfo` shows the host's memory.

use std::path::Path;

use cosim_proto::scene::{Scene, SceneError};
use cosim_proto::sizing::{Part, Sizing};

/// Bytes this machine can still give, or `None` where it cannot be read (not Linux): then no scene is refused for
/// its size.
pub fn available() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    let available = meminfo_available(&meminfo)?;
    Some(match cgroup_room(Path::new("/sys/fs/cgroup")) {
        Some(room) => available.min(room),
        None => available,
    })
}

/// `MemAvailable` in bytes from the text of `/proc/meminfo` (`MemAvailable:   22733940 kB`).
fn meminfo_available(text: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

/// Room left under the cgroup v2 limit of this process (`memory.max` − `memory.current` of the cgroup named in
/// `/proc/self/cgroup`), or `None` without a limit.
fn cgroup_room(root: &Path) -> Option<u64> {
    let own = std::fs::read_to_string("/proc/self/cgroup").ok()?;
    // cgroup v2: one line `0::/path`.
    let path = own.lines().find_map(|l| l.strip_prefix("0::"))?;
    let dir = root.join(path.trim_start_matches('/'));
    let read = |name: &str| std::fs::read_to_string(dir.join(name)).ok();
    let max: u64 = read("memory.max")?.trim().parse().ok()?; // "max" (no limit) does not parse
    let current: u64 = read("memory.current")?.trim().parse().ok()?;
    Some(max.saturating_sub(current))
}

/// Refuse `scene` if `part` of its run needs more than `available` bytes (no refusal when `None`): one line naming
/// `file`, the key that makes it big, what it needs and what is available.
pub fn refuse_above(scene: &Scene, part: Part, file: &str, available: Option<u64>) -> Result<(), SceneError> {
    let Some(available) = available else {
        return Ok(());
    };
    Sizing::of(scene)
        .refuse_above(part, available)
        .map_err(|(key, message)| SceneError {
            file: file.to_string(),
            key,
            message,
        })
}

/// The check a node runs on the scene the broker served, before it builds anything from it: a scene too big for
/// this machine is a failure with one line, not an abort in an allocation.
pub fn node_fits(scene: &Scene, part: Part) -> Result<(), crate::serve::Failure> {
    refuse_above(scene, part, "(scene from the broker)", available()).map_err(|e| crate::serve::Failure {
        unstable: false,
        message: e.to_string(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mem_available_is_read_in_bytes() {
        let text = "MemTotal:       24000000 kB\nMemFree:        21000000 kB\nMemAvailable:   22733940 kB\n";
        assert_eq!(meminfo_available(text), Some(22_733_940 * 1024));
        assert_eq!(meminfo_available("MemTotal: 1 kB\n"), None);
        // This machine's, where there is one.
        if std::path::Path::new("/proc/meminfo").exists() {
            assert!(available().is_some_and(|b| b > 0));
        }
    }

    /// A fluid node's share of a scene of 2e9 particles: refused naming the spacing, before any particle exists.
    #[test]
    fn a_node_refuses_its_part_of_a_scene_too_big_for_the_memory_given() {
        let text = r#"
version = 1
[run]
name = "big"
end_time = 0.1
output_interval = 0.01
[fluid]
density = 1000.0
spacing = 1e-5
[[fluid.block]]
min = [0.0, 0.0]
max = [0.4, 0.5]
"#;
        let scene = cosim_proto::scene::parse("big.toml", text, &[]).unwrap();
        let gib = 1 << 30;
        let err = refuse_above(&scene, Part::Fluid, "(scene from the broker)", Some(16 * gib)).unwrap_err();
        let line = err.to_string();
        assert!(
            line.starts_with("(scene from the broker): fluid.spacing: 1e-5 m fills"),
            "{line}"
        );
        assert!(line.contains("2.00e9 particles"), "{line}");
        assert!(
            line.contains("sph-node needs about 1.") && line.contains(" TiB"),
            "{line}"
        );
        assert!(line.ends_with("this machine has 16.0 GiB available"), "{line}");
        // The broker's share is smaller, the structure node has none; no refusal without a known size.
        assert!(refuse_above(&scene, Part::Structure, "f", Some(gib)).is_ok());
        assert!(refuse_above(&scene, Part::Fluid, "f", None).is_ok());
        assert!(refuse_above(&scene, Part::Fluid, "f", Some(u64::MAX)).is_ok());
    }
}
