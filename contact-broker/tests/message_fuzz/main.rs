//! Message-level fuzzing of the trust boundary (`docs/PROTOCOL.md` §7 "Contents"): well-framed messages with
//! inconsistent contents — ids out of range, lengths that disagree, NaN and infinities, negative masses, empty and
//! huge arrays — fed to the broker's coordinator (as the answers of real in-process nodes, spoilt at a random step)
//! and to both nodes' command handlers. None may panic or hang; each is refused, naming the field, and a node given an
//! unusable command applies none of it.

use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};

use contact_broker::coordinator::{self, Control, Nodes, RunInfo};
use contact_broker::link::{InProcess, LinkError};
use cosim_proto::messages::{Correction, StepCommand};
use cosim_proto::run_status::RunStatus;
use cosim_proto::scene::{self, LoadedScene};
use fem_node::core::FemCore;
use proptest::prelude::*;
use sph_node::core::SphCore;

mod spoils;
use spoils::{spoil_fem, spoil_mesh, spoil_setup, spoil_sph, spoils, FemSpoil, MeshSpoil, SetupSpoil, SphSpoil, Spoil};

/// The hydrostatic plate, coarse: 200 fluid particles on a 20 × 2 plate, 12 coupling steps, output every 4.
fn scene() -> LoadedScene {
    let path = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/hydrostatic_plate.toml"));
    let overrides = [
        "fluid.spacing=0.1",
        "solid[0].divisions=[20, 2]",
        "run.end_time=0.0012",
        "run.output_interval=0.0004",
    ];
    scene::load(&path, &overrides.map(String::from)).expect("the shipped scene loads")
}

fn out_dir() -> PathBuf {
    static N: AtomicU64 = AtomicU64::new(0);
    let dir = std::env::temp_dir().join(format!(
        "cosim-message-fuzz-{}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    ));
    std::fs::create_dir_all(&dir).expect("temporary folder");
    dir
}

/// What a spoilt run ended with: its status and message, and the field the spoil named (None when the spoil did not
/// apply to any message of this run, e.g. a snapshot spoil at a step without one).
fn run_spoilt(spoil: &Spoil) -> (RunStatus, String, Option<&'static str>) {
    let scene = scene();
    let fem = FemCore::new(&scene.scene).expect("fem core");
    let sph = SphCore::new(&scene.scene).expect("sph core");
    let particles = sph.setup().particles;
    let (mut mesh, mut setup) = (fem.mesh().clone(), sph.setup().clone());
    let mut field = None;
    match spoil {
        Spoil::Mesh(how) => field = Some(spoil_mesh(&mut mesh, how)),
        Spoil::Setup(how) => field = Some(spoil_setup(&mut setup, how)),
        _ => {}
    }
    let applied = std::rc::Rc::new(std::cell::Cell::new(None));
    let (fem_spoil, sph_spoil) = (spoil.clone(), spoil.clone());
    let (fem_applied, sph_applied) = (applied.clone(), applied.clone());
    let (mut fem, mut sph) = (fem, sph);
    let (mut fem_step, mut sph_step) = (0u64, 0u64);
    let failed = |node: &str, message: String| LinkError::Failed {
        node: node.into(),
        message,
    };
    let mut fem_link = InProcess::new(mesh, move |cmd: &StepCommand| {
        let mut state = fem.handle(cmd).map_err(|e| failed("fem-node", e.to_string()))?;
        if let (Some(s), Spoil::Fem { step, how }) = (state.as_mut(), &fem_spoil) {
            if *step == fem_step {
                fem_applied.set(spoil_fem(s, how).or(fem_applied.get()));
            }
        }
        fem_step += 1;
        Ok(state)
    });
    let mut sph_link = InProcess::new(setup, move |cmd: &StepCommand| {
        let mut state = sph.handle(cmd).map_err(|e| failed("sph-node", e.to_string()))?;
        if let (Some(s), Spoil::Sph { step, how }) = (state.as_mut(), &sph_spoil) {
            if *step == sph_step {
                sph_applied.set(spoil_sph(s, particles, how).or(sph_applied.get()));
            }
        }
        sph_step += 1;
        Ok(state)
    });
    let out = out_dir();
    let info = RunInfo {
        run_id: "fuzz".into(),
        mode: "in-process".into(),
        out: out.clone(),
    };
    let nodes = Nodes {
        fem: Some(&mut fem_link),
        sph: Some(&mut sph_link),
    };
    let outcome = coordinator::run(&scene, nodes, &info, &mut |_| Control::Continue(()));
    let _ = std::fs::remove_dir_all(&out);
    let field = field.or(applied.get());
    (outcome.summary.status, outcome.summary.message, field)
}

proptest! {
    // A fixed seed: the same 96 messages every run (CI on a clean clone draws nothing new).
    #![proptest_config(ProptestConfig {
        cases: 96,
        failure_persistence: None,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x2026_1127),
        ..ProptestConfig::default()
    })]

    /// The broker's side: every spoilt registration or answer ends the run `failed` (or `unstable` for a NaN or an
    /// infinity in a state) with a message that names the node, the message and the field; none panics or hangs.
    #[test]
    fn the_broker_refuses_every_inconsistent_message_naming_its_field(spoil in spoils()) {
        let (status, message, field) = run_spoilt(&spoil);
        match field {
            None => prop_assert_eq!(status, RunStatus::Ok, "{}", message),
            Some(field) => {
                prop_assert!(status == RunStatus::Failed || status == RunStatus::Unstable, "{status}: {message}");
                prop_assert!(message.contains("sent an unusable message"), "{message}");
                let node = match spoil {
                    Spoil::Mesh(_) | Spoil::Fem { .. } => "fem-node",
                    Spoil::Setup(_) | Spoil::Sph { .. } => "sph-node",
                };
                prop_assert!(message.contains(node), "{node} not in: {message}");
                prop_assert!(message.contains(&format!(" {field}")), "field `{field}` not in: {message}");
            }
        }
    }
}

/// The cases of the 2026-12-06 sweep of hostile external nodes, each of which ran on (`ok`, hung, or filled the
/// memory) before, drawn every time rather than when the fuzz's seed happens to: registrations that disagree with
/// the scene, a coupled structure without a surface, finite numbers beyond any state (a structure at 1e308 m or
/// 1e200 m/s, a mass of 1.7e308 kg/m) and seconds of computation that overflow the run's timings.
#[test]
fn the_sweeps_cases_are_refused_naming_their_field() {
    let cases = [
        (
            Spoil::Setup(SetupSpoil::Spacing(1e-300)),
            "sph/setup spacing = 1e-300: the scene gives 0.1",
        ),
        (
            Spoil::Setup(SetupSpoil::Spacing(0.2)),
            "sph/setup spacing = 0.2: the scene gives 0.1",
        ),
        (
            Spoil::Setup(SetupSpoil::H(0.5)),
            "sph/setup h = 0.5: the scene gives 0.13",
        ),
        (
            Spoil::Setup(SetupSpoil::Density(1e6)),
            "sph/setup density = 1000000: the scene gives 1000",
        ),
        (Spoil::Mesh(MeshSpoil::NoInterface), "fem/mesh interface = 0 entries"),
        // The mesh's geometry and the scene's solids (D15): a cell inside out, a segment and a clamped node listed
        // twice, a solid the scene does not have.
        (
            Spoil::Mesh(MeshSpoil::ReversedCell(0)),
            "fem/mesh cells[0] = [21, 22, 1, 0]: its nodes go clockwise or enclose nothing",
        ),
        (
            Spoil::Mesh(MeshSpoil::SegmentTwice(3)),
            "fem/mesh interface[44] = 3→4: the segment of interface[3] again",
        ),
        (
            Spoil::Mesh(MeshSpoil::SecondSolid),
            "fem/mesh solid_names = [\"plate\", \"intruder\"]: the scene's solids are [\"plate\"]",
        ),
        // A plate registered a million times its size (`particle_particle` took 7.7 GB laying points along it).
        (
            Spoil::Mesh(MeshSpoil::Scale(1e6)),
            "fem/mesh interface = 44 segments 2100000 m long together: the scene's solids have 2.1 m of surface (at \
             most 10 times that)",
        ),
        (
            Spoil::Mesh(MeshSpoil::Mass(0, 1.7e308)),
            "fem/mesh masses[0] = 1.7e308: must be a number > 0 and ≤ 1e50",
        ),
        (
            Spoil::Fem {
                step: 3,
                how: FemSpoil::X(0, -1e308),
            },
            "fem/state x[0][0] = -1e308: not a finite number within ±1e50",
        ),
        (
            Spoil::Fem {
                step: 3,
                how: FemSpoil::Seconds(1.7e308),
            },
            "fem/state compute_seconds = 1.7e308: must be a number of seconds within 0…1e9",
        ),
    ];
    for (spoil, want) in cases {
        let (status, message, _) = run_spoilt(&spoil);
        assert_ne!(status, RunStatus::Ok, "{spoil:?}: {message}");
        assert!(message.contains(want), "{spoil:?}: `{want}` not in `{message}`");
    }
}

/// A state no run of the scene reaches, though its numbers are finite (found 2026-12-06 by a sweep of hostile
/// external nodes, D12 and D1b: a structure reporting 1e20 m/s blew up the fluid node, which took the blame; one
/// flung at 1e11 m/s made the coupling step crawl; half of an interface at one point ran on until the fluid blew up)
/// ends the run `unstable` at the step it arrives, naming its sender, the field and the limit. A speed under the
/// limit is taken.
#[test]
fn a_state_no_run_reaches_is_its_senders_blow_up() {
    let cases = [
        (
            Spoil::Fem {
                step: 3,
                how: FemSpoil::V(0, 1e20),
            },
            &[
                "fem-node: sent an unusable message: fem/state v[0] = [1e20, 0.0]: 1e20 m/s, faster than any run of \
                 the scene moves (50000 m/s: 10 times its fastest wave speed)",
            ][..],
        ),
        (
            Spoil::Fem {
                step: 4,
                how: FemSpoil::Collapse,
            },
            &[
                "fem-node: sent an unusable message: fem/state x = ",
                "collapsed to a point",
            ][..],
        ),
        (
            Spoil::Sph {
                step: 2,
                how: SphSpoil::V(-1e11),
            },
            &[
                "sph-node: sent an unusable message: sph/state v[0] = [",
                "-100000000000.0]: 1e11 m/s, faster than any run of the scene moves",
            ][..],
        ),
        // Far from anywhere a run of the scene reaches, at a plausible speed (D12: a structure at 1e10 m was taken):
        // the plate's scene starts within 2.1 m and moves at most 50 km/s for 1.2 ms, 60 m.
        (
            Spoil::Fem {
                step: 3,
                how: FemSpoil::X(0, 1e9),
            },
            &[
                "fem-node: sent an unusable message: fem/state x[0] = [1000000000.0, ",
                "farther than any run of the scene reaches (x in -60",
            ][..],
        ),
        (
            Spoil::Sph {
                step: 2,
                how: SphSpoil::X(-1e9),
            },
            &[
                "sph-node: sent an unusable message: sph/state x[0] = [",
                "-1000000000.0]: farther than any run of the scene reaches",
            ][..],
        ),
    ];
    for (spoil, wants) in cases {
        let (status, message, _) = run_spoilt(&spoil);
        assert_eq!(status, RunStatus::Unstable, "{spoil:?}: {message}");
        for want in wants {
            assert!(message.contains(want), "{spoil:?}: `{want}` not in `{message}`");
        }
    }
    let (status, message, _) = run_spoilt(&Spoil::Fem {
        step: 3,
        how: FemSpoil::V(0, 4.9e4),
    });
    assert_eq!(status, RunStatus::Ok, "{message}");
}

/// A stable step that collapses (found 2026-12-06 by a sweep of hostile external nodes: a fluid node reporting
/// `dt_stable = 1e-300` every step held the run at a frozen time, 79,000 steps in 30 s, until it was killed; a
/// restored contact bound of 1e-300 s the same) ends the run `unstable` at once, naming the node and the value. One
/// such answer is enough: before, that step was taken and the run went on `ok`.
#[test]
fn a_collapsing_stable_step_ends_the_run_unstable_naming_the_node() {
    for (step, dt) in [(2, 1e-300), (5, 1e-20)] {
        let spoil = Spoil::Sph {
            step,
            how: SphSpoil::DtStable(dt),
        };
        let (status, message, _) = run_spoilt(&spoil);
        assert_eq!(status, RunStatus::Unstable, "{dt}: {message}");
        assert!(
            message.starts_with("sph-node: the coupling step collapsed to"),
            "{message}"
        );
        assert!(
            message.contains(&format!("sph/state dt_stable = {dt:e} s")),
            "{message}"
        );
    }
    // A short step that still moves the run on is taken: 1e-12 s against coupling.max_dt / 2^32 = 2.3e-14 s.
    let spoil = Spoil::Sph {
        step: 2,
        how: SphSpoil::DtStable(1e-12),
    };
    let (status, message, _) = run_spoilt(&spoil);
    assert_eq!(status, RunStatus::Ok, "{message}");
}

/// A command the node cannot use: `(what it spoils, the field named)`.
fn bad_commands(count: u32, max_dt: f64) -> Vec<(StepCommand, &'static str)> {
    let fine = |id: u32| Correction {
        id,
        dx: [1e-6, 0.0],
        dv: [0.0, 1e-3],
        face: None,
    };
    let base = StepCommand {
        dt: max_dt,
        corrections: vec![fine(0), fine(count - 1)],
        roi: None,
        want_interface: true,
        want_snapshot: false,
        stop: false,
    };
    let with = |f: &dyn Fn(&mut StepCommand)| {
        let mut c = base.clone();
        f(&mut c);
        c
    };
    vec![
        (with(&|c| c.corrections.push(fine(count))), "corrections.id"),
        (with(&|c| c.corrections.push(fine(u32::MAX))), "corrections.id"),
        (with(&|c| c.corrections[1].dx[0] = f64::NAN), "corrections.dx"),
        (with(&|c| c.corrections[0].dv[1] = f64::INFINITY), "corrections.dv"),
        (with(&|c| c.dt = f64::NAN), "dt"),
        (with(&|c| c.dt = -1e-4), "dt"),
        // A step of 1e300 s made the node sub-step for ever.
        (with(&|c| c.dt = 1e300), "dt"),
        (with(&|c| c.roi = Some([0.0, f64::NAN, 1.0, 1.0])), "roi"),
        // A huge list whose last entry is bad: nothing of it may be applied.
        (
            with(&|c| {
                c.corrections = (0..200_000).map(|i| fine(i % count)).collect();
                c.corrections.push(fine(count + 7));
            }),
            "corrections.id",
        ),
        (
            with(&|c| {
                c.stop = true;
                c.corrections.push(fine(count));
            }),
            "corrections.id",
        ),
    ]
}

/// The nodes' side: a command with an unknown id, a non-finite number, a step out of range or a huge list with one bad
/// entry is an error naming the field, and the node's state (its checkpoint bytes) is unchanged.
#[test]
fn both_nodes_refuse_an_unusable_command_and_apply_none_of_it() {
    let scene = scene();
    let max_dt = scene.scene.coupling.max_dt;
    let mut fem = FemCore::new(&scene.scene).expect("fem core");
    let mut sph = SphCore::new(&scene.scene).expect("sph core");
    let first = StepCommand {
        dt: 0.0,
        corrections: Vec::new(),
        roi: None,
        want_interface: true,
        want_snapshot: true,
        stop: false,
    };
    fem.handle(&first).expect("step 0");
    sph.handle(&first).expect("step 0");
    let nodes = fem.mesh().nodes.len() as u32;
    for (cmd, field) in bad_commands(nodes, max_dt) {
        let before = fem.checkpoint();
        let e = fem.handle(&cmd).expect_err(field).to_string();
        assert!(
            e.contains(&format!("broker/fem {field}")),
            "fem-node: `{field}` not in: {e}"
        );
        assert_eq!(
            fem.checkpoint(),
            before,
            "fem-node applied part of a refused command ({field})"
        );
    }
    let particles = sph.setup().particles;
    for (cmd, field) in bad_commands(particles, max_dt) {
        let before = sph.checkpoint();
        let e = sph.handle(&cmd).expect_err(field).to_string();
        assert!(
            e.contains(&format!("broker/sph {field}")),
            "sph-node: `{field}` not in: {e}"
        );
        assert_eq!(
            sph.checkpoint(),
            before,
            "sph-node applied part of a refused command ({field})"
        );
    }
    // The same commands made legal are taken: the refusals above were for the spoilt field, not the command.
    let legal = StepCommand {
        corrections: vec![Correction {
            id: nodes - 1,
            dx: [0.0; 2],
            dv: [0.0; 2],
            face: None,
        }],
        dt: max_dt,
        ..first.clone()
    };
    assert!(fem.handle(&legal).expect("a legal command").is_some());
    let legal = StepCommand {
        corrections: vec![Correction {
            id: particles - 1,
            dx: [0.0; 2],
            dv: [0.0; 2],
            face: None,
        }],
        ..legal
    };
    assert!(sph.handle(&legal).expect("a legal command").is_some());
}
