//! No WCSPH fluid particle is ever inside a wall: the tall dam break of `cosim/tests/stress/` (a 0.1 × 0.3 m
//! column at Δx = 10 mm slamming into the far wall of a closed 0.3 m tank), stepped as `cosim run` steps it (1 ms
//! coupling steps, each in as many stable steps as it takes), to t = 2.5 s, with every particle checked after every
//! step against every `[[wall]]` box (grown as the wall particles fill it).
//!
//! Without the wall guard ([`WcsphSolver::wall_pushes`]) and the walls' short-range repulsion
//! (`sph_node::boundary::repulsion`) water seeped into the walls from t ≈ 0.19 s (up to 18 particles inside at a
//! time, 1.5 Δx deep by 1.2 s, 3 Δx by 1.57 s) and a particle came out of the tank's back corner at t ≈ 1.88 s.
//! With the guard alone it had to put particles back 144,955 times (55 particles; the settled bottom layer rested on
//! the floor's face and was put back every step); with the repulsion the walls keep the water out themselves and the
//! guard, the last line of defence, must act less than 1 % as often (measured: never). The run must end with finite
//! states.

use std::path::Path;

use sph_node::boundary::wall_guard::WallBoxes;
use sph_node::WcsphSolver;

const T_END: f64 = 2.5;
const COUPLING_DT: f64 = 1e-3;

fn tall_dam_break() -> cosim_proto::scene::Scene {
    let sets: Vec<String> = [
        "fluid.solver=wcsph",
        "fluid.spacing=0.01",
        "fluid.block.max=[0.1,0.3]",
        "wall[0].min=[-0.03,-0.03]",
        "wall[0].max=[0.33,0.0]",
        "wall[1].min=[-0.03,0.0]",
        "wall[1].max=[0.0,0.6]",
        "wall[2].min=[0.3,0.0]",
        "wall[2].max=[0.33,0.6]",
        "run.end_time=2.5",
    ]
    .map(String::from)
    .into();
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/dam_break.toml");
    cosim_proto::scene::load(&path, &sets).expect("valid scene").scene
}

#[test]
fn tall_dam_break_keeps_every_particle_out_of_the_walls() {
    let started = std::time::Instant::now();
    let scene = tall_dam_break();
    let mut solver = WcsphSolver::new(&scene).unwrap();
    let p = solver.params().clone();
    let n = solver.state().len();
    let centre = {
        let c = solver
            .state()
            .x
            .iter()
            .fold([0.0; 2], |a, x| [a[0] + x[0], a[1] + x[1]]);
        [c[0] / n as f64, c[1] / n as f64]
    };
    // The boxes the walls' particles fill (here the boxes themselves: 3 layers of 10 mm ≥ 2h = 26 mm).
    let boxes = WallBoxes::new(&scene.walls, p.dx, p.h, centre);
    let (mut steps_with_pushes, mut largest) = (0u64, 0u64);
    while solver.state().t < T_END - 1e-9 {
        // As `SphCore::handle` sub-cycles one coupling step.
        let mut done = 0.0;
        while done < COUPLING_DT {
            let mut h = solver.stable_dt().min(COUPLING_DT - done);
            if COUPLING_DT - done - h <= 1e-9 * h {
                h = COUPLING_DT - done;
            }
            let t = solver.state().t;
            solver
                .step(h)
                .unwrap_or_else(|e| panic!("step at t = {t:.4} s failed: {e}"));
            done += h;
            let st = solver.state();
            for (i, (x, v)) in st.x.iter().zip(&st.v).enumerate() {
                assert!(
                    x.iter().chain(v).all(|c| c.is_finite()),
                    "particle {i}: non-finite state at t = {:.4} s",
                    st.t
                );
                assert!(
                    boxes.exit_direction(*x).is_none(),
                    "particle {i} inside a wall at {x:?}, t = {:.4} s (step {})",
                    st.t,
                    st.step
                );
            }
            let last = solver.wall_pushes().1;
            steps_with_pushes += u64::from(last > 0);
            largest = largest.max(last);
        }
    }
    let (total, _) = solver.wall_pushes();
    let st = solver.state();
    eprintln!(
        "tall dam break WCSPH to t = {:.2} s: {} steps, the wall guard put {total} particles back ({steps_with_pushes} \
         steps, at most {largest} in one), {:.1} s wall",
        st.t,
        st.step,
        started.elapsed().as_secs_f64()
    );
    // Every particle stayed in the tank.
    assert!(st.x.iter().all(|x| x[0] >= 0.0 && x[0] <= 0.3 && x[1] >= 0.0));
    // The walls keep the water out on their own: the guard acts less than 1 % as often as it did without the
    // repulsion (144,955 times).
    assert!(total < 1_450, "the wall guard put {total} particles back");
}
