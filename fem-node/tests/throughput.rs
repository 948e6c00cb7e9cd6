//! Single-thread throughput in element-steps per second (printed with `--nocapture`; not asserted).

mod common;

use std::time::Instant;

use common::*;
use cosim_proto::scene::{ElementKind, MaterialModel};

#[test]
fn single_thread_element_steps_per_second() {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    for element in [ElementKind::Quad4, ElementKind::Tri3] {
        for model in [
            MaterialModel::LinearElastic,
            MaterialModel::NeoHookean,
            MaterialModel::StVenantKirchhoff,
        ] {
            let spec = cantilever(
                [0.0, 1.0],
                [0.0, 0.1],
                [100, 10],
                element,
                material(model, 1000.0, 1.0e6, 0.3),
            );
            let mut s = solver(spec, [0.0, -9.81], 0.9);
            let dt = s.stable_dt();
            let steps = 2000;
            let start = Instant::now();
            pool.install(|| {
                for _ in 0..steps {
                    s.substep(dt).unwrap();
                }
            });
            let seconds = start.elapsed().as_secs_f64();
            let rate = (steps * s.model().elements().len()) as f64 / seconds;
            println!(
                "{element:?} {model:?}: {:.2e} element-steps/s (1 thread, {} elements)",
                rate,
                s.model().elements().len()
            );
        }
    }
}
