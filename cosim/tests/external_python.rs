//! An external code in place of a node (`DESIGN.md` §5, `docs/PROTOCOL.md`): `cosim run --external fem` starts the
//! broker and `sph-node` as processes and waits; `examples/python/rigid_plate_node.py` (Python, `eclipse-zenoh` from
//! PyPI) joins as the structure node and runs the scene `cosim/tests/data/plate_on_springs.toml` to its end.
//!
//! The check: the same model written in Rust below ([`RigidPlate`], operation for operation as the Python file),
//! coupled in this process to the same fluid through the same coordinator, gives a **byte-identical** `probes.csv`:
//! everything the Python node computes and sends, and everything the broker does with it, is exactly what the Rust
//! twin produces. And the plate settles where statics says it should: u_y = −(ρ_f g H L + M g)/k, within 10 % (the
//! mean over the last 0.35 s comes out ~5 % short: the SPH side walls carry part of the weight of the water next to
//! them, see the scene file).
//!
//! Needs Python 3.11+ with `eclipse-zenoh` 1.10 (the README's test command installs it in `target/py`; or set
//! `COSIM_PYTHON`).

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::*;
use contact_broker::coordinator::{self, Nodes, RunInfo};
use contact_broker::link::{FemLink, InProcess, LinkError, SphLink};
use contact_broker::recorder::{Recorded, Recorder, Tap};
use contact_broker::setup::RunSetup;
use cosim_proto::messages::{Energies, FemMesh, FemSnapshot, FemState, Segment, StepCommand};
use cosim_proto::scene::{self, Scene};
use cosim_proto::sizing::Part;
use cosim_proto::trace::Node;
use sph_node::core::SphCore;

const SCENE: &str = "cosim/tests/data/plate_on_springs.toml";
/// About 4,000 coupling steps of 1,600 particles: ~10–30 s; no test may hang.
const LIMIT: Duration = Duration::from_secs(240);
/// The Python node's defaults (`--stiffness`, `--damping-ratio`).
const STIFFNESS: f64 = 3.0e8;
const DAMPING_RATIO: f64 = 0.1;

/// The Python interpreter: `$COSIM_PYTHON`, else `target/py/bin/python` (made by the README's test command), else
/// `python3`; it must import zenoh.
fn python() -> PathBuf {
    let chosen = std::env::var_os("COSIM_PYTHON")
        .map(PathBuf::from)
        .or_else(|| Some(root().join("target/py/bin/python")).filter(|p| p.is_file()))
        .unwrap_or_else(|| PathBuf::from("python3"));
    let probe = Command::new(&chosen)
        .args(["-c", "import sys, zenoh; assert sys.version_info >= (3, 11)"])
        .output();
    assert!(
        probe.as_ref().is_ok_and(|o| o.status.success()),
        "{} cannot import zenoh (Python 3.11+ with eclipse-zenoh 1.10 is needed): run \
         `python3 -m venv target/py && target/py/bin/pip install eclipse-zenoh==1.10.0`, or set COSIM_PYTHON ({:?})",
        chosen.display(),
        probe.map(|o| String::from_utf8_lossy(&o.stderr).into_owned())
    );
    chosen
}

/// The rigid plate on springs of `examples/python/rigid_plate_node.py`, written again in Rust with the same
/// operations in the same order, so that the same inputs give the same bits.
struct RigidPlate {
    mass: f64,
    k: f64,
    c: f64,
    h: f64,
    gravity: [f64; 2],
    reference: Vec<[f64; 2]>,
    cells: Vec<Vec<u32>>,
    masses: Vec<f64>,
    segments: Vec<Segment>,
    interface: Vec<u32>,
    u: [f64; 2],
    v: [f64; 2],
}

impl RigidPlate {
    fn new(scene: &Scene, stiffness: f64, damping_ratio: f64) -> Self {
        let solid = &scene.solids[0];
        let ([x0, y0], [x1, y1]) = (solid.min, solid.max);
        let [nx, ny] = solid.divisions;
        let mass = solid.material.density * (x1 - x0) * (y1 - y0);
        let period = 2.0 * std::f64::consts::PI * (mass / stiffness).sqrt();
        let node = |i: u32, j: u32| j * (nx + 1) + i;
        let mut reference = Vec::new();
        for j in 0..=ny {
            for i in 0..=nx {
                reference.push([
                    x0 + (x1 - x0) * f64::from(i) / f64::from(nx),
                    y0 + (y1 - y0) * f64::from(j) / f64::from(ny),
                ]);
            }
        }
        let mut cells = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                cells.push(vec![node(i, j), node(i + 1, j), node(i + 1, j + 1), node(i, j + 1)]);
            }
        }
        let cell_mass = mass / f64::from(nx * ny);
        let mut masses = vec![0.0; reference.len()];
        for cell in &cells {
            for &n in cell {
                masses[n as usize] += cell_mass / 4.0;
            }
        }
        let mut seg: Vec<(u32, u32)> = (0..nx).map(|i| (node(i, 0), node(i + 1, 0))).collect();
        seg.extend((0..ny).map(|j| (node(nx, j), node(nx, j + 1))));
        seg.extend((0..nx).rev().map(|i| (node(i + 1, ny), node(i, ny))));
        seg.extend((0..ny).rev().map(|j| (node(0, j + 1), node(0, j))));
        let mut interface: Vec<u32> = seg.iter().flat_map(|&(a, b)| [a, b]).collect();
        interface.sort_unstable();
        interface.dedup();
        Self {
            mass,
            k: stiffness,
            c: 2.0 * damping_ratio * (stiffness * mass).sqrt(),
            h: period / 40.0,
            gravity: scene.run.gravity,
            reference,
            cells,
            masses,
            segments: seg.into_iter().map(|(a, b)| Segment { a, b }).collect(),
            interface,
            u: [0.0; 2],
            v: [0.0; 2],
        }
    }

    fn mesh(&self, name: &str) -> FemMesh {
        FemMesh {
            solid_names: vec![name.into()],
            nodes: self.reference.clone(),
            masses: self.masses.clone(),
            node_solid: vec![0; self.reference.len()],
            cells: self.cells.clone(),
            cell_solid: vec![0; self.cells.len()],
            interface: self.segments.clone(),
            fixed: Vec::new(),
            dt_stable: self.h,
        }
    }

    fn positions(&self, ids: impl Iterator<Item = usize>) -> Vec<[f64; 2]> {
        ids.map(|n| [self.reference[n][0] + self.u[0], self.reference[n][1] + self.u[1]])
            .collect()
    }

    fn handle(&mut self, cmd: &StepCommand) -> Option<FemState> {
        for c in &cmd.corrections {
            let Some(&m) = self.masses.get(c.id as usize) else {
                continue;
            };
            for k in 0..2 {
                self.v[k] += m * c.dv[k] / self.mass;
                self.u[k] += m * c.dx[k] / self.mass;
            }
        }
        if cmd.stop {
            return None;
        }
        let mut substeps = 0;
        if cmd.dt > 0.0 {
            let n = ((cmd.dt / self.h - 1e-9).ceil() as u32).max(1);
            let h = cmd.dt / f64::from(n);
            for _ in 0..n {
                for k in 0..2 {
                    let a = self.gravity[k] - (self.k * self.u[k] + self.c * self.v[k]) / self.mass;
                    self.v[k] += h * a;
                    self.u[k] += h * self.v[k];
                }
            }
            substeps = n;
        }
        let ids = if cmd.want_interface {
            self.interface.clone()
        } else {
            Vec::new()
        };
        let snapshot = cmd.want_snapshot.then(|| {
            let n = self.reference.len();
            FemSnapshot {
                x: self.positions(0..n),
                v: vec![self.v; n],
                stress: vec![[0.0; 3]; self.cells.len()],
                energies: vec![Energies {
                    kinetic: 0.5 * self.mass * (self.v[0] * self.v[0] + self.v[1] * self.v[1]),
                    strain: 0.5 * self.k * (self.u[0] * self.u[0] + self.u[1] * self.u[1]),
                    potential: -self.mass * (self.gravity[0] * self.u[0] + self.gravity[1] * self.u[1]),
                }],
            }
        });
        Some(FemState {
            x: self.positions(ids.iter().map(|&i| i as usize)),
            v: vec![self.v; ids.len()],
            ids,
            substeps,
            dt_stable: self.h,
            compute_seconds: 0.0,
            snapshot,
        })
    }
}

/// The scene with the Rust twin in place of the Python node, in this process; with `record`, its messages are kept in
/// `out/trace/` as `cosim run --record` keeps them.
fn run_rust_twin(out: &Path, record: bool) -> f64 {
    let loaded = scene::load(&root().join(SCENE), &[]).unwrap();
    let mut plate = RigidPlate::new(&loaded.scene, STIFFNESS, DAMPING_RATIO);
    let fem = InProcess::new(plate.mesh(&loaded.scene.solids[0].name), move |cmd: &StepCommand| {
        Ok::<_, LinkError>(plate.handle(cmd))
    });
    let sph = cosim::in_process::link("sph-node", SphCore::new(&loaded.scene).unwrap());
    std::fs::create_dir_all(out).unwrap();
    let info = RunInfo {
        run_id: run_id("rust_twin"),
        mode: "in-process".into(),
        out: out.to_path_buf(),
    };
    let recorder = record.then(|| {
        let setup = RunSetup::load(&root().join(SCENE), &[], Part::Run).unwrap();
        Recorder::begin(out, &info.run_id, &setup, true).unwrap()
    });
    let tap = |node| Tap {
        recorder: recorder.clone().unwrap(),
        node,
    };
    let (mut fem, mut sph): (Box<FemLink>, Box<SphLink>) = match record {
        true => (
            Box::new(Recorded::new(fem, tap(Node::Fem), &info.run_id)),
            Box::new(Recorded::new(sph, tap(Node::Sph), &info.run_id)),
        ),
        false => (Box::new(fem), Box::new(sph)),
    };
    let nodes = Nodes {
        fem: Some(fem.as_mut()),
        sph: Some(sph.as_mut()),
    };
    let outcome = coordinator::run(&loaded, nodes, &info, &mut |_| std::ops::ControlFlow::Continue(()));
    assert!(outcome.summary.status.is_ok(), "{}", outcome.summary.message);
    if let Some(r) = &recorder {
        r.finish("ok", "", outcome.summary.steps);
    }
    let g = loaded.scene.run.gravity[1].abs();
    let block = &loaded.scene.fluid.as_ref().unwrap().blocks[0];
    let solid = &loaded.scene.solids[0];
    let weight_fluid = 1000.0 * g * (block.max[1] - block.min[1]) * (block.max[0] - block.min[0]);
    let weight_plate = solid.material.density * (solid.max[0] - solid.min[0]) * (solid.max[1] - solid.min[1]) * g;
    -(weight_fluid + weight_plate) / STIFFNESS
}

#[test]
fn python_structure_node_matches_its_rust_twin_bit_for_bit() {
    let python = python();
    let dir = scratch("external_python");
    let (out_py, out_rs) = (dir.join("python"), dir.join("rust"));
    let started = Instant::now();
    let until = started + LIMIT;
    let cosim_log = std::fs::File::create(dir.join("cosim.log")).unwrap();
    let id = run_id("external_python");
    let mut cosim_run = Kill(
        Command::new(cosim())
            .current_dir(root())
            .env("COSIM_BIN_DIR", bin_dir())
            .args([
                "run",
                SCENE,
                "--external",
                "fem",
                "--wait-external",
                "60",
                "--quiet",
                // Paused once on the way, to look at a particle (below); a pause changes no bit of the run.
                "--break",
                "t>=0.1",
                "--out",
            ])
            .arg(&out_py)
            .args(["--run-id", &id])
            .stdin(Stdio::null())
            .stdout(cosim_log.try_clone().unwrap())
            .stderr(cosim_log)
            .spawn()
            .unwrap(),
    );
    let node_log = std::fs::File::create(dir.join("python.log")).unwrap();
    let mut node = Kill(
        Command::new(&python)
            .current_dir(root())
            .args(["examples/python/rigid_plate_node.py", "--timeout", "60", "--from"])
            .arg(out_py.join("external.json"))
            .stdin(Stdio::null())
            .stdout(node_log.try_clone().unwrap())
            .stderr(node_log)
            .spawn()
            .unwrap(),
    );
    look_at_a_particle_while_paused(&mut cosim_run, &id, until);
    let status = wait_exit(&mut cosim_run.0, until, "cosim run --external fem");
    let node_status = wait_exit(&mut node.0, until, "the Python node");
    let logs = || {
        format!(
            "cosim: {}\npython: {}",
            std::fs::read_to_string(dir.join("cosim.log")).unwrap_or_default(),
            std::fs::read_to_string(dir.join("python.log")).unwrap_or_default()
        )
    };
    assert!(status.success() && node_status.success(), "{}", logs());
    let joined = json(&out_py.join("external.json"));
    assert_eq!(joined["node"], "fem");
    let s = json(&out_py.join("summary.json"));
    assert_eq!(s["status"], "ok");
    assert_eq!(s["mode"], "processes");
    assert!(s["contact_stats"]["contacts"].as_u64().unwrap() > 0);
    eprintln!(
        "python node: {} coupled steps in {:.1} s ({:.0} steps/s); {}",
        s["steps"],
        s["wall_seconds"].as_f64().unwrap(),
        s["steps"].as_f64().unwrap() / s["wall_seconds"].as_f64().unwrap(),
        std::fs::read_to_string(dir.join("python.log"))
            .unwrap_or_default()
            .trim()
    );

    let statics = run_rust_twin(&out_rs, false);
    let py = std::fs::read(out_py.join("probes.csv")).unwrap();
    let rs = std::fs::read(out_rs.join("probes.csv")).unwrap();
    assert!(py.len() > 100, "probes.csv is empty");
    assert!(py == rs, "the Python node and its Rust twin differ: {}", logs());

    let w = cosim::compare::read_probe(&out_py, "mid_uy").unwrap();
    let late: Vec<f64> = w.iter().filter(|p| p.0 > 0.05).map(|p| p.1).collect();
    let mean = late.iter().sum::<f64>() / late.len() as f64;
    let err = (mean - statics) / statics;
    eprintln!(
        "plate on springs: mean settlement {mean:.4e} m vs statics {statics:.4e} m ({:+.1} %)",
        100.0 * err
    );
    assert!(err.abs() < 0.10, "{mean} vs {statics}");
}

/// `cosim inspect --particle` on a run whose structure node is an outside program that saves no checkpoint: the
/// particle is shown, and the structure said not to be (the whole query failed before: D25 of the 2026-12-06 sweep of
/// hostile external nodes). Then the run goes on.
fn look_at_a_particle_while_paused(run: &mut Kill, id: &str, until: Instant) {
    let ask = |args: &[&str]| {
        let out = cosim_run(args, Duration::from_secs(60));
        let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
        let doc = serde_json::from_str(&stdout).unwrap_or(serde_json::Value::Null);
        (out.status.code(), doc, stdout + &String::from_utf8_lossy(&out.stderr))
    };
    loop {
        assert!(run.0.try_wait().unwrap().is_none(), "the run ended instead of pausing");
        assert!(Instant::now() < until, "the run did not pause");
        let (code, doc, _) = ask(&["ctl", id, "status"]);
        if code == Some(0) && doc["paused"].as_str().is_some_and(|p| !p.is_empty()) {
            break;
        }
        std::thread::sleep(Duration::from_millis(200));
    }
    let (code, doc, text) = ask(&["inspect", id, "--particle", "0"]);
    assert_eq!(code, Some(0), "{text}");
    assert_eq!(doc["particle"]["id"], 0, "{doc:#}");
    assert!(doc["particle"]["rho"].as_f64().unwrap() > 900.0, "{doc:#}");
    let structure = doc["structure"].as_str().unwrap_or_default();
    assert!(
        structure.starts_with("not shown: ") && structure.contains("fem-node"),
        "{doc:#}"
    );
    let (code, _, text) = ask(&["ctl", id, "resume"]);
    assert_eq!(code, Some(0), "{text}");
}

/// Issue 19: the conformance test for an outside code. A run of the Rust twin, recorded in this process, is replayed
/// with `cosim replay --exec` against the Python node: each of its answers matches the twin's within the tolerance.
/// Byte for byte they do not quite (on 2026-11-27 the first difference was the last bit of a snapshot's kinetic
/// energy at step 3350, a quantity no probe reads): that line is printed, not asserted.
#[test]
fn python_node_replays_a_trace_of_its_rust_twin() {
    let python = python();
    let dir = scratch("external_python_replay");
    run_rust_twin(&dir, true);
    let steps = json(&dir.join("summary.json"))["steps"].as_u64().unwrap();
    let exec = format!(
        "{} {} --timeout 60",
        python.display(),
        root().join("examples/python/rigid_plate_node.py").display()
    );
    let trace = dir.join("trace").display().to_string();
    let replay = |tolerance: &[&str]| {
        let mut cmd = Command::new(cosim());
        cmd.args(["replay", &trace, "--node", "fem", "--exec", &exec])
            .args(tolerance)
            .env("COSIM_BIN_DIR", bin_dir());
        let out = run_bounded(&mut cmd, LIMIT);
        let said = format!(
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        (out.status.success(), said)
    };
    let (ok, said) = replay(&["--rtol", "1e-9", "--atol", "1e-12"]);
    assert!(ok, "{said}");
    assert!(
        said.starts_with(&format!("matched {} steps (fem-node, ", steps + 1)),
        "{said}"
    );
    eprintln!("byte for byte: {}", replay(&[]).1.trim());
}
