//! ISPH and WCSPH on the dam break against a wall of Lobovsky et al. 2014 (`scenes/lobovsky_dam_break.toml`,
//! H = 0.3 m, Δx = H/30 and, for ISPH, H/60, `cosim run --in-process`, probes every 1 ms): the pressure at sensors 1
//! (y = 3 mm) and 2 (y = 15 mm), as the scene's sensor probes report it (the time mean over each sampling interval),
//! against the recorded peak event, and the water levels at gauges H1–H4 against the recorded levels (issue 16; ISPH
//! acceptance: `docs/CORRECTIONS.md`, "ISPH pressure"; WCSPH: "WCSPH at the wall impact"). Times and pressures in
//! the data's units: t* = t sqrt(g/H), p* = p/(ρgH). About a minute (ISPH H/30), 85 s (ISPH H/60, 2 cores) and 15 s
//! (WCSPH) of wall time.

mod common;

use std::path::Path;
use std::time::Duration;

use common::{cosim_run, json, root, run_id, scratch, Scratch};

const H: f64 = 0.3;
const G: f64 = 9.81;
const RHO: f64 = 1000.0;
/// A sensor reads the impact once p* passes this (the experiment's and the probe's first impact).
const IMPACT: f64 = 0.1;

/// (t*, p*) of a CSV with a header, columns `t_col`, `p_col`, scaled by `t_scale`, `p_scale`.
fn series(path: &Path, t_col: &str, p_col: &str, t_scale: f64, p_scale: f64) -> Vec<(f64, f64)> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("no column {name}"))
    };
    let (ct, cp) = (col(t_col), col(p_col));
    lines
        .map(|l| {
            let f: Vec<f64> = l.split(',').map(|v| v.parse().unwrap_or(f64::NAN)).collect();
            (f[ct] * t_scale, f[cp] * p_scale)
        })
        .collect()
}

/// Linear interpolation of `s` (sorted by t) at `t`.
fn at(s: &[(f64, f64)], t: f64) -> f64 {
    let k = s.partition_point(|p| p.0 <= t).clamp(1, s.len() - 1);
    let ((t0, p0), (t1, p1)) = (s[k - 1], s[k]);
    p0 + (p1 - p0) * (t - t0) / (t1 - t0)
}

fn first_impact(s: &[(f64, f64)]) -> f64 {
    s.iter().find(|p| p.0 > 1.0 && p.1 >= IMPACT).expect("an impact").0
}

/// What a run gives at one sensor or gauge, and what was recorded there.
struct Sensor {
    name: &'static str,
    sim: Vec<(f64, f64)>,
    data: Vec<(f64, f64)>,
}

impl Sensor {
    fn first(&self) -> (f64, f64) {
        (first_impact(&self.sim), first_impact(&self.data))
    }
    fn peak(&self) -> f64 {
        let t = first_impact(&self.sim);
        self.sim
            .iter()
            .filter(|p| p.0 <= t + 0.5)
            .map(|p| p.1)
            .fold(f64::NEG_INFINITY, f64::max)
    }
    /// RMS of sim − data for t* ≤ `t_end` (a gauge's level/H).
    fn rms_until(&self, t_end: f64) -> f64 {
        let w: Vec<f64> = self
            .sim
            .iter()
            .filter(|p| p.0 <= t_end)
            .map(|p| p.1 - at(&self.data, p.0))
            .collect();
        (w.iter().map(|d| d * d).sum::<f64>() / w.len() as f64).sqrt()
    }
    fn rms(&self) -> f64 {
        let w: Vec<f64> = self
            .sim
            .iter()
            .filter(|p| (3.0..=7.0).contains(&p.0))
            .map(|p| p.1 - at(&self.data, p.0))
            .collect();
        (w.iter().map(|d| d * d).sum::<f64>() / w.len() as f64).sqrt()
    }
}

/// The first impact's pressure impulse (the bench's score `b`) within `tol` (relative) of the recording's.
fn assert_impulse_within(name: &str, b: &cosim::bench::lobovsky::SensorScore, tol: f64) {
    assert!(
        (b.impulse / b.impulse_data - 1.0).abs() <= tol,
        "{name}: impulse {} against the recording's {}",
        b.impulse,
        b.impulse_data
    );
}

/// [`lobovsky_run`] at Δx = H/60: the sensor probes (and their `_raw` twins) half a spacing in front of the wall, x =
/// 1.6075 m, and frames at the start and the end only (every 10 ms would be 153 MB).
fn h60_run(name: &str, sets: &[&str]) -> ([Sensor; 2], [Sensor; 4], Scratch) {
    let mut all = vec![
        "fluid.spacing=0.005",
        "run.frame_interval=1.25",
        "probe[0].point=[1.6075,0.003]",
        "probe[1].point=[1.6075,0.015]",
        "probe[2].point=[1.6075,0.003]",
        "probe[3].point=[1.6075,0.015]",
    ];
    all.extend_from_slice(sets);
    lobovsky_run(name, &all)
}

/// Runs the scene (Δx = H/30 as shipped) with the `--set`s `sets` and returns sensors 1 and 2, the water-level
/// gauges H1–H4 (level/H) and the run's folder.
fn lobovsky_run(name: &str, sets: &[&str]) -> ([Sensor; 2], [Sensor; 4], Scratch) {
    let out = scratch(&format!("lobovsky-{name}"));
    let scene = root().join("scenes/lobovsky_dam_break.toml");
    let (scene_s, out_s, id) = (scene.display().to_string(), out.display().to_string(), run_id(name));
    let mut args = vec![
        "run",
        &scene_s,
        "--in-process",
        "--quiet",
        "--out",
        &out_s,
        "--run-id",
        &id,
    ];
    for set in sets {
        args.extend(["--set", set]);
    }
    let res = cosim_run(&args, Duration::from_secs(600));
    let summary = json(&out.join("summary.json"));
    assert!(
        res.status.success(),
        "{summary}\n{}",
        String::from_utf8_lossy(&res.stderr)
    );
    assert_eq!(summary["status"], "ok", "{summary}");
    let ts = (G / H).sqrt();
    let rgh = RHO * G * H;
    let data = root().join("scenes/data");
    let sensor = |k: usize, name: &'static str| Sensor {
        name,
        sim: series(&out.join("probes.csv"), "t", &format!("p_sensor{k}"), ts, 1.0 / rgh),
        data: series(
            &data.join(format!("lobovsky2014_H300_sensor{k}_event.csv")),
            "t_star",
            "p_star",
            1.0,
            1.0,
        ),
    };
    let gauge = |k: usize, name: &'static str| Sensor {
        name,
        sim: series(&out.join("probes.csv"), "t", &format!("level_H{k}"), ts, 1.0 / H),
        data: series(
            &data.join(format!("lobovsky2014_H300_level_H{k}.csv")),
            "t_star",
            "level",
            1.0,
            1.0,
        ),
    };
    (
        [sensor(1, "sensor 1"), sensor(2, "sensor 2")],
        [gauge(1, "H1"), gauge(2, "H2"), gauge(3, "H3"), gauge(4, "H4")],
        out,
    )
}

/// The impact arrives on time and its peak, as the sensor probe reports it (`p_sensor1`, `p_sensor2`: the mean over
/// each 1 ms sampling interval of every ISPH step's value, interpolated from the fluid particles), is within a factor 2
/// of the recorded event (1.5–6 ρgH); the pressure is never a suction below −0.5 ρgH; a sensor under water never
/// reads exactly 0 from 0.1 t* after the first impact on (clipped negative pressures); and after the impact (t* in
/// [3, 7]) the RMS difference to the measurement is at most 0.25 ρgH.
///
/// Measured (2026-11-28, probes from the fluid particles only): first impact t* 2.453 / 2.453 at sensors 1 / 2
/// (recorded 2.444 / 2.460), peak 3.30 / 2.95 ρgH (recorded 3.04 / 1.95; the instantaneous `p_sensor*_raw` 4.92 /
/// 3.65), RMS t* 3–7 0.177 / 0.162 ρgH, lowest sample 0, no exact zero in the window (the raw probes read exactly 0
/// once, at t* = 2.505). Before, when the probes took the wall particles' pressures in, a single free-surface
/// particle running 4 cm ahead of the front made the wall read 12–15 ρgH for 5 ms: first impact t* 2.385 / 2.390,
/// peak 5.00 / 10.34, RMS 0.183 / 0.172 (docs/CORRECTIONS.md, "What a pressure probe reads").
///
/// The water-level gauges H1–H4 (`water_level` probes, the highest surface on the gauge's line) follow the recorded
/// levels within 0.05 H r.m.s. up to t* = 5.5, before the plunging wave that returns from the wall reaches H3 and H4
/// (measured 0.027 / 0.021 / 0.018 / 0.018 H; to t* = 7.15, 0.027 / 0.021 / 0.068 / 0.099 H: the run's returning
/// wave reaches H4 about 0.3 t* after the recorded one; WCSPH to t* = 5.5: 0.014 / 0.032 / 0.026 / 0.459 H, the
/// jet thrown up the wall falling back through H4's line at t* 4.6–4.9).
#[test]
fn isph_h30_impact_time_peak_level_and_no_dropouts() {
    let (sensors, gauges, out) = lobovsky_run("isph-h30", &["fluid.solver=isph"]);
    assert_isph_bounds("H/30", &sensors, &gauges, &out);
}

/// The same bounds at Δx = H/60 (issue 16: "H/60 too if the suite's time allows"; the sensor probes half a spacing
/// from the wall; 85 s of wall time on 2 cores, 132 CPU-s). Measured (2026-12-07, thirty-second session): first
/// impact t* 2.402 / 2.407 (recorded 2.444 / 2.460), peak 2.78 / 2.82 ρgH, RMS t* 3–7 0.217 / 0.203 ρgH, lowest
/// sample 0, no exact zero under water, impulse 0.867 / 0.713 (+5.3 / −3.0 %), gauges H1–H4 0.022 / 0.023 / 0.020 /
/// 0.017 H — the bench's H/60 row (docs/PERFORMANCE.md, "The wall impact … per solver and resolution"), now held by
/// the suite: the multigrid's first version had put this peak at 6.41, over the bound, and only the bench saw it.
#[test]
fn isph_h60_impact_time_peak_level_and_no_dropouts() {
    let (sensors, gauges, out) = h60_run("isph-h60", &["fluid.solver=isph"]);
    assert_isph_bounds("H/60", &sensors, &gauges, &out);
}

/// Issue 16's bounds on an ISPH run at `label`'s spacing: the gauges to t* = 5.5, and at both sensors the first
/// impact, the peak, the lowest sample, no exact zero under water, the RMS after the impact and the impulse.
fn assert_isph_bounds(label: &str, sensors: &[Sensor; 2], gauges: &[Sensor; 4], out: &Path) {
    // `cosim bench`'s wall-impact case scores a run with its own code (`cosim::bench::lobovsky`): the same numbers.
    let bench = cosim::bench::lobovsky::score(out, &root().join("scenes")).expect("bench score");
    for g in gauges {
        let rms = g.rms_until(5.5);
        eprintln!(
            "ISPH {label} gauge {}: level r.m.s. difference to t* = 5.5 {rms:.3} H",
            g.name
        );
        assert!(rms <= 0.05, "gauge {}: level r.m.s. difference {rms:.3} H", g.name);
    }
    for (s, b) in sensors.iter().zip(&bench) {
        let (sim, exp) = s.first();
        let same = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(1.0);
        assert!(
            same(sim, b.first_impact)
                && same(exp, b.first_impact_data)
                && same(s.peak(), b.peak)
                && same(s.rms(), b.rms),
            "{}: the bench scores {b:?}",
            s.name
        );
        let min = s.sim.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
        let zeros: Vec<f64> = s
            .sim
            .iter()
            .filter(|p| p.0 > sim + 0.1 && p.1 == 0.0)
            .map(|p| p.0)
            .collect();
        let peak = s.peak();
        eprintln!(
            "ISPH {label} {}: first impact t* = {sim:.3} (measured {exp:.3}), peak {peak:.2} ρgH, RMS t* 3–7 {:.3} ρgH, \
             min {min:.3} ρgH, exact zeros under water {}",
            s.name,
            s.rms(),
            zeros.len()
        );
        assert!(
            (sim - exp).abs() <= 0.1,
            "{}: first impact at t* = {sim}, measured {exp}",
            s.name
        );
        assert!((1.5..=6.0).contains(&peak), "{}: peak {peak} ρgH", s.name);
        assert!(min >= -0.5, "{}: a sample of {min} ρgH", s.name);
        assert!(zeros.is_empty(), "{}: p = 0 under water at t* = {zeros:?}", s.name);
        assert!(s.rms() <= 0.25, "{}: RMS {} ρgH after the impact", s.name, s.rms());
        // The first impact's pressure impulse, ∫ p* dt* from 0.05 t* before it to 0.5 t* after it (each series from
        // its own impact; the bench's score): the momentum the wall takes, whatever the pulse's shape. Measured
        // 0.809 / 0.673 against the recording's 0.823 / 0.735 (−1.7 / −8.4 %; WCSPH +25 / +16 %, docs/CORRECTIONS.md
        // "WCSPH at the wall impact"); bound ±15 %.
        eprintln!(
            "ISPH {label} {}: first-impact impulse {:.3} (recorded {:.3})",
            s.name, b.impulse, b.impulse_data
        );
        assert_impulse_within(s.name, b, 0.15);
    }
}

/// WCSPH with δ-SPH at δ = 0.5 (over the paper's set: Shepard every 20 steps, XSPH, APD): the impact arrives within
/// ±0.1 t* of the recording, the wall takes the recorded impulse within 25 % (∫ p* dt* from 0.05 t* before the first
/// impact to 0.5 t* after it), and after the impact (t* in [3, 7]) the RMS difference to the measurement is at most
/// 0.25 ρgH. Measured: first impact 2.528 / 2.528 (recorded 2.444 / 2.460), impulse 0.940 / 0.896 (0.823 / 0.735:
/// +14 / +22 %), RMS 0.197 / 0.197 (the paper's set alone: 0.340 / 0.313, an acoustic ringing of the pool that
/// δ-SPH at 0.5 damps; at H/60 0.145 / 0.151). Not met, and not asserted (issue 16 stays open on them): the peak,
/// 13.3 / 13.3 ρgH against 3.04 / 1.95 (the water hammer ρ c0 u of the weakly compressible impact, delivered in
/// 1–3 ms where the recording takes tens), and the lowest sample, −4.7 / −5.3 ρgH (its rebound).
#[test]
fn wcsph_h30_with_delta_sph_impact_time_impulse_and_level_after() {
    let (sensors, _, out) = lobovsky_run("wcsph-h30", &["fluid.density_diffusion=0.5"]);
    let bench = cosim::bench::lobovsky::score(&out, &root().join("scenes")).expect("bench score");
    for (s, b) in sensors.iter().zip(&bench) {
        let (sim, exp) = s.first();
        eprintln!(
            "WCSPH H/30, delta-SPH 0.5, {}: first impact t* = {sim:.3} (measured {exp:.3}), impulse {:.3} \
             (recorded {:.3}), RMS t* 3–7 {:.3} ρgH; not met: peak {:.2} ρgH, lowest {:.2} ρgH",
            s.name,
            b.impulse,
            b.impulse_data,
            s.rms(),
            s.peak(),
            b.min
        );
        assert!(
            (sim - exp).abs() <= 0.1,
            "{}: first impact at t* = {sim}, measured {exp}",
            s.name
        );
        assert_impulse_within(s.name, b, 0.25);
        assert!(s.rms() <= 0.25, "{}: RMS {} ρgH after the impact", s.name, s.rms());
    }
}
