//! Helpers shared by the acceptance tests.
#![allow(dead_code)]

use cosim_proto::scene::{BoxSpec, ElementKind, MaterialModel, MaterialSpec, SolidSpec};
use fem_node::{FemModel, FemSolver};

/// A material of the given model, density [kg/m³], Young's modulus [Pa] and Poisson's ratio.
pub fn material(model: MaterialModel, density: f64, youngs_modulus: f64, poisson_ratio: f64) -> MaterialSpec {
    MaterialSpec {
        model,
        density,
        youngs_modulus,
        poisson_ratio,
    }
}

/// A rectangular bar `[x0, x1] × [y0, y1]` clamped at its left end `x = x0`.
pub fn cantilever(
    x: [f64; 2],
    y: [f64; 2],
    divisions: [u32; 2],
    element: ElementKind,
    material: MaterialSpec,
) -> SolidSpec {
    let eps = 1e-9 * (x[1] - x[0]);
    SolidSpec {
        name: "bar".into(),
        min: [x[0], y[0]],
        max: [x[1], y[1]],
        divisions,
        element,
        material,
        fixed: vec![BoxSpec {
            min: [x[0] - eps, y[0] - eps],
            max: [x[0] + eps, y[1] + eps],
        }],
        damping: 0.0,
        mesh_damping: Some(0.0),
    }
}

/// Builds a solver of one solid.
pub fn solver(spec: SolidSpec, gravity: [f64; 2], cfl: f64) -> FemSolver {
    FemSolver::new(FemModel::from_solids(&[spec], gravity).expect("model"), cfl).expect("solver")
}

/// A time series `(t, value)`.
pub type Series = Vec<(f64, f64)>;

/// Times at which the series crosses `level` (linear interpolation), in either direction.
pub fn crossings(series: &Series, level: f64) -> Vec<f64> {
    series
        .windows(2)
        .filter_map(|w| {
            let (a, b) = (w[0].1 - level, w[1].1 - level);
            if (a < 0.0 && b >= 0.0) || (a > 0.0 && b <= 0.0) {
                Some(w[0].0 + (w[1].0 - w[0].0) * a / (a - b))
            } else {
                None
            }
        })
        .collect()
}

/// Mean frequency from the crossings of `level`: (number of half periods) / (2 · time span).
pub fn frequency_from_crossings(series: &Series, level: f64) -> f64 {
    let c = crossings(series, level);
    assert!(c.len() >= 3, "only {} crossings", c.len());
    (c.len() - 1) as f64 / (2.0 * (c[c.len() - 1] - c[0]))
}

/// `(mean, amplitude) = ((max + min)/2, (max − min)/2)` of the values with `t` in `[t0, t1]`.
pub fn mean_amplitude(series: &Series, t0: f64, t1: f64) -> (f64, f64) {
    let vals = series.iter().filter(|(t, _)| *t >= t0 && *t <= t1).map(|s| s.1);
    let (lo, hi) = vals.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
    (0.5 * (hi + lo), 0.5 * (hi - lo))
}

/// Relative error `|value − reference| / |reference|`.
pub fn rel_err(value: f64, reference: f64) -> f64 {
    (value - reference).abs() / reference.abs()
}
