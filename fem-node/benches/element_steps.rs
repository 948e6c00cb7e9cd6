//! Element-steps per second of the explicit solver, single thread, quad4 and tri3 (`cargo bench -p fem-node`).
//! Prints the median of several repetitions; nothing is asserted (machines are shared and noisy).

use std::time::Instant;

use cosim_proto::scene::{ElementKind, MaterialModel, MaterialSpec, SolidSpec};
use fem_node::{FemModel, FemSolver};

fn beam(element: ElementKind, model: MaterialModel) -> SolidSpec {
    SolidSpec {
        name: "beam".into(),
        min: [0.0, 0.0],
        max: [1.0, 0.05],
        divisions: [200, 25],
        element,
        material: MaterialSpec {
            model,
            density: 1000.0,
            youngs_modulus: 1.4e6,
            poisson_ratio: 0.4,
        },
        fixed: vec![cosim_proto::scene::BoxSpec {
            min: [-1e-9, -1.0],
            max: [1e-9, 1.0],
        }],
        damping: 0.0,
        mesh_damping: Some(0.0),
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    println!(
        "{:<8} {:<22} {:>9} {:>8} {:>16}",
        "element", "material", "elements", "steps", "element-steps/s"
    );
    for element in [ElementKind::Quad4, ElementKind::Tri3] {
        for material in [
            MaterialModel::StVenantKirchhoff,
            MaterialModel::LinearElastic,
            MaterialModel::NeoHookean,
        ] {
            let spec = beam(element, material);
            let model = FemModel::from_solids(std::slice::from_ref(&spec), [0.0, -2.0]).unwrap();
            let elements = model.elements().len();
            let mut solver = FemSolver::new(model, 0.9).unwrap();
            let dt = solver.stable_dt();
            let steps = 200;
            let rates: Vec<f64> = (0..5)
                .map(|_| {
                    let t0 = Instant::now();
                    pool.install(|| {
                        for _ in 0..steps {
                            solver.substep(dt).unwrap();
                        }
                    });
                    (elements * steps) as f64 / t0.elapsed().as_secs_f64()
                })
                .collect();
            println!(
                "{:<8} {:<22} {:>9} {:>8} {:>16.3e}",
                format!("{element:?}"),
                format!("{material:?}"),
                elements,
                steps,
                median(rates)
            );
        }
    }
}
