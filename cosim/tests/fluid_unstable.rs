//! `cosim run` of a fluid scene that goes wrong (`cosim/tests/data/fluid_unstable.toml`: a tank with no floor, so
//! the water falls and the stability guard stops it, its kinetic energy past twice the energy it started with),
//! as processes:
//! exit code 1, `summary.json` status `unstable`, one stderr line naming the SPH step, the particle and the
//! reason, and the frames and probe samples written before the failure kept and readable. The in-process run
//! reports the same failure.

mod common;

use std::path::Path;
use std::time::Duration;

use common::*;

/// The run fails after about 0.2 s of simulated time, under a second of wall time; no test may hang.
const LIMIT: Duration = Duration::from_secs(60);
const SCENE: &str = "cosim/tests/data/fluid_unstable.toml";
/// The scene's `run.end_time`.
const END_TIME: f64 = 1.0;
/// Fluid particles of the scene: a 0.1 m × 0.2 m block at Δx = 0.01 m.
const PARTICLES: usize = 200;

/// `cosim run SCENE --out OUT` with `extra` arguments; the process output.
fn run(out: &Path, id: &str, extra: &[&str]) -> std::process::Output {
    let mut cmd = std::process::Command::new(cosim());
    cmd.current_dir(root()).env("COSIM_BIN_DIR", bin_dir()).args([
        "run",
        SCENE,
        "--quiet",
        "--out",
        out.to_str().unwrap(),
        "--run-id",
        &run_id(id),
    ]);
    cmd.args(extra);
    run_bounded(&mut cmd, LIMIT)
}

/// (step, particle, reason) of "unstable at SPH step N, particle K: REASON" in `text`; REASON runs to the end of
/// the line or to " (outputs so far", which cosim appends on stderr.
fn sph_report(text: &str) -> (u64, usize, String) {
    let rest = text
        .split_once("unstable at SPH step ")
        .unwrap_or_else(|| panic!("no SPH step in {text:?}"))
        .1;
    let (step, rest) = rest.split_once(", particle ").unwrap();
    let (particle, rest) = rest.split_once(": ").unwrap();
    let reason = rest.split(" (outputs so far").next().unwrap().lines().next().unwrap();
    (
        step.parse().unwrap_or_else(|_| panic!("step {step:?}")),
        particle.parse().unwrap_or_else(|_| panic!("particle {particle:?}")),
        reason.to_string(),
    )
}

/// Standard base64 (with `=` padding) to bytes.
fn base64(text: &str) -> Vec<u8> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("not base64: {c:?}"),
    };
    let digits: Vec<u8> = text
        .bytes()
        .filter(|&c| c != b'=' && !c.is_ascii_whitespace())
        .collect();
    let mut out = Vec::with_capacity(digits.len() * 3 / 4);
    for chunk in digits.chunks(4) {
        let mut acc = 0u32;
        for (k, &c) in chunk.iter().enumerate() {
            acc |= u32::from(value(c)) << (18 - 6 * k);
        }
        out.extend_from_slice(&acc.to_be_bytes()[1..chunk.len()]);
    }
    out
}

/// The particle positions of a binary (base64, UInt64 header) VTU frame as written by the broker.
fn vtu_points(path: &Path) -> Vec<[f64; 3]> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(
        text.starts_with("<VTKFile type=\"UnstructuredGrid\"") && text.trim_end().ends_with("</VTKFile>"),
        "{} is not a complete VTU file",
        path.display()
    );
    let n: usize = text
        .split_once("NumberOfPoints=\"")
        .and_then(|(_, r)| r.split('"').next())
        .and_then(|s| s.parse().ok())
        .expect("NumberOfPoints");
    let data = text
        .split_once("<Points>")
        .and_then(|(_, r)| r.split_once('>'))
        .and_then(|(_, r)| r.split_once("</DataArray>"))
        .expect("a Points data array")
        .0;
    let bytes = base64(data);
    let len = u64::from_le_bytes(bytes[..8].try_into().unwrap()) as usize;
    assert_eq!(
        len,
        n * 3 * 8,
        "{}: Points holds {len} bytes for {n} points",
        path.display()
    );
    assert_eq!(bytes.len(), 8 + len, "{}", path.display());
    bytes[8..]
        .chunks(24)
        .map(|p| [0, 1, 2].map(|k| f64::from_le_bytes(p[8 * k..8 * k + 8].try_into().unwrap())))
        .collect()
}

#[test]
fn a_fluid_blow_up_ends_the_run_unstable_naming_step_particle_and_reason() {
    let dir = scratch("fluid-unstable");
    let out = dir.join("processes");
    let res = run(&out, "fluid-unstable", &[]);
    let err = String::from_utf8_lossy(&res.stderr);

    // Exit code 1 and one line on stderr that names the step, the particle and the reason.
    assert_eq!(res.status.code(), Some(1), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("run unstable") && err.contains("sph-node"), "{err}");
    let (step, particle, reason) = sph_report(&err);
    assert!(step >= 1, "{err}");
    assert!(particle < PARTICLES, "{err}");
    // The falling water passes the energy guard's bound (twice the energy it had) before it leaves the domain.
    assert!(
        reason.starts_with("left the domain at [") || reason.starts_with("kinetic energy"),
        "{err}"
    );

    // summary.json: unstable, with the same report, stopped before the end.
    let s = json(&out.join("summary.json"));
    assert_eq!(s["status"], "unstable");
    assert_eq!(s["mode"], "processes");
    assert_eq!(s["solver"], "wcsph");
    assert_eq!(s["particles"].as_u64().unwrap(), PARTICLES as u64);
    let message = s["message"].as_str().unwrap();
    assert_eq!(sph_report(message), (step, particle, reason.clone()), "{message}");
    let sim_time = s["sim_time"].as_f64().unwrap();
    assert!(sim_time > 0.0 && sim_time < END_TIME, "sim_time {sim_time}");

    // The probe samples taken before the blow-up: one row each, finite, in time order, none after the failure.
    let csv = std::fs::read_to_string(out.join("probes.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next().unwrap(), "t,p_floor,energy");
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    let samples = s["samples"].as_u64().unwrap() as usize;
    assert!(
        samples >= 2 && rows.len() == samples,
        "{} rows, {samples} samples",
        rows.len()
    );
    assert!(
        rows.iter().flatten().all(|v| v.is_finite()),
        "a probe value is not finite"
    );
    assert!(rows.windows(2).all(|w| w[1][0] > w[0][0]), "probe times out of order");
    assert!(rows.last().unwrap()[0] <= sim_time, "a sample after the failure");

    // The frames: every one the collection lists exists, the last good one is a complete VTU whose particles
    // are all finite, with as many points as the first frame.
    let frames = out.join("frames");
    let pvd = std::fs::read_to_string(frames.join("particles.pvd")).unwrap();
    let listed: Vec<(f64, String)> = pvd
        .lines()
        .filter_map(|l| {
            let t = l.split_once("timestep=\"")?.1.split('"').next()?.parse().ok()?;
            let f = l.split_once("file=\"")?.1.split('"').next()?.to_string();
            Some((t, f))
        })
        .collect();
    let n_frames = s["frames"].as_u64().unwrap() as usize;
    assert!(
        n_frames >= 2 && listed.len() == n_frames,
        "{} listed, {n_frames} frames",
        listed.len()
    );
    for (_, f) in &listed {
        assert!(frames.join(f).is_file(), "{f} is listed but missing");
    }
    let (t_last, last) = listed.last().unwrap();
    assert!(*t_last <= sim_time, "a frame after the failure: t = {t_last}");
    let first_points = vtu_points(&frames.join(&listed[0].1));
    let points = vtu_points(&frames.join(last));
    assert!(points.len() > PARTICLES, "fluid and wall particles: {}", points.len());
    assert_eq!(points.len(), first_points.len());
    assert!(
        points.iter().flatten().all(|v| v.is_finite()),
        "{last} holds a non-finite position"
    );
    assert_ne!(points, first_points, "the last frame shows the water moved");
    eprintln!(
        "unstable at SPH step {step}, particle {particle} ({reason}) after t = {sim_time} s; {samples} samples and \
         {n_frames} frames kept, the last at t = {t_last} s"
    );

    // In-process: the same failure, reported the same way.
    let inp = dir.join("in-process");
    let res = run(&inp, "fluid-unstable-in-process", &["--in-process"]);
    let err_in = String::from_utf8_lossy(&res.stderr);
    assert_eq!(res.status.code(), Some(1), "{err_in}");
    let s_in = json(&inp.join("summary.json"));
    assert_eq!(s_in["status"], "unstable");
    assert_eq!(s_in["message"], s["message"]);
    assert_eq!(sph_report(&err_in), (step, particle, reason));
    let _ = std::fs::remove_dir_all(&dir);
}
