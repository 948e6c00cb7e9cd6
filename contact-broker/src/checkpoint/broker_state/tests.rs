//! Unit tests of `BrokerState::check`: every field a crafted checkpoint could get wrong is refused, naming it.

use super::*;
use crate::summary::{ContactStats, Timings};

/// A coupled scene: one 2 × 1 quad solid (6 nodes), a fluid block, one probe.
fn scene() -> Scene {
    let text = r#"
version = 1
[run]
name = "t"
end_time = 1.0
output_interval = 0.1
gravity = [0.0, -9.81]
[fluid]
density = 1000.0
spacing = 0.1
sound_speed = 20.0
[[fluid.block]]
min = [0.0, 0.0]
max = [0.4, 0.4]
[[wall]]
min = [-0.2, -0.2]
max = [2.0, 0.0]
[[solid]]
name = "s"
min = [1.0, 0.0]
max = [1.2, 0.1]
divisions = [2, 1]
material = { model = "linear_elastic", density = 1000.0, youngs_modulus = 1e6, poisson_ratio = 0.3 }
[[probe]]
name = "front"
kind = "surge_front"
component = "x"
"#;
    cosim_proto::scene::parse("t.toml", text, &[]).unwrap()
}

fn state() -> BrokerState {
    BrokerState {
        step: 10,
        t: 0.25,
        next_output: 3,
        next_checkpoint: 2,
        dt_fluid: 1e-3,
        dt_contact: f64::INFINITY,
        dt_structure: f64::INFINITY,
        pending_fem: vec![Correction {
            id: 5,
            dx: [0.0, 1e-4],
            dv: [0.0; 2],
            face: None,
        }],
        pending_sph: vec![Correction {
            id: 15,
            dx: [1e-4, 0.0],
            dv: [0.1, 0.0],
            face: None,
        }],
        roi: Some([0.9, -0.1, 1.3, 0.2]),
        load: Some(vec![[0.0; 2]; 6]),
        load_log: LoadLog::default(),
        owed: Vec::new(),
        exchanged: 40,
        fluid_origin: Some(vec![[0.05, 0.05]; 16]),
        rows: vec![(0.0, vec![0.4]), (0.1, vec![0.45]), (0.2, vec![0.5])],
        summary: Summary {
            status: cosim_proto::run_status::RunStatus::Ok,
            message: String::new(),
            run_id: "r".into(),
            scene: "t".into(),
            steps: 10,
            fem_substeps: 100,
            sph_substeps: 10,
            sim_time: 0.25,
            wall_seconds: 1.0,
            particles: 16,
            fem_nodes: 6,
            fem_elements: 2,
            solver: "wcsph".into(),
            contact: "node_to_segment".into(),
            mode: "in-process".into(),
            frames: 3,
            samples: 3,
            timings: Timings::default(),
            contact_stats: ContactStats::default(),
            counts: Default::default(),
            reaction_relaxation: None,
            contact_step_bound: None,
            energy_growth: None,
            trace: None,
            solid_in_wall: None,
        },
    }
}

/// The refusal of `state` after `edit`.
fn refused(edit: impl FnOnce(&mut BrokerState)) -> String {
    let mut s = state();
    edit(&mut s);
    s.check(&scene()).expect_err("an inconsistent state is refused")
}

#[test]
fn a_consistent_state_passes() {
    assert_eq!(state().check(&scene()), Ok(()));
    assert!(state().check_nodes(6, 16).is_ok());
}

#[test]
fn ids_out_of_range_are_refused_naming_the_field() {
    let e = refused(|s| s.pending_sph[0].id = 16);
    assert_eq!(e, "pending_sph[0].id = 16, but there are 16 fluid particles");
    let e = refused(|s| s.pending_fem[0].id = 6);
    assert_eq!(e, "pending_fem[0].id = 6, but there are 6 structure nodes");
    let e = refused(|s| s.pending_fem[0].dv = [f64::NAN, 0.0]);
    assert!(e.starts_with("pending_fem[0] (id 5)") && e.contains("NaN"), "{e}");
}

#[test]
fn lengths_that_disagree_are_refused_naming_the_field() {
    let e = refused(|s| s.rows[1].1.push(0.0));
    assert_eq!(e, "rows[1] holds 2 values, the scene has 1 probes");
    let e = refused(|s| {
        s.load.as_mut().unwrap().pop();
    });
    assert_eq!(e, "load holds 5 nodes, the structure has 6");
    let e = refused(|s| s.fluid_origin = Some(vec![[0.0; 2]; 17]));
    assert_eq!(e, "fluid_origin holds 17 positions, the fluid has 16 particles");
    let e = refused(|s| s.summary.fem_nodes = 9);
    assert_eq!(e, "summary.fem_nodes = 9 where the scene's solids have 6 nodes");
    let e = refused(|s| s.rows.push((0.25, vec![0.5])));
    assert_eq!(e, "summary.samples = 3 and summary.frames = 3 where rows holds 4");
    let entry = |t: f64, node: u32, wall: usize, depth: f64| crate::wall_entry::WallEntry {
        t,
        solid: "gate".into(),
        node,
        wall,
        depth,
    };
    let mut fine = state();
    fine.summary.solid_in_wall = Some(entry(0.25, 5, 0, 1e-3));
    fine.check(&scene()).unwrap();
    for bad in [
        entry(0.3, 5, 0, 1e-3),
        entry(0.25, 6, 0, 1e-3),
        entry(0.25, 5, 1, 1e-3),
        entry(0.25, 5, 0, 0.0),
        entry(f64::NAN, 5, 0, 1e-3),
    ] {
        let e = refused(|s| s.summary.solid_in_wall = Some(bad.clone()));
        assert!(
            e.starts_with("summary.solid_in_wall = ") && e.ends_with("node below 6, wall below 1)"),
            "{e}"
        );
    }
    let e = state().check_nodes(6, 17).unwrap_err().to_string();
    assert!(e.contains("16 fluid particles") && e.contains("have 6 and 17"), "{e}");
}

#[test]
fn numbers_that_would_stall_or_poison_the_run_are_refused() {
    for dt in [0.0, -1e-3, f64::NAN] {
        let e = refused(|s| s.dt_fluid = dt);
        assert_eq!(e, format!("dt_fluid = {dt} is not a positive step"));
        let e = refused(|s| s.dt_contact = dt);
        assert_eq!(e, format!("dt_contact = {dt} is not a positive step"));
        let e = refused(|s| s.dt_structure = dt);
        assert_eq!(e, format!("dt_structure = {dt} is not a positive step"));
    }
    // Positive, but below coupling.max_dt / 2^32 (the scene's default max_dt, 1e-4 s).
    let floor = cosim_proto::scene::shortest_step(scene().coupling.max_dt);
    assert_eq!(
        refused(|s| s.dt_fluid = 1e-300),
        format!(
            "dt_fluid = 1e-300 s is below coupling.max_dt / 2^32 = {} s, the shortest step a run takes",
            Num(floor)
        )
    );
    assert!(refused(|s| s.dt_structure = floor * 0.5).starts_with("dt_structure = "));
    let mut at_floor = state();
    at_floor.dt_contact = floor;
    assert_eq!(at_floor.check(&scene()), Ok(()));
    let e = refused(|s| s.next_output = 2);
    assert!(
        e.starts_with("next_output = 2: output time 0.2 s is not after t = 0.25 s"),
        "{e}"
    );
    let e = refused(|s| s.rows[2].0 = f64::NAN);
    assert!(e.starts_with("rows[2]: t = NaN"), "{e}");
    let e = refused(|s| s.t = f64::INFINITY);
    assert_eq!(e, "t = inf is not a time");
    let e = refused(|s| s.summary.steps = 11);
    assert_eq!(e, "summary.steps = 11 where step = 10");
    let e = refused(|s| s.owed = vec![[0.0, f64::NAN]]);
    assert_eq!(e, "owed[0] = [0.0, NaN] is not finite");
    let e = refused(|s| s.owed = vec![[0.0; 2]; 7]);
    assert_eq!(e, "owed holds 7 nodes, the structure has 6");
}

#[test]
fn an_energy_balance_without_a_budget_is_refused() {
    let growth = |budget: f64, largest: f64, rounding: f64| {
        refused(|s| {
            s.summary.energy_growth = Some(crate::energy_balance::EnergyGrowth {
                largest,
                at: 0.1,
                budget,
                initial: -1.0,
                rounding,
            })
        })
    };
    for (budget, largest, rounding) in [
        (0.0, 0.1, 0.0),
        (-2.0, 0.1, 0.0),
        (f64::NAN, 0.1, 0.0),
        (2.0, f64::INFINITY, 0.0),
        (2.0, -0.5, 0.0),
        (2.0, 0.1, -1e-12),
        (2.0, 0.1, f64::NAN),
    ] {
        let e = growth(budget, largest, rounding);
        assert!(e.starts_with("summary.energy_growth = "), "{e}");
        assert!(
            e.ends_with("is not a balance (budget > 0, gain and rounding ≥ 0, all finite)"),
            "{e}"
        );
    }
}
