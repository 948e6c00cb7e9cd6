//! Sub-cycling, clamps, corrections and typed numerical failure.

mod common;

use common::*;
use cosim_proto::messages::Correction;
use cosim_proto::scene::{ElementKind, MaterialModel};
use fem_node::FemError;

fn bar(element: ElementKind) -> fem_node::FemSolver {
    let spec = cantilever(
        [0.0, 0.35],
        [0.0, 0.02],
        [35, 2],
        element,
        material(MaterialModel::LinearElastic, 1000.0, 1.4e6, 0.4),
    );
    solver(spec, [0.0, -2.0], 0.9)
}

#[test]
fn advance_sub_cycles_within_the_stable_step() {
    for element in [ElementKind::Quad4, ElementKind::Tri3] {
        let mut s = bar(element);
        let stable = s.stable_dt();
        // c_d = sqrt((λ + 2μ)/ρ) = sqrt(3e6/1e3); square 10 mm cells: L_e = 10 mm/√2 (quad), triangle altitude
        // 10 mm/√2 too.
        let expected = 0.9 * 0.01 / 2f64.sqrt() / 3000f64.sqrt();
        assert!(
            rel_err(stable, expected) < 1e-9,
            "{element:?}: stable dt {stable} vs {expected}"
        );
        let dt = 7.3 * stable;
        let k = s.advance(dt).unwrap();
        assert_eq!(k, 8);
        assert_eq!(s.state().step, 8);
        assert!((s.state().t - dt).abs() < 1e-15);
        assert_eq!(s.advance(0.0).unwrap(), 0);
        assert!(matches!(s.advance(-1.0), Err(FemError::InvalidParameter { .. })));
    }
}

/// `advance_until` asks before each sub-step but the first: stopped at its third question it has taken 3 of the 8
/// sub-steps, bit for bit those of `advance`; never stopped it is `advance`.
#[test]
fn advance_until_stops_between_two_sub_steps() {
    let (mut whole, mut cut, mut three) = (
        bar(ElementKind::Quad4),
        bar(ElementKind::Quad4),
        bar(ElementKind::Quad4),
    );
    let dt = 7.3 * whole.stable_dt();
    assert_eq!(whole.advance(dt).unwrap(), 8);
    let asked = std::cell::Cell::new(0);
    let stop = || {
        asked.set(asked.get() + 1);
        (asked.get() == 3).then_some("enough")
    };
    match cut.advance_until(dt, &stop) {
        Err(e @ FemError::Stopped { done: 3, of: 8, .. }) => assert!(e.to_string().ends_with(": enough"), "{e}"),
        other => panic!("expected Stopped after 3 of 8, got {other:?}"),
    }
    for _ in 0..3 {
        three.substep(dt / 8.0).unwrap();
    }
    assert_eq!(cut.state().step, 3);
    let bits = |s: &fem_node::FemSolver| s.state().x.iter().flatten().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&cut), bits(&three));
    let mut never = bar(ElementKind::Quad4);
    assert_eq!(never.advance_until(dt, &|| None).unwrap(), 8);
    assert_eq!(bits(&never), bits(&whole));
}

#[test]
fn clamped_nodes_stay_put_and_ignore_corrections() {
    let mut s = bar(ElementKind::Quad4);
    let fixed: Vec<usize> = (0..s.model().node_count()).filter(|&k| s.model().fixed()[k]).collect();
    assert_eq!(fixed.len(), 3);
    let free = s.model().nearest_node(0, [0.35, 0.01]).unwrap();
    s.apply_corrections(&[
        Correction {
            id: fixed[1] as u32,
            dx: [1e-3, 0.0],
            dv: [1.0, 0.0],
            face: None,
        },
        Correction {
            id: free as u32,
            dx: [0.0, 1e-4],
            dv: [0.0, 0.5],
            face: None,
        },
    ])
    .unwrap();
    // A correction for a node the mesh does not have is an error, and nothing of its list is applied.
    let before = s.state().clone();
    let unknown = s.apply_corrections(&[
        Correction {
            id: free as u32,
            dx: [0.0, 1.0],
            dv: [0.0, 1.0],
            face: None,
        },
        Correction {
            id: u32::MAX,
            dx: [1.0, 1.0],
            dv: [1.0, 1.0],
            face: None,
        },
    ]);
    assert_eq!(
        unknown.unwrap_err().to_string(),
        format!(
            "corrections: correction for node {}, but the mesh has {} nodes",
            u32::MAX,
            s.model().node_count()
        )
    );
    assert_eq!(s.state().x, before.x);
    let x_free = s.state().x[free];
    assert_eq!(s.state().v[free], [0.0, 0.5]);
    assert!((x_free[1] - 0.01 - 1e-4).abs() < 1e-15);
    s.advance(0.05).unwrap();
    for &k in &fixed {
        assert_eq!(s.state().x[k], s.model().reference()[k]);
        assert_eq!(s.state().v[k], [0.0; 2]);
    }
}

#[test]
fn inverted_element_is_a_typed_error() {
    let mut s = bar(ElementKind::Quad4);
    // Throw the far corner of the last element across the bar.
    let k = s.model().nearest_node(0, [0.35, 0.0]).unwrap();
    s.apply_corrections(&[Correction {
        id: k as u32,
        dx: [-0.015, 0.03],
        dv: [0.0; 2],
        face: None,
    }])
    .unwrap();
    match s.advance(1e-4) {
        Err(FemError::Unstable { element, reason, .. }) => {
            assert!(
                s.model().elements()[element].nodes().contains(&(k as u32)),
                "element {element}"
            );
            assert!(reason.contains("inverted") || reason.contains("collapsed"), "{reason}");
        }
        other => panic!("expected an instability, got {other:?}"),
    }
}

#[test]
fn blow_up_is_a_typed_error() {
    // Stepping far above the stable step must end in an error, not a panic or NaNs.
    let mut s = bar(ElementKind::Tri3);
    s.set_velocities(|_, p| [0.0, p[0]]);
    let dt = 5.0 * s.stable_dt();
    let err = (0..100_000).find_map(|_| s.substep(dt).err()).expect("no failure");
    assert!(matches!(err, FemError::Unstable { .. }), "{err}");
}

#[test]
fn energies_and_stress_at_rest() {
    let s = bar(ElementKind::Quad4);
    let e = s.energies();
    assert_eq!(e.len(), 1);
    // Grid coordinates carry round-off, so "zero" is relative to E = 1.4 MPa and a strain energy scale E·A.
    assert_eq!((e[0].kinetic, e[0].potential), (0.0, 0.0));
    assert!(e[0].strain.abs() < 1e-20, "{e:?}");
    let worst = s.cell_stress().iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(worst < 1e-12 * 1.4e6, "stress at rest {worst}");
    let m: f64 = s.model().masses().iter().sum();
    assert!(rel_err(m, 1000.0 * 0.35 * 0.02) < 1e-12);
    let mesh = s.mesh_message();
    assert_eq!(
        (
            mesh.nodes.len(),
            mesh.cells.len(),
            mesh.interface.len(),
            mesh.fixed.len()
        ),
        (108, 70, 74, 3)
    );
}

#[test]
fn stable_step_is_stable_on_elongated_elements() {
    // Measured critical safety factors of these meshes (random velocities, 4000 steps): quads 1.00–1.41,
    // triangles 0.943–1.2 (the lower ends for 5:1 and longer cells), so the default cfl = 0.9 holds for both.
    for (element, cfl) in [(ElementKind::Quad4, 1.0), (ElementKind::Tri3, 0.9)] {
        let mut spec = cantilever(
            [0.0, 1.0],
            [0.0, 1.0],
            [60, 12],
            element,
            material(MaterialModel::LinearElastic, 1000.0, 1.0e6, 0.3),
        );
        spec.fixed.clear();
        let mut s = solver(spec, [0.0, 0.0], cfl);
        let mut seed = 12345u64;
        let mut random = move || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let v: Vec<[f64; 2]> = (0..s.model().node_count())
            .map(|_| [1e-6 * random(), 1e-6 * random()])
            .collect();
        s.set_velocities(|k, _| v[k]);
        s.refresh_accelerations().unwrap();
        let e0 = s.total_energy();
        let dt = s.stable_dt();
        for _ in 0..4000 {
            s.substep(dt).unwrap();
        }
        let ratio = s.total_energy() / e0;
        assert!(ratio < 10.0, "{element:?} at cfl {cfl}: energy grew {ratio}x");
    }
}
