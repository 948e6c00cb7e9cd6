//! A scene whose solid is far from the water (`cosim/tests/data/far_solid.toml`: a dam break in a closed tank,
//! a cantilever 0.7 m beyond its far wall) as three processes: the broker's region of interest around the
//! structure holds no particle at any step, so `sph-node` sends none and no contact is made (`DESIGN.md` §3:
//! SPH sends only the particles near the structure), while both solvers still advance in lockstep to the end.

mod common;

use std::time::Duration;

use common::*;

/// About 2,600 coupling steps of 560 particles: a few seconds; no test may hang.
const LIMIT: Duration = Duration::from_secs(120);

#[test]
fn a_solid_out_of_reach_gets_no_particles_and_no_contact() {
    let out = scratch("far_solid").child("out");
    let mut cmd = std::process::Command::new(cosim());
    cmd.current_dir(root()).env("COSIM_BIN_DIR", bin_dir()).args([
        "run",
        "cosim/tests/data/far_solid.toml",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
        "--run-id",
        &run_id("far_solid"),
    ]);
    let output = run_bounded(&mut cmd, LIMIT);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let s = json(&out.join("summary.json"));
    assert_eq!(s["status"], "ok");
    assert_eq!(s["mode"], "processes");
    // Both nodes ran the whole scene: 0.2 s at the fluid's stable step (≤ coupling.max_dt = 1e-4 s).
    assert!((s["sim_time"].as_f64().unwrap() - 0.2).abs() < 1e-9, "{s}");
    assert!(s["steps"].as_u64().unwrap() >= 2000, "{s}");
    assert_eq!(s["particles"], 560);
    assert_eq!(s["fem_nodes"], 51);
    let stats = &s["contact_stats"];
    assert_eq!(stats["exchanged_max"], 0, "no particle is near the solid: {stats}");
    assert_eq!(stats["exchanged_per_step"].as_f64(), Some(0.0), "{stats}");
    assert_eq!(stats["contacts"], 0, "{stats}");
    assert_eq!(stats["max_penetration"].as_f64(), Some(0.0), "{stats}");
}
