//! The content checks of each message type: what passes, and the one line naming what does not.

use super::*;
use crate::messages::ContactFace;

fn mesh() -> FemMesh {
    FemMesh {
        solid_names: vec!["plate".into()],
        nodes: vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
        masses: vec![0.25; 4],
        node_solid: vec![0; 4],
        cells: vec![vec![0, 1, 2, 3]],
        cell_solid: vec![0],
        interface: vec![
            Segment { a: 0, b: 1 },
            Segment { a: 1, b: 2 },
            Segment { a: 2, b: 3 },
            Segment { a: 3, b: 0 },
        ],
        fixed: vec![0, 1],
        dt_stable: 1e-4,
    }
}

#[test]
fn a_consistent_mesh_passes_and_each_inconsistency_is_named() {
    assert_eq!(mesh().validate(), Ok(()));
    type Spoil = fn(&mut FemMesh);
    let cases: Vec<(Spoil, &str)> = vec![
        (
            |m| m.interface[2].b = 4,
            "fem/mesh interface[2][1] = 4: out of range (4 nodes)",
        ),
        (
            |m| m.masses.truncate(3),
            "fem/mesh masses = 3 entries: one per node expected: 4",
        ),
        (
            |m| m.masses[1] = -1.0,
            "fem/mesh masses[1] = -1.0: must be a number > 0 and ≤ 1e50",
        ),
        (
            |m| m.nodes[3][1] = f64::NAN,
            "fem/mesh nodes[3][1] = NaN: not a finite number within ±1e50",
        ),
        (
            |m| m.cells[0][3] = 7,
            "fem/mesh cells[0][3] = 7: out of range (4 nodes)",
        ),
        (
            |m| m.node_solid[2] = 1,
            "fem/mesh node_solid[2] = 1: out of range (1 solids)",
        ),
        (
            |m| m.cell_solid[0] = 3,
            "fem/mesh cell_solid[0] = 3: out of range (1 solids)",
        ),
        (|m| m.fixed.push(9), "fem/mesh fixed[2] = 9: out of range (4 nodes)"),
        (
            |m| m.dt_stable = 0.0,
            "fem/mesh dt_stable = 0.0: must be a number > 0 and ≤ 1e50",
        ),
        (
            |m| m.dt_stable = f64::NAN,
            "fem/mesh dt_stable = NaN: must be a number > 0 and ≤ 1e50",
        ),
        // The contact's geometry (2026-12-06): a segment between two nodes at one point, and a boundary that goes
        // clockwise (its normals point into the solid).
        (
            |m| m.nodes[2] = m.nodes[1],
            "fem/mesh interface[1] = 1→2: a segment of zero length (both nodes at [1.0, 0.0])",
        ),
        (
            |m| m.interface.iter_mut().for_each(|s| (s.a, s.b) = (s.b, s.a)),
            "fem/mesh interface = the segments of solid 0 (plate): they go clockwise round it or enclose nothing \
             (signed area -1e0 m²): they must go counter-clockwise, so that their normals point out of the solid",
        ),
        // Found by the same sweep (D15): cells of one node, cells turned inside out, a segment or a clamped node
        // listed twice.
        (
            |m| m.cells[0] = vec![0, 0, 0, 0],
            "fem/mesh cells[0] = [0, 0, 0, 0]: node 0 is in it twice: a cell joins different nodes",
        ),
        (
            |m| m.cells[0].reverse(),
            "fem/mesh cells[0] = [3, 2, 1, 0]: its nodes go clockwise or enclose nothing (signed area -1e0 m²): a \
             cell's nodes go counter-clockwise",
        ),
        (
            |m| m.nodes[2] = [0.0, 0.0],
            "fem/mesh cells[0] = [0, 1, 2, 3]: its nodes go clockwise or enclose nothing (signed area 0e0 m²): a \
             cell's nodes go counter-clockwise",
        ),
        (
            |m| m.interface.push(Segment { a: 1, b: 2 }),
            "fem/mesh interface[4] = 1→2: the segment of interface[1] again: each boundary segment is listed once",
        ),
        (
            |m| m.interface.push(Segment { a: 2, b: 1 }),
            "fem/mesh interface[4] = 2→1: the segment of interface[1] again: each boundary segment is listed once",
        ),
        (
            |m| m.fixed.push(0),
            "fem/mesh fixed[2] = 0: node 0 is listed twice (also fixed[0])",
        ),
    ];
    for (spoil, want) in cases {
        let mut m = mesh();
        spoil(&mut m);
        assert_eq!(m.validate().unwrap_err().to_string(), want);
    }
}

#[test]
fn a_state_must_report_exactly_the_interface_it_was_asked_for() {
    let m = mesh();
    let ids = m.interface_nodes();
    let asked = Asked {
        interface: true,
        snapshot: false,
        interface_ids: &ids,
        reach: Reach::ANY,
    };
    let state = FemState {
        ids: ids.clone(),
        x: m.nodes.clone(),
        v: vec![[0.0; 2]; 4],
        substeps: 1,
        dt_stable: 1e-4,
        compute_seconds: 0.0,
        snapshot: None,
    };
    assert_eq!(state.validate(&m, asked), Ok(()));
    let mut wrong = state.clone();
    wrong.ids[2] = 168;
    // The message the broker gave before named two equal counts ("reported 4 …, the mesh has 4").
    assert_eq!(
        wrong.validate(&m, asked).unwrap_err().to_string(),
        "fem/state ids[2] = 168: the mesh's interface node 2 is node 2"
    );
    let mut nan = state.clone();
    nan.v[1][0] = f64::INFINITY;
    let e = nan.validate(&m, asked).unwrap_err();
    assert!(e.is_non_finite());
    assert_eq!(
        e.to_string(),
        "fem/state v[1][0] = inf: not a finite number within ±1e50"
    );
    // Finite but beyond any state a run can hold (found 2026-12-06 by a sweep of hostile external nodes: a structure
    // at ±1e308 m held the broker's contact grid in an endless loop, one at 1e200 m/s blew up the fluid node, which
    // took the blame): refused as a node that blew up.
    let mut far = state.clone();
    far.x[3][1] = -1e308;
    let e = far.validate(&m, asked).unwrap_err();
    assert!(e.is_non_finite());
    assert_eq!(
        e.to_string(),
        "fem/state x[3][1] = -1e308: not a finite number within ±1e50"
    );
    let mut fast = state.clone();
    fast.v[0][0] = 1e200;
    assert!(fast.validate(&m, asked).unwrap_err().is_non_finite());
    let mut edge = state.clone();
    edge.x[3][1] = 1e50;
    assert_eq!(edge.validate(&m, asked), Ok(()));
    // Seconds of computation whose sum over a run would overflow summary.json's timings to null (a complete run's
    // summary was then taken for a stub and overwritten).
    let mut slow = state.clone();
    slow.compute_seconds = 1.7e308;
    assert_eq!(
        slow.validate(&m, asked).unwrap_err().to_string(),
        "fem/state compute_seconds = 1.7e308: must be a number of seconds within 0…1e9"
    );
    slow.compute_seconds = 1e9;
    assert_eq!(slow.validate(&m, asked), Ok(()));
    // A speed no run of the scene reaches (D12 of the sweep: 1e20 m/s blew up the fluid node, which took the blame)
    // is the sender's blow-up, finite or not; a speed at the limit passes.
    let limited = Asked {
        reach: Reach {
            speed: 100.0,
            ..Reach::ANY
        },
        ..asked
    };
    let mut flung = state.clone();
    flung.v[2] = [60.0, -80.0];
    assert_eq!(flung.validate(&m, limited), Ok(()));
    flung.v[2] = [60.0, -80.001];
    let e = flung.validate(&m, limited).unwrap_err();
    assert!(e.blew_up() && !e.is_non_finite());
    assert_eq!(
        e.to_string(),
        "fem/state v[2] = [60.0, -80.001]: 100.001 m/s, faster than any run of the scene moves (100 m/s: 10 times \
         its fastest wave speed)"
    );
    // An interface segment collapsed to a point (D12c: half the interface nodes at one point).
    let mut collapsed = state.clone();
    collapsed.x[1] = collapsed.x[0];
    let e = collapsed.validate(&m, asked).unwrap_err();
    assert!(e.blew_up());
    assert_eq!(
        e.to_string(),
        format!(
            "fem/state x = {:?} for nodes 0 and 1: interface segment 0 collapsed to a point",
            state.x[0]
        )
    );
    // A position no run of the scene reaches (D12: a structure at 1e10 m with a plausible speed was taken): the box
    // where it starts (the unit square) grown by 100 m/s over 0.5 s; its edge passes.
    let far = Asked {
        reach: Reach::new(100.0, ([0.0, 0.0], [1.0, 1.0]), 0.5),
        ..asked
    };
    let mut moved = state.clone();
    moved.x[3] = [-50.0, 51.0];
    assert_eq!(moved.validate(&m, far), Ok(()));
    moved.x[3] = [1e10, 0.5];
    let e = moved.validate(&m, far).unwrap_err();
    assert!(e.blew_up() && !e.is_non_finite());
    assert_eq!(
        e.to_string(),
        "fem/state x[3] = [10000000000.0, 0.5]: farther than any run of the scene reaches (x in -50…51 m, y in -50…51 \
         m: where it starts, grown by 10 times its fastest wave speed over its end time)"
    );
    let no_snapshot = Asked {
        snapshot: true,
        ..asked
    };
    assert_eq!(
        state.validate(&m, no_snapshot).unwrap_err().to_string(),
        "fem/state snapshot = none: asked for at an output time"
    );
}

#[test]
fn fluid_ids_must_be_in_range_ascending_and_once() {
    let setup = SphSetup {
        particles: 3,
        spacing: 0.01,
        h: 0.013,
        density: 1000.0,
        walls: vec![],
        dt_stable: 1e-4,
        sensors: 0,
    };
    let asked = Asked {
        interface: true,
        snapshot: false,
        interface_ids: &[],
        reach: Reach::ANY,
    };
    let state = |ids: Vec<u32>| SphState {
        x: vec![[0.0; 2]; ids.len()],
        v: vec![[0.0; 2]; ids.len()],
        m: vec![0.1; ids.len()],
        ids,
        substeps: 1,
        dt_stable: 1e-4,
        compute_seconds: 0.0,
        snapshot: None,
    };
    assert_eq!(state(vec![0, 2]).validate(&setup, asked), Ok(()));
    assert_eq!(
        state(vec![0, 3]).validate(&setup, asked).unwrap_err().to_string(),
        "sph/state ids[1] = 3: out of range (3 particles)"
    );
    assert_eq!(
        state(vec![2, 2]).validate(&setup, asked).unwrap_err().to_string(),
        "sph/state ids[1] = 2: ids must be ascending, each once"
    );
    let mut fast = state(vec![1]);
    fast.v[0] = [0.0, -1e20];
    let limited = Asked {
        reach: Reach {
            speed: 240.0,
            ..Reach::ANY
        },
        ..asked
    };
    assert_eq!(
        fast.validate(&setup, limited).unwrap_err().to_string(),
        "sph/state v[0] = [0.0, -1e20]: 1e20 m/s, faster than any run of the scene moves (240 m/s: 10 times its \
         fastest wave speed)"
    );
    let mut zero_dt = state(vec![1]);
    zero_dt.dt_stable = 0.0;
    assert_eq!(
        zero_dt.validate(&setup, asked).unwrap_err().to_string(),
        "sph/state dt_stable = 0.0: a stable step must be > 0"
    );
}

#[test]
fn a_command_longer_than_max_dt_or_for_an_unknown_id_is_refused() {
    let cmd = StepCommand {
        dt: 1e-4,
        corrections: vec![Correction {
            id: 3,
            dx: [0.0; 2],
            dv: [1.0, 0.0],
            face: None,
        }],
        roi: None,
        want_interface: true,
        want_snapshot: false,
        stop: false,
    };
    assert_eq!(cmd.validate("broker/fem", 4, 1e-4), Ok(()));
    assert_eq!(
        cmd.validate("broker/fem", 3, 1e-4).unwrap_err().to_string(),
        "broker/fem corrections.id[0] = 3: out of range (3 ids)"
    );
    let long = StepCommand {
        dt: 1e300,
        ..cmd.clone()
    };
    assert_eq!(
        long.validate("broker/sph", 4, 1e-4).unwrap_err().to_string(),
        "broker/sph dt = 1e300: a step is between 0 and coupling.max_dt = 0.0001 s"
    );
    let nan = StepCommand { dt: f64::NAN, ..cmd };
    assert!(nan.validate("broker/sph", 4, 1e-4).is_err());
}

/// Protocol 3: a face comes with a fluid correction only, with a finite point and a unit normal.
#[test]
fn a_correction_s_face_is_checked() {
    let with = |face: ContactFace| StepCommand {
        dt: 1e-4,
        corrections: vec![Correction {
            id: 1,
            dx: [0.0; 2],
            dv: [0.0, 0.1],
            face: Some(face),
        }],
        roi: None,
        want_interface: true,
        want_snapshot: false,
        stop: false,
    };
    let good = ContactFace {
        point: [0.5, 0.0],
        normal: [0.6, 0.8],
    };
    assert_eq!(with(good).validate("broker/sph", 2, 1e-4), Ok(()));
    assert_eq!(
        with(good).validate("broker/fem", 2, 1e-4).unwrap_err().to_string(),
        "broker/fem corrections.face[0] = a face: faces come with the fluid's corrections only"
    );
    let long = ContactFace {
        normal: [0.6, 0.9],
        ..good
    };
    assert_eq!(
        with(long).validate("broker/sph", 2, 1e-4).unwrap_err().to_string(),
        "broker/sph corrections.face.normal[0] = [0.6, 0.9]: must be a unit vector"
    );
    let nan = ContactFace {
        point: [f64::NAN, 0.0],
        ..good
    };
    assert!(with(nan).validate("broker/sph", 2, 1e-4).is_err());
    let nan_normal = ContactFace {
        normal: [f64::NAN, 1.0],
        ..good
    };
    assert!(with(nan_normal).validate("broker/sph", 2, 1e-4).is_err());
}

/// The limit is ten times the fastest of the fluid's sound speed and the solids' bar wave speeds; none without one.
#[test]
fn the_reach_is_the_start_grown_by_the_speed_over_the_end_time() {
    let r = Reach::new(240.0, ([0.0, -1.0], [2.0, 0.5]), 0.25);
    assert_eq!((r.min, r.max, r.speed), ([-60.0, -61.0], [62.0, 60.5], 240.0));
    // No wave speed, or an end time that makes it infinite: no bound.
    assert_eq!(Reach::new(f64::INFINITY, ([0.0; 2], [1.0; 2]), 1.0), Reach::ANY);
    assert_eq!(Reach::new(1e300, ([0.0; 2], [1.0; 2]), 1e300).max, [f64::INFINITY; 2]);
}

#[test]
fn the_speed_limit_is_ten_times_the_fastest_wave_speed() {
    assert_eq!(speed_limit(Some(24.0), [104.0, 3.0]), 1040.0);
    assert_eq!(speed_limit(Some(24.0), []), 240.0);
    assert_eq!(speed_limit(None, [5000.0]), 50000.0);
    assert_eq!(speed_limit(None, [f64::NAN]), f64::INFINITY);
    assert_eq!(speed_limit(None, []), f64::INFINITY);
}
